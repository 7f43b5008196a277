"""The defect contact in the time loop: a smooth damping force over a defect, the offset
effect at the output a user reads, and the static equilibrium with the balls' centrifugal
force."""
import copy
import math

import numpy as np
import pytest

from bearing_lab import simulate
from bearing_lab.sim import _kernels as K
from bearing_lab.sim import load_scene
from bearing_lab.sim.assembly import assemble
from bearing_lab.units import G as G0


@pytest.mark.parametrize("overrides", [{}, {"defect.length_mm": 3.0, "defect.skew_deg": 60.0}],
                         ids=["O1", "O2-60deg"])
def test_damping_force_is_continuous_over_a_defect(overrides):
    """A ball rolling at the cage speed over the defect at a constant approach and a constant
    approach rate (5 mm/s): the contact force may change only as fast as the elastic part
    does (the table's geometry); the drop profile's slope breaks (at every table node on the
    flanks) must not show.  Damping on ``delta_rate - dh/dpsi * psi_rate`` put a step of
    c_max * jump(dh/dpsi) * psi_rate there (13-21 N on these defects)."""
    sc = load_scene("paper-O1", fidelity="multibody", **overrides)
    asm = assemble(sc)
    p = asm.p
    args = (p, asm.dint, asm.dflt, asm.hbuf, asm.gbuf)
    tab = asm.tables[0]
    delta = (float(np.max(asm.static["ball_loads"])) / p[K.P_KO]) ** (2 / 3)
    reld = p[K.P_FTF] * sc.nominal_rpm * 2 * math.pi / 60
    dpsi = (tab.psi_max - tab.psi_min) / (tab.psi.size - 1)
    psi = np.arange(tab.psi_min + 0.5 * dpsi, tab.psi_max - 0.5 * dpsi, dpsi / 25)
    force = np.array([K.defect_force(0, x, reld, delta, 5e-3, p[K.P_KO], *args) for x in psi])
    undamped = p.copy()
    undamped[K.P_CMAX] = 0.0
    elastic = np.array([K.defect_force(0, x, reld, delta, 5e-3, p[K.P_KO], undamped, *args[1:])
                        for x in psi])
    assert np.ptp(elastic) > 0.3 * elastic.max()              # the defect is felt
    assert np.any(np.abs(np.diff(tab.drop)) > 0)               # with a sloped drop profile
    step_allowed = 2 * np.max(np.abs(np.diff(elastic))) + 1e-9 * elastic.max()
    assert np.max(np.abs(np.diff(force))) <= step_allowed
    # the damping itself is there (STEP on the equivalent penetration), and bounded by c_max
    damping = force - elastic
    assert np.max(damping) == pytest.approx(p[K.P_CMAX] * 5e-3, rel=1e-6)
    assert np.all(damping >= -1e-12) and np.all(damping <= p[K.P_CMAX] * 5e-3 * (1 + 1e-12))


def _peak_after(ds, t0=0.1):
    a = ds.outer_ring_acc_y.values[ds.time.values > t0]
    return float(np.max(np.abs(a)))


@pytest.mark.parametrize("fs", [20_000.0, 100_000.0])
def test_offset_lowers_the_peak_acceleration(fs):
    """paper-O1 as a user runs it (0.3 s, default model and output, max |a| after 0.1 s):
    H = 0 > B/3 > B/2, B/2 at least 8 % below H = 0 and still far above the healthy
    bearing (the same outline 8 mm off the track)."""
    peaks = [_peak_after(simulate("paper-O1", duration=0.3, fs=fs, progress=False,
                                  **{"defect.offset_mm": h})) for h in (0.0, 1 / 3, 0.5, 8.0)]
    h0, h3, h2, healthy = peaks
    assert h0 > h3 > h2, peaks
    assert h2 <= 0.92 * h0, peaks
    assert h2 > 20 * healthy, peaks


def test_ball_loads_balance_the_load_at_3600_rpm():
    """Multibody balls at 3600 r/min (centrifugal force 9.6 N per ball): over the run the
    inner contacts' loads add up to the load on the inner ring (480 N + its weight) to
    0.1 %, so the preloaded shaft spring carries nothing on average; at the start the
    static solution balances each ball between its contacts (Q_o = Q_i + centrifugal -
    weight) and the rings exactly."""
    raw = copy.deepcopy(load_scene("paper-O1").data)
    raw["defect"] = []
    raw["shaft"]["unbalance_g_mm"] = 0.0
    sc = load_scene(raw, fidelity="multibody", speed_rpm=3600.0)
    asm = assemble(sc)
    st = asm.static
    b = sc.bearing
    m_b = sc.masses()[2]
    omega_c = b.frequency_factors()["ftf"] * 3600 / 60 * 2 * math.pi
    body = m_b * (b.pitch_diameter / 2 * omega_c ** 2 - G0 * np.sin(st["phis"]))
    np.testing.assert_allclose(st["ball_loads_outer"] - st["ball_loads_inner"], body, atol=1e-6)
    assert body.mean() > 9.0
    ds = simulate(sc, duration=0.05, progress=False)
    t = ds.time.values + ds.attrs["settle_time_s"]
    phi = st["phis"][:, None] + omega_c * t[None, :]
    fy = np.sum(ds.ball_load_inner.values * np.sin(phi), axis=0)
    fx = np.sum(ds.ball_load_inner.values * np.cos(phi), axis=0)
    applied = st["f_in"]                                   # load + inner-ring weight
    assert applied[1] == pytest.approx(-480.0 - sc.masses()[0] * G0)
    assert fy.mean() == pytest.approx(applied[1], rel=1e-3)
    assert abs(fx.mean()) < 1e-3 * abs(applied[1])


def test_table_time_reported_apart_from_the_time_loop(private_table_cache):
    """Cold: the table is built here; warm: the same table comes from the cache."""
    ds = simulate("paper-O1", duration=0.02, progress=False, **{"defect.length_mm": 1.7})
    assert ds.attrs["table_time_s"] > 0 and ds.attrs["wall_time_s"] > 0
    again = simulate("paper-O1", duration=0.02, progress=False, **{"defect.length_mm": 1.7})
    assert again.attrs["table_time_s"] < 0.5 * ds.attrs["table_time_s"]   # from the cache
