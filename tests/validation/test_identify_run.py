"""An identification a user can run: its cost estimate brackets what it costs, its progress moves with every
scene, and a stopped run keeps its scenes (a rerun reads them back) and reports a partial result.  A small
grid (4 scenes of 0.5 s) on the stand-in rig of test_identify.py, with contact tables built cold in a cache
of this module's own."""
import json
import os

import pytest

from bearing_lab.cli import main
from bearing_lab.validation.identify import IdentificationInterrupted, identify

from ._standins import calibration, hidden

pytestmark = pytest.mark.xdist_group("identification_run")

# two aligned outlines (θ = 0) and two skewed ones; none is the stand-ins' own (H = 0.3 mm, θ = 30°)
GRID = {"defect.length_mm": [2.5, 3.0], "defect.offset_mm": [0.25], "defect.skew_deg": [0.0, 30.0]}


@pytest.fixture(scope="module")
def rig(tmp_path_factory):
    """The stand-in case, and the cold run over GRID (its estimate, progress events and result), in a table
    cache no other test has filled."""
    from bearing_lab.sim.defects import contact
    d = tmp_path_factory.mktemp("ident_run")
    saved_env, saved_mem = os.environ["BEARING_LAB_CACHE"], dict(contact._MEMORY)
    os.environ["BEARING_LAB_CACHE"] = str(d / "cache")
    contact._MEMORY.clear()
    try:
        case = hidden(d, "paper-O2", 0.3, 30.0, seed=23, calib=calibration(d), name="rig", duration_s=0.5,
                      declared_length_mm=2.5)
        events, said = [], []
        res = identify(case, grid=GRID, refine=False, progress=events.append, notify=said.append)
        yield d, case, res, events, said
    finally:
        os.environ["BEARING_LAB_CACHE"] = saved_env
        contact._MEMORY.clear()
        contact._MEMORY.update(saved_mem)


def test_the_estimate_counts_the_tables_to_build_and_brackets_the_cost(rig):
    d, case, res, _, said = rig
    est = res.estimate
    assert est["coarse_scenes"] == 4 and est["refine_scenes"] == (0, 0)
    assert est["tables_new"] == {"aligned": 2, "skewed": 2} and est["tables_cached"] == 0, est
    lo, hi = est["cpu_s"]
    spent = res.cpu_time_s - res.setup_cpu_s          # the scenes: tables, time loops, scoring
    print(f"estimate {lo:.1f}-{hi:.1f} s CPU, spent {spent:.1f} s (setup {res.setup_cpu_s:.1f} s)")
    assert lo <= spent <= hi, (lo, spent, hi)
    assert any("4 to build (2 skewed), 0 cached" in s for s in said), said
    # the tables are counted as contact_table keys them: after the run every one is cached
    from bearing_lab.validation.identify import _setting
    from bearing_lab.validation.identify_run import estimate
    from bearing_lab.validation import load_case
    os.environ["BEARING_LAB_CACHE"], saved = str(d / "cache"), os.environ["BEARING_LAB_CACHE"]
    try:
        _, base = _setting(load_case(case), None, None)
        again = estimate(base, GRID, refine=False)
    finally:
        os.environ["BEARING_LAB_CACHE"] = saved
    assert again["tables_cached"] == 4 and again["tables_new"] == {"aligned": 0, "skewed": 0}, again
    assert again["cpu_s"][1] < hi


def test_progress_moves_with_every_scene_and_counts_the_tables_left(rig):
    _, _, res, events, _ = rig
    assert [e["scenes"] for e in events] == [1, 2, 3, 4]
    assert events[0]["tables_left"] == 3 and events[-1]["tables_left"] == 0, events
    assert all(e["total"] >= e["scenes"] for e in events)


