"""A wheel, installed outside the checkout, works: the recordings registry, the shipped validation
cases, scenes and report templates travel as package data.

The wheel is built from a copy of the checkout's files (``pip wheel --no-deps``) and installed with ``--no-deps
--no-index`` into a fresh venv in a temporary folder.  The dependencies are not downloaded again:
a ``.pth`` line puts the test environment's site-packages *behind* the new venv's own, so the
installed wheel is what ``import bearing_lab`` finds (checked), while numpy, scipy, numba ... come
from the environment already installed.  The commands run from a folder outside the checkout.

The validation from the wheel runs the installed paper case shortened (its two runs 0.2 s instead of 1 s, no
studies): the same command, case file, reference, scenes, numba kernels (compiled from the installed modules)
and report templates as the full case, whose own verdicts the README tour checks from the checkout.

Marked ``wheel`` (deselect locally with ``-m "not wheel"``); about 20 s of CPU, most of it compiling the
installed package's numba kernels.
"""
import json
import os
import shutil
import site
import subprocess
import sys
import venv
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
IN_CI = os.environ.get("CI", "").lower() in ("1", "true", "yes")
CWRU = "cwru/130_OR007@6_0.mat"

pytestmark = [pytest.mark.wheel, pytest.mark.xdist_group("wheel")]


def _run(cmd, cwd, env, timeout=300, ok=(0,)):
    p = subprocess.run([str(c) for c in cmd], cwd=cwd, env=env, capture_output=True, text=True,
                       timeout=timeout)
    assert p.returncode in ok, f"{' '.join(map(str, cmd))} -> {p.returncode}\n{p.stdout[-2000:]}\n{p.stderr[-3000:]}"
    return p


def _source_files() -> list[str]:
    """The checkout's files that git knows or would add (no build/, *.egg-info, .venv): a stale
    egg-info's file list would otherwise smuggle files into the wheel that the package-data
    declaration misses."""
    try:
        files = subprocess.run(["git", "-C", str(ROOT), "ls-files", "-z", "--cached", "--others",
                                "--exclude-standard"], capture_output=True, text=True, check=True).stdout
        rels = list(filter(None, files.split("\0")))
    except (OSError, subprocess.CalledProcessError):   # a source archive without git
        skip = {".git", ".venv", "build", "dist", "reports", "__pycache__", ".pytest_cache", ".hypothesis"}
        rels = [str(f.relative_to(ROOT)) for f in ROOT.rglob("*")
                if f.is_file() and not skip & set(f.relative_to(ROOT).parts)
                and not any(part.endswith(".egg-info") for part in f.parts)]
    return rels


