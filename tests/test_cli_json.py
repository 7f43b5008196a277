"""Output meant for programs is strict JSON: no NaN/Infinity tokens, no numpy noise on stderr."""
import json
import subprocess
import sys

import numpy as np


def _strict(text):
    def refuse(token):
        raise ValueError(f"non-standard JSON token {token}")
    return json.loads(text, parse_constant=refuse)


def test_analyze_json_with_one_huge_sample(tmp_path):
    """One sample of 1e300 made `analyze --json` print NaN/Infinity and 18 numpy warnings."""
    t = np.arange(20000) / 20000.0
    x = np.sin(2 * np.pi * 100 * t) + 0.1 * np.random.default_rng(0).normal(size=t.size)
    x[500] = 1e300
    p = tmp_path / "big.csv"
    p.write_text("time,acc [m/s2]\n" + "\n".join(f"{a:.8f},{b:.17g}" for a, b in zip(t, x)) + "\n")
    r = subprocess.run([sys.executable, "-m", "bearing_lab", "analyze", str(p), "--bearing", "6205",
                        "--json"], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    d = _strict(r.stdout)
    assert d["metrics"]["rms"] is None and d["metrics"]["peak"] == 1e300
    assert "encountered" not in r.stderr, r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and "not finite" in r.stderr


def test_info_json_is_strict(tmp_path):
    from bearing_lab.utils._json import dumps
    assert _strict(dumps({"a": float("inf"), "b": [np.float64("nan"), np.int64(3)]})) == \
        {"a": None, "b": [None, 3]}
