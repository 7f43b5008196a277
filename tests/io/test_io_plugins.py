"""Readers of other packages (entry-point group ``bearing_lab.readers``): a lab adds its own
format without forking.  The plugin is a real installed distribution (a ``.dist-info`` with
``entry_points.txt`` on ``sys.path``), exercised in a child process so this session's reader
table is untouched."""
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from bearing_lab.io import ENGINES, FALLBACK_READERS, SNIFF_ORDER

PLUGIN = textwrap.dedent('''
    from pathlib import Path
    import numpy as np
    from bearing_lab.io import RecordingReader
    from bearing_lab.io._base import RecordingBuilder

    class LabFmtReader(RecordingReader):
        """Text: 'LABFMT1 <fs_hz>' then one acceleration in g per line."""
        name = "labfmt"
        description = "our lab's logger text format"
        extensions = (".lab",)

        def guess_can_open(self, path, head):
            return head.startswith(b"LABFMT1 ")

        def open_dataset(self, path, *, channels=None, checksum=True):
            path = Path(path)
            b = RecordingBuilder(path, self, units="g", checksum=checksum)
            lines = path.read_text().split("\\n")
            fs = float(lines[0].split()[1])
            b.add_channel("acc", np.array([float(v) for v in lines[1:] if v.strip()]), None)
            return b.build(fs=fs, default_channel="acc", channels=channels)
''')


def _install(tmp_path, value="labreaders:LabFmtReader", name="labfmt"):
    (tmp_path / "labreaders.py").write_text(PLUGIN)
    info = tmp_path / "labreaders-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: labreaders\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text(f"[bearing_lab.readers]\n{name} = {value}\n")


def _child(tmp_path, code):
    p = subprocess.run([sys.executable, "-W", "always", "-c", code], capture_output=True, text=True,
                       timeout=120, cwd=tmp_path,
                       env={"PYTHONPATH": str(tmp_path), "PATH": "/usr/bin:/bin", "HOME": str(tmp_path)})
    assert p.returncode == 0, p.stderr[-3000:]
    return p


def test_builtin_sniffing_order_is_explicit():
    assert list(ENGINES)[:len(SNIFF_ORDER)] == list(SNIFF_ORDER)
    assert list(ENGINES)[-len(FALLBACK_READERS):] == list(FALLBACK_READERS)


def test_plugin_reader_is_sniffed_before_the_catch_all(tmp_path):
    _install(tmp_path)
    x = np.sin(np.arange(200) * 0.3)
    (tmp_path / "run1.lab").write_text("LABFMT1 5000\n" + "\n".join(f"{v:.6f}" for v in x) + "\n")
    out = _child(tmp_path, textwrap.dedent('''
        import bearing_lab.io as io
        names = list(io.ENGINES)
        assert names.index("labfmt") == len(io.SNIFF_ORDER), names
        assert names[-1] == "csv", names
        ds = io.open_recording("run1.lab")
        print(ds.attrs["reader"], ds.attrs["sampling_rate_hz"], ds["acc"].attrs["units"],
              float(ds["acc"].values.max()), sep="|")
    ''')).stdout.strip().split("|")
    assert out[:3] == ["labfmt", "5000.0", "m s-2"]
    assert float(out[3]) == pytest.approx(x.max() * 9.80665, rel=1e-5)


def test_broken_plugin_is_skipped_with_a_warning(tmp_path):
    _install(tmp_path, value="labreaders:NoSuchReader")
    p = _child(tmp_path, "import bearing_lab.io as io; print('labfmt' in io.ENGINES)")
    assert p.stdout.strip() == "False"
    assert "reader 'labfmt'" in p.stderr and "cannot be imported" in p.stderr
