"""The README's Python examples run as printed (the walkthrough section has its own test,
tests/validation/test_walkthrough.py, which also runs its shell lines)."""
import os
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
IN_CI = os.environ.get("CI", "").lower() in ("1", "true", "yes")
WALKTHROUGH = "## Validate your own recording"


def _python_blocks():
    text = (ROOT / "README.md").read_text()
    i = text.index(WALKTHROUGH)
    j = text.find("\n## ", i + 5)
    outside = text[:i] + (text[j:] if j >= 0 else "")
    return re.findall(r"```python\n(.*?)```", outside, flags=re.S)


def test_readme_has_python_examples():
    assert _python_blocks(), "the README lost its Python example"


@pytest.mark.parametrize("n", range(len(_python_blocks())))
def test_readme_python_example_runs(n, mirror, monkeypatch):
    body = _python_blocks()[n]
    if "../shared/data" in body:
        if mirror is None or not Path(mirror).is_dir():
            if IN_CI:
                pytest.fail("BEARING_LAB_MIRROR is required in CI")
            pytest.skip("no BEARING_LAB_MIRROR")
        body = body.replace("../shared/data", str(mirror))
    monkeypatch.chdir(ROOT)
    # a fresh namespace, as a new session: nothing imported beforehand
    exec(compile(body, f"README.md python example {n + 1}", "exec"), {"__name__": "__readme__"})
