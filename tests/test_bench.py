"""`bearing-lab bench` end to end on one scene (short records): the report, the netCDF table and
the auto rules are written, and every row was measured against the converged reference."""
import math
import tomllib

import numpy as np
import pytest


def test_bench_writes_report_rules_and_rows(tmp_path):
    from bearing_lab.studies.bench import rows_of, run_bench, summary_table
    ds = run_bench(tmp_path, duration=0.05, scenes=["paper-slot"], progress=False, scipy=False,
                   rate_duration=0.05)
    for name in ("index.html", "performance.nc", "auto_rules.toml", "work_precision_paper-slot.png",
                 "auto_rate_study.csv"):
        assert (tmp_path / name).stat().st_size > 0
    rows = rows_of(ds)
    assert {r["fidelity"] for r in rows} == {"multibody", "quasi-static", "multibody+dynamic cage"}
    assert {r["contact"] for r in rows} == {"halfspace", "area", "drop", "profile"}
    assert all(r["cost"] > 0 for r in rows)
    assert all(math.isfinite(r["err_peak"]) for r in rows)
    # the tightest adaptive multibody setting sits close to the reference, the local law far from
    # it (benchmarks/README.md); across the full groove width the rigid 2-D drop and the
    # along-track profile are the same geometry, so the same record
    tight = [r for r in rows if r["setting"] == "dp54 rtol=1e-06" and r["fidelity"] == "multibody"]
    assert tight and tight[0]["err_peak"] < 0.01
    err = {r["contact"]: r["err_peak"] for r in rows if r["contact"] != "halfspace"}
    assert err["area"] > 0.2
    assert err["drop"] == pytest.approx(err["profile"], rel=1e-9, abs=1e-12)
    rules = tomllib.loads((tmp_path / "auto_rules.toml").read_text())
    assert rules["defect"]["fidelity"] == "multibody" and rules["defect"]["method"] in ("dp54", "bs32")
    assert "paper-slot" in summary_table(ds)
    # `bench --json`: strict JSON with every row and the scene's fastest setting within tolerance
    import json
    from bearing_lab.utils._json import dumps
    from bearing_lab.cli.bench import json_summary
    js = json.loads(dumps(json_summary(ds, tmp_path)))
    assert len(js["rows"]) == len(rows) and js["tolerance"]["peak"] > 0
    best = js["fastest_within_tolerance"]["paper-slot"]
    assert best is not None and best["err_peak"] <= js["tolerance"]["peak"] and best in js["rows"]
    assert best["cost"] == min(r["cost"] for r in js["rows"] if r["scene"] == "paper-slot"
                               and r["solver"] == "bearing_lab" and r["err_peak"] <= js["tolerance"]["peak"]
                               and not r["err_period"] > js["tolerance"]["period"])
    # the rate study: every candidate at 20, 100 and 200 kHz, each against its own reference at that
    # rate, and a rule per rate made from those rows
    from bearing_lab.studies.bench import RATE_SETTINGS, RATES_HZ, rate_choices, read_rate_study
    rrows = read_rate_study(tmp_path / "auto_rate_study.csv")
    assert {(r["rate_hz"], r["method"], r["rtol"]) for r in rrows} == {
        (fs, m, rt) for fs in RATES_HZ for m, rt in RATE_SETTINGS}
    assert all(math.isfinite(r["err_peak"]) and r["cost"] > 0 for r in rrows)
    assert len({r["ref_peak"] for r in rrows}) == len(RATES_HZ)      # one reference per rate
    bands = rules["defect"]["by_rate"]
    assert [b["max_rate_hz"] for b in bands] == sorted(RATES_HZ)
    for b in bands:
        best = rate_choices(rrows)[("defect", b["max_rate_hz"])]
        assert (b["method"], b["rtol"]) == best[:2] and b["expected_peak_error"] <= 0.01
    assert "200 kHz" in ds.attrs["rate_table_md"]
    assert np.isfinite(ds["cost"].values).all()


def test_one_tolerance_rule_for_both_benchmarks():
    """Peak error within TOL_PEAK; the period error counts only where the reference has a period."""
    from bearing_lab.studies.bench_common import TOL_PEAK, TOL_PERIOD, within_tolerance
    good = {"err_peak": TOL_PEAK / 2, "err_period": TOL_PERIOD / 2}
    assert within_tolerance(good, 0.01)
    assert not within_tolerance({**good, "err_peak": 2 * TOL_PEAK}, 0.01)
    assert not within_tolerance({**good, "err_peak": math.nan}, 0.01)
    assert not within_tolerance({**good, "err_period": 2 * TOL_PERIOD}, 0.01)
    assert not within_tolerance({**good, "err_period": math.nan}, 0.01)       # a period the run lost
    assert within_tolerance({**good, "err_period": math.nan}, math.nan)       # none to lose


def test_rules_are_chosen_within_a_margin_of_the_tolerance():
    """A setting becomes a rule only within RULE_MARGIN of the tolerance: an error of 0.6 % peak
    (or 0.06 % period) is within the 1 % (0.1 %) promised but not within half of it; the rule
    chosen from rows is the cheapest that keeps the margin, not the cheapest within tolerance."""
    from bearing_lab.studies.bench import rate_choices
    from bearing_lab.studies.bench_common import RULE_MARGIN, TOL_PEAK, TOL_PERIOD, within_tolerance
    assert 0 < RULE_MARGIN < 1
    thin = {"err_peak": 0.6 * TOL_PEAK, "err_period": 0.0}
    assert within_tolerance(thin, 0.01) and not within_tolerance(thin, 0.01, RULE_MARGIN)
    thin_period = {"err_peak": 0.0, "err_period": 0.6 * TOL_PERIOD}
    assert within_tolerance(thin_period, 0.01) and not within_tolerance(thin_period, 0.01, RULE_MARGIN)
    with pytest.raises(ValueError, match="fraction"):
        within_tolerance(thin, 0.01, 0.0)

    def row(scene, method, rtol, cost, err):
        return dict(kind="defect", scene=scene, rate_hz=1e5, method=method, rtol=rtol, cost=cost,
                    err_peak=err, err_period=1e-8, ref_period=0.01)
    rows = [row(s, "bs32", 1e-4, 1.0, e) for s, e in (("a", 0.002), ("b", 0.6 * TOL_PEAK))]
    rows += [row(s, "bs32", 1e-5, 1.1, 0.1 * TOL_PEAK) for s in ("a", "b")]
    assert rate_choices(rows)[("defect", 1e5)][:2] == ("bs32", 1e-5)
