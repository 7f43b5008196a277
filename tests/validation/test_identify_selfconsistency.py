"""Self-consistency of the identification: a recording the model itself made (a stand-in of paper O2 at
600 N, its housing resonance 4300 Hz at 5 %), with the structural path fitted on that same recording against
the TRUE geometry, must be explained by the true geometry, within the identification's threshold.  Otherwise
the intervals can exclude the truth.

The path fit once gave this stand-in's resonance as 4282 Hz, 5.29 % (the envelope maximum of each impact
flipped between the defect's entry and exit rings, and the simulation's impacts were located on the bare
simulation, not on its ringing through the path), and the truth then misfit by 0.41 dB against a 0.35 dB
threshold; these checks keep the truth within the threshold and the fitted resonance within the
tolerance below."""
import pytest

from bearing_lab.validation import make_standin_recording
from bearing_lab.validation.identify import identify

pytestmark = pytest.mark.xdist_group("identify_selfconsistency")

RPM, LOAD_N, OFFSET_MM, SKEW_DEG = 1793.0, 600.0, 0.3, 30.0
RESONANCE_HZ, DAMPING = 4300.0, 0.05            # the stand-in's housing resonance (make_standin_recording)

@pytest.fixture(scope="module")
def truth_case(tmp_path_factory):
    d = tmp_path_factory.mktemp("selfcons")
    rec = d / "o2_600.uff"
    make_standin_recording(rec, scene="paper-O2", rpm=RPM, duration=2.0, seed=11, resonance_hz=RESONANCE_HZ,
                           resonance_damping=DAMPING, overrides={"load.radial_n": LOAD_N,
                                                                 "defect.offset_mm": OFFSET_MM,
                                                                 "defect.skew_deg": SKEW_DEG})
    case = d / "o2_600.toml"
    case.write_text(f'''name = "o2_600"
bearing = "6308"
speed = {RPM}

[recording]
file = "{rec.name}"
channel = "Acc"
duration_s = 1.0

[load]
radial_n = {LOAD_N}
on = "inner"

[[defect]]
race = "outer"
length_mm = 3.0
width_mm = 1.0
offset_mm = {OFFSET_MM}
skew_deg = {SKEW_DEG}

[tolerances]
bpfo = {{}}
''')
    return case


def test_the_true_geometry_explains_a_recording_the_model_made(truth_case):
    truth = identify(truth_case, grid={"defect.length_mm": [3.0], "defect.offset_mm": [OFFSET_MM],
                                       "defect.skew_deg": [SKEW_DEG]}, refine=False, progress=False)
    assert truth.explains_recording is True
    assert truth.best["score_db"] <= truth.threshold_db, (truth.best, truth.threshold_db, truth.noise_db)


def test_signatures_are_compared_through_the_stand_ins_own_resonance(truth_case):
    """The impact signature is compared through the resonance the stand-in was made with: within 0.2 % in
    frequency and 0.001 in damping ratio (a 4300 Hz, 5 % ring's decay then differs by under 3 %)."""
    from bearing_lab.validation.candidates import setting_for
    from bearing_lab.validation.load import load_case
    from bearing_lab.validation.recording_case import prepare
    from bearing_lab.validation.rig import path_for
    case = load_case(str(truth_case))
    prep = prepare(case)
    st = setting_for(prep, path_for(case, prep), None)
    (res,) = st.path.resonances
    assert res.frequency_hz == pytest.approx(RESONANCE_HZ, rel=0.002), st.path.fit.get("notes")
    assert res.damping_ratio == pytest.approx(DAMPING, abs=0.001), st.path.fit.get("notes")
