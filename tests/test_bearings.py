"""Kinematic frequencies against an independent table computed by hand from Harris &
Kotzalas's formulas (6308: Liu et al., Table 1; 6205/6203: the CWRU bearing data center)."""
import pytest

from bearing_lab import get_bearing
from bearing_lab.errors import SceneError

# Hand-computed FTF, BPFO, BPFI, BSF per unit shaft frequency
REFERENCE = {
    "6308": (0.38399, 3.0719, 4.9281, 2.0390),
    "6205": (0.3983, 3.5848, 5.4152, 2.3567),
    "6203": (0.3816, 3.0531, 4.9469, 1.9938),
}


@pytest.mark.parametrize("name", REFERENCE)
def test_frequency_factors_match_reference(name):
    f = get_bearing(name).frequency_factors()
    ftf, bpfo, bpfi, bsf = REFERENCE[name]
    assert f["ftf"] == pytest.approx(ftf, rel=2e-4)
    assert f["bpfo"] == pytest.approx(bpfo, rel=2e-4)
    assert f["bpfi"] == pytest.approx(bpfi, rel=2e-4)
    assert f["bsf"] == pytest.approx(bsf, rel=2e-4)


def test_6308_at_1800_rpm_and_surface_speed():
    import math
    b = get_bearing("6308")
    f = b.fault_frequencies(30.0)
    assert f["bpfo"] == pytest.approx(92.158, abs=2e-3)
    assert f["bpfi"] == pytest.approx(147.842, abs=2e-3)
    assert f["bsf"] == pytest.approx(61.171, abs=2e-3)
    assert 1 / f["bpfo"] == pytest.approx(0.0108509, rel=1e-5)
    assert b.surface_speed(2 * math.pi * 30) == pytest.approx(2.898, abs=1e-3)


def test_unknown_bearing_is_refused_by_name():
    with pytest.raises(SceneError, match="unknown bearing '6999'"):
        get_bearing("6999")
