"""`case new` on a recording stored in volts: the sensor sensitivity is an option, written to the case,
and the case then reads the file in the same acceleration units as `import --sensitivity` does."""
import numpy as np
import pytest

from bearing_lab.cli import main
from bearing_lab.io import open_recording
from bearing_lab.validation import load_case


@pytest.fixture(scope="module")
def sample(tmp_path_factory):
    d = tmp_path_factory.mktemp("volts")
    assert main(["data", "sample", "-o", str(d / "rec.uff"), "-q"]) == 0
    return d / "rec.uff"


def test_without_a_sensitivity_the_error_names_the_option(sample, capsys):
    out = sample.with_name("nosens.toml")
    assert main(["case", "new", str(sample), "--bearing", "6308", "--speed", "1800", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "--sensitivity" in err and "in V" in err and not out.exists()


def test_the_sensitivity_is_written_and_the_case_reads_the_file_with_it(sample, capsys):
    out = sample.with_name("sens.toml")
    assert main(["case", "new", str(sample), "--bearing", "6308", "--speed", "1800",
                 "--sensitivity", "9.91mV/g", "-o", str(out), "-q"]) == 0
    with out.open("a") as fh:                       # what the user adds (the file cannot tell it)
        fh.write('\n[load]\nradial_n = 300.0\non = "inner"\n')
    case = load_case(out)
    assert case.recording.sensitivity == "9.91mV/g"
    via_case = open_recording(case.recording.file, **case.recording.read_options())
    volts = open_recording(sample, sensitivity=False)
    ch = next(iter(volts.data_vars))
    assert via_case[ch].attrs["units"] == "m s-2" and volts[ch].attrs["units"] == "V"
    # 1 V at 9.91 mV/g is 1 / 9.91e-3 g = 989.6 m/s²: the scale a user's sensor sheet gives
    ratio = via_case[ch].values / volts[ch].values
    np.testing.assert_allclose(ratio[np.abs(volts[ch].values) > 1e-6], 9.80665 / 9.91e-3, rtol=1e-6)
