"""fidelity/solver "auto": on scenes NOT used to make the rules (the bench scenes are paper-healthy,
paper-slot, paper-O1 at H = B/2, paper-O2 at 60°, cwru-or007-6 and paper-slot at 300 r/min),
auto's error stays within the default tolerance (1 % peak acceleration, 0.1 % period) of a
converged reference, and the choice is recorded in the output."""
import numpy as np
import pytest

from bearing_lab import simulate
from bearing_lab.analysis import excitation_period

CASES = [
    ("paper-O3", {"speed_rpm": 1200.0}, "bpfo"),
    ("cwru-or021-6", {}, "bpfo"),
    ("cwru-ir007", {}, "bpfi"),
    ("paper-O2", {"defect.offset_mm": 0.25, "defect.skew_deg": 20.0}, "bpfo"),
]


@pytest.mark.parametrize("scene,ov,line", CASES)
def test_auto_within_tolerance_on_unseen_scenes(scene, ov, line):
    auto = simulate(scene, duration=0.3, progress=False, **ov)
    assert "auto rule" in auto.attrs["auto_choice"]
    ref = simulate(scene, duration=0.3, progress=False, fidelity="multibody", method="dp54", rtol=1e-9,
                   **{"solver.max_step_s": 2e-6}, **ov)
    a, r = auto.outer_ring_acc_y.values, ref.outer_ring_acc_y.values
    fs = auto.attrs["sampling_rate_hz"]
    peak_err = abs(np.abs(a).max() - np.abs(r).max()) / np.abs(r).max()
    from bearing_lab import get_bearing
    f = get_bearing(auto.attrs["bearing"]).fault_frequencies(auto.attrs["shaft_speed_rpm"] / 60)[line]
    pa, _ = excitation_period(a, fs, frequency_range=(0.9 * f, 1.1 * f))
    pr, _ = excitation_period(r, fs, frequency_range=(0.9 * f, 1.1 * f))
    print(f"{scene} {ov}: auto = {auto.attrs['fidelity']} {auto.attrs['solver_method']} "
          f"rtol {auto.attrs['solver_rtol']:g}: peak error {peak_err:.1e}, period error {abs(pa - pr) / pr:.1e}")
    assert peak_err < 0.01
    assert abs(pa - pr) / pr < 0.001
