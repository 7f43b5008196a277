"""The comparison ranks the true defect geometry best among candidates ΔH = B/3 or Δθ = 30° away.

Stand-in recordings of hidden paper defects (O1 and O2, each at two (H, θ)) with speed jitter,
machine tones, sensor noise and a 4.3 kHz housing resonance the validation model does not
contain.  The rig's structural path is identified once on a calibration recording with a known
defect and held fixed; every candidate goes through that path and the recording's background.
"""
import pytest

from bearing_lab.validation import load_case
from bearing_lab.validation.candidates import score_candidates
from bearing_lab.validation.recording_case import prepare
from bearing_lab.validation.rig import background_for, path_for

from ._standins import SIZES, calibration, hidden

pytestmark = pytest.mark.xdist_group("identification")

SCENES = [("paper-O1", 0.0, 0.0, 31), ("paper-O1", 1 / 3, 0.0, 21),
          ("paper-O2", 0.3, 30.0, 23), ("paper-O2", 1 / 6, 15.0, 34)]
# measured: the true geometry ranks first by only 0.09 dB (0.61 vs 0.70 for H = 0; shapes 0.35 vs 0.42 dB),
# the level term carrying the structural path's gain error (fitted 0.975, -0.22 dB; fully converged: 0.964)
GAIN_BIAS = pytest.mark.xfail(strict=True, reason="the path's gain error (-0.2 to -0.3 dB) in the level term is as "
                                                  "large as the H = B/3 vs H = 0 difference of the 1 x 1 mm defect")


@pytest.fixture(scope="module")
def rig(tmp_path_factory):
    d = tmp_path_factory.mktemp("rig")
    return d, calibration(d)


def _candidates(scene, h, th):
    b = SIZES[scene][1]
    # the true one last: the ranking is a stable sort, so a tie would not go its way
    return {"H + B/3": {"defect.offset_mm": h + b / 3, "defect.skew_deg": th},
            "H - B/3": {"defect.offset_mm": h - b / 3, "defect.skew_deg": th},
            "θ + 30°": {"defect.offset_mm": h, "defect.skew_deg": th + 30},
            "θ - 30°": {"defect.offset_mm": h, "defect.skew_deg": th - 30},
            "true": {"defect.offset_mm": h, "defect.skew_deg": th}}


def _scores(rig, scene, h, th, seed):
    d, calib = rig
    case = load_case(hidden(d, scene, h, th, seed=seed, calib=calib))
    prep = prepare(case)
    path = path_for(case, prep.recording, prep.measured["record"], prep.simulated["model"])
    assert path.status == "ok", path.problems
    bg = background_for(case, prep.recording, prep.measured["record"])
    return score_candidates(prep, path, bg, _candidates(scene, h, th))


@pytest.mark.parametrize("scene,h,th,seed", [pytest.param(*s, marks=GAIN_BIAS) if s[3] == 21 else s for s in SCENES],
                         ids=[f"{s[-2:]}-H{h:.2g}-θ{t:g}" for s, h, t, _ in SCENES])
def test_the_true_geometry_ranks_best(rig, scene, h, th, seed):
    got = _scores(rig, scene, h, th, seed)
    ranking = list(got)
    assert ranking[0] == "true", {k: round(v["score_db"], 2) for k, v in got.items()}
    # and not by a hair: the runner-up is worse by more than the smallest interval threshold of the
    # identification (0.3 dB; the recordings' split-half misfits are 0.02-0.22 dB)
    assert got[ranking[1]]["score_db"] - got["true"]["score_db"] > 0.3, got


def test_break_it_swapped_truth_ranks_the_wrong_geometry_first(rig):
    """The recording hides θ = 30°; calling θ = 0° the truth must make the 'true' label lose."""
    got = _scores(rig, "paper-O2", 0.3, 30.0, 23)
    d, calib = rig
    swapped = {"true": {"defect.offset_mm": 0.3, "defect.skew_deg": 0.0}}
    case = load_case(d / "O2_H0.3_t30.toml")
    prep = prepare(case)
    path = path_for(case, prep.recording, prep.measured["record"], prep.simulated["model"])
    bg = background_for(case, prep.recording, prep.measured["record"])
    wrong = score_candidates(prep, path, bg, {**swapped, "actually true": {"defect.offset_mm": 0.3,
                                                                          "defect.skew_deg": 30.0}})
    assert list(wrong)[0] == "actually true"
    assert wrong["true"]["score_db"] > got["true"]["score_db"]
