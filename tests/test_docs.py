"""The documents: every link and ``docs/*.md`` mention resolves, the index lists every page,
the scene-key page matches the key table, and modules and functions stay within the size
limits except where docs/architecture.md says why."""
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"


def _texts():
    files = [ROOT / "README.md", *DOCS.glob("*.md"), *(ROOT / "data").glob("*.md"),
             *(ROOT / "benchmarks").glob("*.md"), *(ROOT / "validation").glob("*.md")]
    files += [p for p in (ROOT / "bearing_lab").rglob("*.py")]
    return {p: p.read_text() for p in files}


def test_every_document_reference_resolves():
    missing = []
    for p, text in _texts().items():
        for target in re.findall(r"\]\(([^)#\s]+\.md)(?:#[^)]*)?\)", text):   # markdown links
            if not (p.parent / target).resolve().is_file():
                missing.append(f"{p.relative_to(ROOT)} -> {target}")
        for target in re.findall(r"\bdocs/([a-z0-9_-]+\.md)", text):          # docs/x.md mentions
            if not (DOCS / target).is_file():
                missing.append(f"{p.relative_to(ROOT)} -> docs/{target}")
    assert not missing, missing


def test_index_lists_every_document():
    index = (DOCS / "README.md").read_text()
    listed = set(re.findall(r"\]\(([a-z0-9_-]+\.md)\)", index))
    pages = {p.name for p in DOCS.glob("*.md")} - {"README.md"}
    assert listed == pages, {"not listed": pages - listed, "listed but absent": listed - pages}


def test_scene_keys_page_matches_the_table():
    from bearing_lab.sim.scene_keys import keys_markdown
    assert (DOCS / "scene-keys.md").read_text() == keys_markdown(), (
        "docs/scene-keys.md is out of step with bearing_lab/sim/scene_keys.py: regenerate it "
        "(see docs/architecture.md, 'A scene key')")


def test_defect_keys_documented():
    from bearing_lab.sim.defects.model import _KEYS
    from bearing_lab.sim.scene_keys import DEFECT_DOCS, DEFECT_KEYS
    assert set(DEFECT_DOCS) == DEFECT_KEYS == set(_KEYS) | {"contact_model"}


def _size_exceptions():
    text = (DOCS / "architecture.md").read_text()
    table = text[text.index("<!-- sizes:"):]
    return {m.group(1): int(m.group(2)) for m in re.finditer(r"^\| `([^`]+)` \| (\d+) \|", table, flags=re.M)}


def test_sizes_within_limits_or_explained():
    import importlib.util
    spec = importlib.util.spec_from_file_location("sizes", ROOT / "tools" / "sizes.py")
    sizes = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(sizes)
    allowed = _size_exceptions()
    assert allowed, "the exceptions table of docs/architecture.md was not found"
    mods, funcs = sizes.offenders()
    over = [f"{k}: {v} lines" for k, v in {**mods, **funcs}.items() if v > allowed.get(k, 0)]
    assert not over, ("over the size limits and not explained in docs/architecture.md "
                      "(split it, or add a row with the reason): " + "; ".join(over))
    known = {**sizes.module_sizes(), **sizes.function_sizes()}
    stale = [k for k in allowed if k not in known]
    assert not stale, f"docs/architecture.md lists what no longer exists: {stale}"
    needless = [k for k in allowed if k not in {**mods, **funcs}]
    assert not needless, f"docs/architecture.md lists exceptions now within the limits (remove the rows): {needless}"

