"""The bounds-checked MATLAB v5 reader: same values as scipy.io on good files, no crash on bad ones.

scipy.io.loadmat is the independent reference for well-formed files (it is a separate
implementation of the same MathWorks specification); on damaged files it is the thing we
must not call, because its compiled reader crashes the process.
"""
import resource
import subprocess
import sys
import zlib

import numpy as np
import pytest
import scipy.io

from bearing_lab import RecordingError, open_recording
from bearing_lab.io import _mat5

MAT_FILES = ["cwru/105_IR007_0.mat", "cwru/97_Normal_0.mat", "cwru/12k_FE/IR007_0.mat",
             "cwru/48k_DE/IR014_0.mat", "mfpt/OuterRaceFault_vload_1.mat",
             "mfpt/InnerRaceFault_vload_1.mat", "lms/testlab_acceler.mat"]


def _scipy_plain(obj):
    """scipy.io.loadmat(squeeze_me=True, struct_as_record=False) -> plain Python, like _mat5."""
    from scipy.io.matlab import mat_struct
    if isinstance(obj, mat_struct):
        return {k: _scipy_plain(getattr(obj, k)) for k in obj._fieldnames}
    if isinstance(obj, np.ndarray):
        if obj.dtype.kind == "U":
            if obj.size == 0:
                return ""
            if obj.ndim <= 1 and all(len(s) <= 1 for s in obj.ravel()):
                return "".join(obj.ravel().tolist())
            return [str(s) for s in obj.ravel()]
        if obj.dtype == object:
            return [_scipy_plain(o) for o in obj.ravel()]
    return obj


def _same(a, b, where=""):
    if isinstance(a, dict):
        assert isinstance(b, dict) and list(a) == list(b), (where, a, b)
        for k in a:
            _same(a[k], b[k], f"{where}.{k}")
    elif isinstance(a, list):
        assert isinstance(b, list) and len(a) == len(b), (where, a, b)
        for i, (x, y) in enumerate(zip(a, b)):
            _same(x, y, f"{where}[{i}]")
    elif isinstance(a, str):
        assert a == b, (where, a, b)
    else:
        x, y = np.asarray(a), np.asarray(b)
        assert x.shape == y.shape and np.array_equal(x, y), (where, a, b)


def _against_scipy(path):
    ref = scipy.io.loadmat(path, squeeze_me=True, struct_as_record=False)
    ref = {k: _scipy_plain(v) for k, v in ref.items() if not k.startswith("__")}
    mine = _mat5.load(path.read_bytes())
    _same(ref, mine)
    assert _mat5.variable_names(path.read_bytes()) == list(ref)


@pytest.mark.parametrize("rel", MAT_FILES, ids=[r.split("/")[-1] for r in MAT_FILES])
def test_real_files_equal_scipy(datafile, rel):
    _against_scipy(datafile(rel))


@pytest.mark.parametrize("compress", [False, True])
def test_every_class_equals_scipy(tmp_path, compress):
    p = tmp_path / "kinds.mat"
    data = {
        "d": np.arange(12.0).reshape(3, 4), "s": np.float32([1.5, -2]), "i8": np.int8([-3, 4]),
        "u16": np.uint16([[1], [2]]), "i64": np.int64([2 ** 40]), "scalar": 7.25,
        "c": np.array([1 + 2j, 3 - 4j]), "b": np.array([True, False, True]),
        "text": "hello µ", "rows": np.array(["ab", "cd"]), "empty": np.zeros((0, 3)),
        "cell": np.array([np.arange(3.0), "x", np.array([[1, 2], [3, 4]])], dtype=object),
        "st": {"a": 1.0, "nested": {"name": "2:Point1", "v": np.arange(5)}},
        "sarr": np.array([({"k": 1},), ({"k": 2},)], dtype=[("f", object)]),
    }
    scipy.io.savemat(p, data, do_compression=compress)
    _against_scipy(p)


def _crash_free(args, timeout=60):
    """Run ``bearing-lab`` in a child: a segmentation fault shows as a negative status."""
    return subprocess.run([sys.executable, "-m", "bearing_lab", *args], capture_output=True,
                          text=True, timeout=timeout)


def test_corrupt_type_byte_is_one_line_not_a_segfault(datafile, tmp_path):
    """Byte 192 of a CWRU file set to 0x19 (an unknown data type): scipy crashed (exit 139)."""
    p = tmp_path / "105_IR007_0.mat"
    b = bytearray(datafile("cwru/105_IR007_0.mat").read_bytes())
    b[192] = 0x19
    p.write_bytes(bytes(b))
    r = _crash_free(["info", str(p)])
    assert r.returncode == 2, (r.returncode, r.stderr[-500:])
    err = r.stderr.strip().splitlines()
    assert len(err) == 1 and "105_IR007_0.mat" in err[0] and "data type 25" in err[0], r.stderr


def test_declared_sizes_checked_before_any_allocation(datafile, tmp_path):
    """A 1 MB file whose array claims 2**31 doubles is refused at once, in little memory."""
    src = datafile("lms/testlab_acceler.mat").read_bytes()
    b = bytearray(src)
    b[132:136] = (0x7FFFFFF0).to_bytes(4, "little")   # top-level element size
    p = tmp_path / "big.mat"
    p.write_bytes(bytes(b))
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    with pytest.raises(RecordingError, match=r"big.mat: .*declares 2147483632 bytes but only"):
        open_recording(p)
    grown_mb = (resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before) / 1024
    assert grown_mb < 100


def test_compressed_variable_inflation_is_bounded():
    """A compressed element that declares more than deflate can produce is refused unread."""
    inner = (14).to_bytes(4, "little") + (1 << 31).to_bytes(4, "little") + bytes(64)
    comp = zlib.compress(inner)
    head = b"MATLAB 5.0 MAT-file".ljust(116, b" ") + bytes(8) + b"\x00\x01IM"
    buf = head + (15).to_bytes(4, "little") + len(comp).to_bytes(4, "little") + comp
    with pytest.raises(_mat5.Mat5Error, match="more than deflate can produce"):
        _mat5.load(buf)


@pytest.mark.parametrize("cut", [130, 200, 4000, -3])
def test_truncated_file_refused(datafile, tmp_path, cut):
    src = datafile("cwru/130_OR007@6_0.mat").read_bytes()
    p = tmp_path / "130_OR007@6_0.mat"
    p.write_bytes(src[:cut])
    with pytest.raises(RecordingError, match="130_OR007@6_0.mat"):
        open_recording(p, format="cwru")


def test_cwru_renamed_channel_is_not_dropped(datafile, tmp_path):
    """One letter of 'X130_FE_time' changed: FE must not vanish from the recording in silence."""
    src = datafile("cwru/130_OR007@6_0.mat").read_bytes()
    k = src.index(b"X130_FE_time")
    p = tmp_path / "130_OR007@6_0.mat"
    p.write_bytes(src[:k + 6] + b"X" + src[k + 7:])
    with pytest.raises(RecordingError, match=r"variable 'X130_FX_time' holds 121991 samples"):
        open_recording(p)
    ds = open_recording(p, channels=["DE", "BA"])   # the user may still read what is named
    assert list(ds.data_vars) == ["DE", "BA"]