def _counting_runner(monkeypatch, stop_after=None):
    """Count the scenes simulated (the sweep's scene runner); raise KeyboardInterrupt on scene ``stop_after``+1."""
    import bearing_lab.sweep as sw
    real, ran = sw._simulate_scene, []

    def run(*a, **k):
        if stop_after is not None and len(ran) == stop_after:
            raise KeyboardInterrupt
        ran.append(a[1])
        return real(*a, **k)
    monkeypatch.setattr(sw, "_simulate_scene", run)
    return ran


def test_a_stopped_run_keeps_its_scenes_and_a_rerun_reads_them_back(rig, tmp_path, monkeypatch):
    d, case, full, _, _ = rig
    monkeypatch.setenv("BEARING_LAB_CACHE", str(d / "cache"))
    journal = tmp_path / "j.jsonl"

    def ctrl_c_at_two(ev):
        if ev["scenes"] == 2:
            raise KeyboardInterrupt
    with pytest.raises(IdentificationInterrupted) as exc:
        identify(case, grid=GRID, refine=False, progress=ctrl_c_at_two, journal=journal)
    part = exc.value.result
    assert part is not None and part.partial and part.n_scenes == 2
    assert part.notes[0].startswith("PARTIAL: stopped after 2 scenes (2 of the coarse grid's 4")
    assert all(p["statement"].startswith("partial, ") for p in part.parameters.values())
    assert part.best["score_db"] == min(p["score_db"] for p in full.points[:2])
    assert len(journal.read_text().splitlines()) == 1 + 2
    ran = _counting_runner(monkeypatch)
    said = []
    res = identify(case, grid=GRID, refine=False, progress=False, journal=journal, notify=said.append)
    assert len(ran) == 2 and res.resumed == 2 and not res.partial      # only the two scenes not done
    assert any(s.startswith("resuming: 2 scored scenes") for s in said), said
    assert res.estimate["coarse_done"] == 2 and res.estimate["coarse_scenes"] == 2
    key = list(GRID)
    got = {tuple(p[k] for k in key): p["score_db"] for p in res.points}
    assert got == {tuple(p[k] for k in key): p["score_db"] for p in full.points}      # the same scores
    assert res.signatures["best"] is not None


def test_a_journal_of_another_comparison_is_set_aside(rig, tmp_path, monkeypatch):
    d, case, full, _, _ = rig
    monkeypatch.setenv("BEARING_LAB_CACHE", str(d / "cache"))
    journal = tmp_path / "j.jsonl"
    journal.write_text(json.dumps({"journal": "bearing_lab identification", "comparison": "0" * 64}) + "\n"
                       + json.dumps({"scene": "x", "point": {}, "score": {"score_db": -99.0}}) + "\n")
    said = []
    res = identify(case, grid={k: v[:1] for k, v in GRID.items()}, refine=False, progress=False, journal=journal,
                   notify=said.append)
    assert res.resumed == 0 and res.best["score_db"] > -99.0
    assert (tmp_path / "j.jsonl.old").is_file() and any("set aside" in s for s in said), said


def test_cli_interrupted_writes_a_partial_result_exits_130_and_resumes(rig, tmp_path, monkeypatch, capsys):
    d, case, full, _, _ = rig
    monkeypatch.setenv("BEARING_LAB_CACHE", str(d / "cache"))
    args = ["identify", str(case), "-o", str(tmp_path), "--no-progress", "--no-refine", "--length-mm", "2.5", "3.0",
            "--offset-mm", "0.25", "--skew-deg", "0", "30"]
    _counting_runner(monkeypatch, stop_after=3)
    assert main(args) == 130
    out, err = capsys.readouterr()
    assert out.startswith("PARTIAL result (interrupted after 3 scenes)") and "partial, length" in out, out
    assert "rerun the same command to resume" in err
    written = json.loads((tmp_path / "rig" / "identification-partial.json").read_text())
    assert written["partial"] is True and written["n_scenes"] == 3
    assert not (tmp_path / "rig" / "identification.json").exists()
    monkeypatch.undo()
    monkeypatch.setenv("BEARING_LAB_CACHE", str(d / "cache"))
    ran = _counting_runner(monkeypatch)
    assert main(args) == 0
    out, err = capsys.readouterr()
    assert len(ran) == 1 and "resuming: 3 scored scenes" in err, err
    done = json.loads((tmp_path / "rig" / "identification.json").read_text())
    assert done["partial"] is False and done["n_scenes"] == 4 and done["resumed"] == 3
    assert not (tmp_path / "rig" / "identification-partial.json").exists()      # superseded


