"""Dynamic cage (cage and ball orbital/spin motion from traction and pocket contact)."""
import math

import numpy as np
import pytest

from bearing_lab import get_bearing, simulate
from bearing_lab.errors import SceneError
from tests.naive import impulse_times


def test_loaded_bearing_rolls_near_the_kinematic_cage_speed():
    """Under 480 N the load zone drives the cage: its mean speed within 1 % of FTF, and the
    slot's impacts keep the kinematic period within 0.5 %."""
    ds = simulate("paper-slot", duration=0.3, progress=False, fidelity="multibody",
                  **{"cage.model": "dynamic", "load.radial_n": 480.0})
    ftf = get_bearing("6308").fault_frequencies(30.0)["ftf"]
    cage_hz = float(ds.cage_speed.mean()) / (2 * math.pi)
    assert cage_hz == pytest.approx(ftf, rel=0.01)
    assert cage_hz < ftf  # traction needs slip: the cage lags, never leads
    t = impulse_times(ds.outer_ring_acc_y.values, 20000.0, 0.5, dead_time=0.005)
    period = np.polyfit(np.arange(len(t)), t, 1)[0]
    assert period == pytest.approx(1 / (8 * ftf), rel=5e-3)


def test_unloaded_bearing_skids():
    """With no radial load (no gravity) nothing drives the balls: the cage falls behind the
    kinematic speed (skidding), the classical light-load result."""
    ds = simulate("paper-healthy", duration=0.2, progress=False, fidelity="multibody",
                  **{"cage.model": "dynamic", "load.radial_n": 0.0, "gravity.enabled": False,
                     "clearance.radial_um": 10.0})
    ftf = get_bearing("6308").fault_frequencies(30.0)["ftf"] * 2 * math.pi
    assert float(ds.cage_speed[-200:].mean()) < 0.99 * ftf
    assert np.all(np.isfinite(ds.outer_ring_acc_y))


def test_quasi_static_with_dynamic_cage_refused():
    with pytest.raises(SceneError, match="needs fidelity='multibody'"):
        simulate("paper-slot", duration=0.01, progress=False, fidelity="quasi-static",
                 **{"cage.model": "dynamic"})