def _clean_source(dest: Path) -> Path:
    """A copy of :func:`_source_files` in ``dest``."""
    for rel in _source_files():
        f = ROOT / rel
        if f.is_file():
            (dest / rel).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(f, dest / rel)
    return dest


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    """(venv bin folder, environment, work folder) of a fresh venv holding the built wheel."""
    tmp = tmp_path_factory.mktemp("wheel")
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV", "MPLBACKEND")}
    env["PIP_DISABLE_PIP_VERSION_CHECK"] = "1"
    src = _clean_source(tmp / "src")
    _run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", tmp / "dist", src], tmp, env)
    wheels = list((tmp / "dist").glob("bearing_lab-*.whl"))
    assert len(wheels) == 1, wheels
    venv.EnvBuilder(with_pip=False).create(tmp / "venv")
    vpy = tmp / "venv" / "bin" / "python"
    _run([sys.executable, "-m", "pip", "--python", vpy, "install", "--no-deps", "--no-index", "-q",
          wheels[0]], tmp, env)
    purelib = Path(_run([vpy, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                        tmp, env).stdout.strip())
    (purelib / "_test_env_deps.pth").write_text("\n".join(site.getsitepackages()) + "\n")
    work = tmp / "work"
    work.mkdir()
    return vpy.parent, env, work


def test_wheel_holds_the_installed_package(installed):
    bin_dir, env, work = installed
    out = _run([bin_dir / "python", "-c",
                "import bearing_lab, bearing_lab.datasets as d; print(bearing_lab.__file__); "
                "print(len(d.load_registry()))"], work, env).stdout.split()
    assert Path(out[0]).is_relative_to(bin_dir.parent), f"imported {out[0]}, not the wheel"
    assert not Path(out[0]).is_relative_to(ROOT)
    assert int(out[1]) > 100        # the CWRU drive-end table alone has more rows


def _installed_package(bin_dir, env, work) -> Path:
    out = _run([bin_dir / "python", "-c", "import bearing_lab; print(bearing_lab.__file__)"], work, env).stdout
    return Path(out.strip()).parent


def test_every_package_file_is_installed_as_it_is_in_the_checkout(installed):
    """The modules and every data file (scenes, solver rules, report templates, shipped cases, the registry,
    the sample recording): a file the package-data declaration misses is absent here."""
    bin_dir, env, work = installed
    pkg = _installed_package(bin_dir, env, work)
    rels = [r for r in _source_files() if r.startswith("bearing_lab/") and (ROOT / r).is_file()]
    assert any(r.endswith(".toml") for r in rels) and any(r.endswith(".html") for r in rels), rels
    missing = [r for r in rels if not (pkg / r.split("/", 1)[1]).is_file()]
    assert not missing, f"not in the wheel: {missing}"
    changed = [r for r in rels if (pkg / r.split("/", 1)[1]).read_bytes() != (ROOT / r).read_bytes()]
    assert not changed, changed


def test_validate_the_installed_paper_case_shortened_from_the_wheel(installed):
    bin_dir, env, work = installed
    env = {k: v for k, v in env.items() if k != "BEARING_LAB_MIRROR"}
    # every shipped case, read from the installed package
    listed = _run([bin_dir / "bearing-lab", "validate", "--list"], work, env).stdout
    shipped = [p.stem for p in (ROOT / "bearing_lab" / "validation" / "cases").glob("*.toml")
               if not p.stem.endswith("_reference")]
    assert len(shipped) >= 2 and all(f"\n{n} " in "\n" + listed for n in shipped), listed
    # the installed paper case, its runs 0.2 s and no studies, beside its installed reference
    cases = _installed_package(bin_dir, env, work) / "validation" / "cases"
    text = (cases / "paper.toml").read_text()
    edits = {'name = "paper"\n': 'name = "paper-short"\n', "duration_s = 1.0\n": "duration_s = 0.2\n",
             "[studies]\nenabled = true\n": "[studies]\nenabled = false\n",
             'reference = "paper_reference.toml"\n': f'reference = "{cases / "paper_reference.toml"}"\n'}
    for a, b in edits.items():
        assert a in text, f"the shipped paper case no longer has {a!r}: update this test"
        text = text.replace(a, b)
    (work / "paper-short.toml").write_text(text)
    p = _run([bin_dir / "bearing-lab", "validate", "paper-short.toml", "-o", work / "reports", "--no-progress"],
             work, env, ok=(0, 1))
    summary = json.loads((work / "reports" / "paper-short" / "summary.json").read_text())
    assert summary["case"] == "paper-short" and summary["status"] in ("pass", "fail"), summary["status"]
    # exit status 1 exactly when a row fails without a declared reason
    assert p.returncode == (1 if summary["verdict"] == "fail" else 0), (p.returncode, summary["verdict"])
    assert summary["rows"], "no compared quantity"
    # the pages are made from the installed templates (the stylesheet is inlined)
    css = (ROOT / "bearing_lab" / "report" / "templates" / "base.css").read_text().splitlines()[0]
    for page in (work / "reports" / "index.html", work / "reports" / "paper-short" / "index.html"):
        assert page.stat().st_size > 1000 and css in page.read_text(), page
    # the sample recording is package data
    _run([bin_dir / "bearing-lab", "data", "sample", "-o", work / "sample.uff", "-q"], work, env)
    assert (work / "sample.uff").stat().st_size > 50000


def test_cwru_import_from_the_wheel(installed, mirror):
    bin_dir, env, work = installed
    if mirror is None or not (Path(mirror) / CWRU).is_file():
        if IN_CI:
            pytest.fail(f"BEARING_LAB_MIRROR with {CWRU} is required in CI")
        pytest.skip(f"no BEARING_LAB_MIRROR with {CWRU}")
    env = dict(env, BEARING_LAB_MIRROR=str(mirror))
    out = work / "130.nc"
    _run([bin_dir / "bearing-lab", "import", Path(mirror) / CWRU, "-o", out], work, env)
    info = _run([bin_dir / "bearing-lab", "info", "--json", out], work, env).stdout
    got = json.loads(info)
    # CWRU files store no sampling rate: without the registry the reader refuses the file
    assert got["reader"] == "cwru" and got["sampling_rate_hz"] == 12000.0, info[:500]
    src = _run([bin_dir / "python", "-c", "import sys, xarray as xr; "
                "print(xr.open_dataset(sys.argv[1]).attrs['sampling_rate_source'])", out], work, env).stdout
    assert "registry" in src, src