def test_the_truth_explains_the_recording_and_a_far_geometry_does_not(rig):
    """A recording the model made is explained by its own geometry; a geometry far from it is reported as not
    explaining the recording, rather than as parameters that are merely not identifiable."""
    _, case, _, _, _ = rig
    truth = identify(case, grid={"defect.length_mm": [3.0], "defect.offset_mm": [0.3], "defect.skew_deg": [30.0]},
                     refine=False, progress=False)
    assert truth.explains_recording is True, (truth.best["score_db"], truth.threshold_db)
    assert not any("does not explain" in n for n in truth.notes)
    far = identify(case, grid={"defect.length_mm": [1.0], "defect.offset_mm": [0.0], "defect.skew_deg": [-60.0]},
                   refine=False, progress=False)
    assert far.explains_recording is False and far.best["score_db"] > far.threshold_db
    assert "the model does not explain this recording" in far.notes[0]
    assert far.to_dict()["explains_recording"] is False



def test_a_mirrored_scene_scores_as_its_mirror_and_only_one_on_the_track_centre_is_mirrored(rig):
    """At H = 0 a defect at θ and at -θ are mirror images: simulated both, they score alike (within 0.01 dB,
    a thirtieth of the smallest threshold), so the search scores the one at -θ as its mirror.  Off the track
    centre nothing is mirrored."""
    from bearing_lab.validation import load_case
    from bearing_lab.validation.identify import _run_grid, _setting
    from bearing_lab.validation.identify_run import mirrors
    _, case, _, _, _ = rig
    st, base = _setting(load_case(case), None, None)
    keys = ["defect.length_mm", "defect.offset_mm", "defect.skew_deg"]
    pair = [(2.5, 0.0, 30.0), (2.5, 0.0, -30.0)]
    assert mirrors(base, keys, pair, set()) == {pair[1]: pair[0]}
    assert mirrors(base, keys, [(2.5, 0.25, 30.0), (2.5, 0.25, -30.0)], set()) == {}
    assert mirrors(base, keys, [pair[1]], set()) == {}             # its mirror is not searched: simulated
    scores = []
    for c in pair:                                  # each simulated on its own: no mirror is used
        out: list = []
        _run_grid(st, base, {k: [x] for k, x in zip(keys, c)}, scheduler="serial", cache_dir=False, bar=None,
                  out=out, keep={})
        scores.append(out[0]["score_db"])
    assert abs(scores[0] - scores[1]) < 0.01, scores
    both: list = []                                 # searched together: the one at -θ is the other's score
    _run_grid(st, base, {"defect.length_mm": [2.5], "defect.offset_mm": [0.0], "defect.skew_deg": [-30.0, 30.0]},
              scheduler="serial", cache_dir=False, bar=None, out=both, keep={})
    assert len(both) == 2 and both[0]["score_db"] == both[1]["score_db"] == scores[0]


def test_refinement_scenes_lie_on_the_lattice_of_the_grid():
    """Grid values and half steps are lattice points; any value moves to the nearest sixteenth of its gap."""
    from bearing_lab.validation.identify_search import snap
    grid = {"defect.length_mm": [1.5, 3.0, 6.0]}
    assert [snap(grid, "defect.length_mm", x) for x in (1.5, 2.25, 3.0, 4.5, 6.0)] == [1.5, 2.25, 3.0, 4.5, 6.0]
    assert snap(grid, "defect.length_mm", 3.1) == 3.1875 and snap(grid, "defect.length_mm", 2.95) == 2.9062
    assert snap(grid, "defect.length_mm", 7.0) == 6.0            # inside the searched range
