"""Fuzz every reader with corrupted copies of real files: flipped bytes and cut lengths.

Only :class:`RecordingError` may escape, and its message names the file.  Kept
fast: few derandomized examples, small copies written to a temporary directory.
"""
import tempfile
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

from bearing_lab import RecordingError, check_dataset, open_recording

SETTINGS = settings(max_examples=12, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.too_slow,
                                           HealthCheck.function_scoped_fixture])

# (mirror path, bytes kept before fuzzing (None = whole file), options)
REAL = [
    ("lms/binary8byte_g.uff", None, {}),
    ("lms/catman_58_ascii_short.uff", None, {}),
    ("lms/truncated_58_ascii.uff", None, {"allow_truncated": True}),
    ("lms/mpstd_set001_58b_4ch.uff", 12000, {"allow_truncated": True}),
    ("lms/testlab_geometry_only.uff", None, {}),
    ("lms/testlab_acceler.mat", None, {}),
    ("cwru/130_OR007@6_0.mat", None, {}),
    ("mfpt/OuterRaceFault_vload_1.mat", None, {}),
    ("ims/2004.02.12.10.32.39", 60000, {}),
]


def _synthetic():
    import io
    import scipy.io.wavfile
    t = np.arange(400) / 1000.0
    x = np.sin(2 * np.pi * 30 * t)
    csv = "time,a [g],b [m/s2]\n" + "\n".join(f"{a:.4f},{b:.6f},{-b:.6f}" for a, b in zip(t, x))
    txt = "Name\tP1\nRun\tR1\nProject\tX\nIncrement\t0.001\nP1\tP2\ng\tg\nReal\tReal\n" + \
        "\n".join(f"{b:.6f}\t{2 * b:.6f}" for b in x)
    buf = io.BytesIO()
    scipy.io.wavfile.write(buf, 1000, (x * 3000).astype(np.int16))
    return [("rig.csv", csv.encode(), {}), ("export.txt", txt.encode(), {}),
            ("rec.wav", buf.getvalue(), {"full_scale": "5 g"})]


def _check(name, data, opts):
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / name
        p.write_bytes(data)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                ds = open_recording(p, **opts)
            except RecordingError as exc:
                assert p.name in str(exc), str(exc)
                return
        check_dataset(ds, kind="recording")


def _mutate(data, cut, flips):
    b = bytearray(data[:max(1, int(len(data) * cut))])
    for pos, val in flips:
        b[int(pos * (len(b) - 1))] = val
    return bytes(b)


flips = st.lists(st.tuples(st.floats(0, 1), st.integers(0, 255)), max_size=6)
cuts = st.one_of(st.just(1.0), st.floats(0.0, 1.0))


@pytest.mark.parametrize("rel, keep, opts", REAL, ids=[r[0].split("/")[-1] for r in REAL])
def test_fuzz_real(datafile, rel, keep, opts):
    src = datafile(rel)
    data = src.read_bytes()[:keep] if keep else src.read_bytes()
    name = src.name

    @SETTINGS
    @given(cut=cuts, fl=flips)
    def run(cut, fl):
        _check(name, _mutate(data, cut, fl), opts)

    run()


@pytest.mark.parametrize("name, data, opts", _synthetic(), ids=["csv", "testlab_text", "wav"])
def test_fuzz_synthetic(name, data, opts):
    @SETTINGS
    @given(cut=cuts, fl=flips)
    def run(cut, fl):
        _check(name, _mutate(data, cut, fl), opts)

    run()
