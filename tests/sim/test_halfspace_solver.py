"""The half-space contact solver itself: the preconditioned conjugate gradient against the plain
one and against Hertz, its iteration count, the preconditioner as an approximate inverse, and the
solve on the box of the cells that can touch."""
import math

import numpy as np
import pytest

from bearing_lab.bearings import get_bearing
from bearing_lab.sim.defects import Defect, RaceGeometry
from bearing_lab.sim.defects import halfspace_skewed as hsk
from bearing_lab.sim.defects.halfspace import (SOLVE_TOL, TABLE_CELLS, HalfSpace, e_star_of,
                                               intact_contact, love_influence,
                                               preconditioner_stencil)
from bearing_lab.sim.hertz import race_contact

B6308 = get_bearing("6308")
GEOM = RaceGeometry.from_bearing(B6308, "outer")


def _skewed_windows(delta, cells=TABLE_CELLS, n=9):
    """Gaps of a 3 x 1 mm pit at 30 degrees, 0.3 mm off the track centre, for n ball positions
    across it (the kind of window the identification solves most), and the intact gap."""
    d = Defect(length=3e-3, width=1e-3, depth=0.5e-3, offset=0.3e-3, skew=math.radians(30.0))
    g = hsk.skewed_grid(d, GEOM, delta, cells)
    hs = HalfSpace(g.nu, g.nv, g.du, g.dv, e_star_of())
    gi, gf, ins, _ = hsk.windows(d, GEOM, g, np.linspace(-2e-3, 2e-3, n))
    ins &= gi < delta
    return hs, np.where(ins, gf, gi), gi[n // 2]


@pytest.mark.parametrize("delta", [1.0e-6, 4.04e-6, 8.4e-6])
def test_preconditioned_intact_solve_agrees_with_plain_and_hertz(delta):
    """Intact contact on the tables' grid: the preconditioned and the plain solve (same start,
    tight tolerance) give the same force within 1e-5, and both Hertz's K delta^1.5 (Harris &
    Kotzalas' K, sim/hertz.py) within 1 % over the scenes' load range."""
    base = intact_contact(GEOM, delta, tol=1e-8)
    hs, gap = base["solver"], base["gap"]
    p0 = np.where(gap < delta, 1e6, 0.0)
    cell = base["grid"].dx * base["grid"].dy
    f_pc = hs.solve(gap, delta, tol=1e-8, p0=p0)[0].sum() * cell
    f_plain = hs.solve(gap, delta, tol=1e-8, p0=p0, precondition=False)[0].sum() * cell
    assert f_pc == pytest.approx(f_plain, rel=1e-5)
    K = race_contact(B6308.ball_diameter, B6308.pitch_diameter, 0.53, "outer").stiffness
    assert f_pc == pytest.approx(K * delta ** 1.5, rel=0.01)


@pytest.mark.parametrize("delta,cells", [(0.3e-6, TABLE_CELLS), (4.04e-6, TABLE_CELLS),
                                         (15e-6, TABLE_CELLS), (4.04e-6, (16, 12))])
def test_preconditioner_halves_the_iterations_over_a_defect(delta, cells):
    """Ball positions over a skewed pit, at the tables' tolerance: the preconditioned solve takes
    at most 0.7 of the plain solve's iterations (measured 0.55-0.6), and the shares it gives
    agree with a tight plain solve as closely as the plain solve at the tables' tolerance does
    (both within 1e-4 of the intact force; measured 1-3e-5)."""
    hs, gaps, intact_gap = _skewed_windows(delta, cells)
    p_int = hs.solve(intact_gap, delta, tol=1e-8)[0]
    p0 = np.broadcast_to(p_int, gaps.shape)
    exact = hs.solve_batch(gaps, delta, tol=1e-9, p0=p0, precondition=False)[0].sum(axis=(1, 2))
    p_plain, it_plain = hs.solve_batch(gaps, delta, tol=SOLVE_TOL, p0=p0, precondition=False)
    p_pc, it_pc = hs.solve_batch(gaps, delta, tol=SOLVE_TOL, p0=p0)
    assert it_plain.sum() > 50                      # a real count, not a trivial one
    assert it_pc.sum() <= 0.7 * it_plain.sum()
    F = p_int.sum()
    assert np.abs(p_plain.sum(axis=(1, 2)) - exact).max() / F < 1e-4
    assert np.abs(p_pc.sum(axis=(1, 2)) - exact).max() / F < 1e-4
    assert np.all(p_pc >= 0)


@pytest.mark.parametrize("cell_ratio", [1.0, 0.3, 3.0])
def test_stencil_is_an_approximate_inverse_of_the_influence(cell_ratio):
    """On a small grid (dense matrices, independent of the FFT): the influence matrix A of the
    cells (Love's rectangle, every pair) has a condition number that grows with the grid; the
    stencil S applied to it (S A, similar to a symmetric positive definite matrix) has a
    condition number at least 3 times smaller, and positive eigenvalues (measured on 16 x 14
    cells: 25 -> 4.4 on square cells, 32 -> 5.8 on cells 0.3 and 3 times as long as wide)."""
    nx, ny = 16, 14
    dx = 1e-5
    kern = love_influence(nx, ny, dx, dx * cell_ratio, e_star_of())
    idx = np.array([(i, j) for i in range(nx) for j in range(ny)])
    A = kern[np.abs(idx[:, None, 0] - idx[None, :, 0]), np.abs(idx[:, None, 1] - idx[None, :, 1])]
    st = preconditioner_stencil(kern)
    assert st.shape == (3, 3)
    di = idx[:, None, 0] - idx[None, :, 0]
    dj = idx[:, None, 1] - idx[None, :, 1]
    near = (np.abs(di) <= 1) & (np.abs(dj) <= 1)
    S = np.where(near, st[np.clip(di + 1, 0, 2), np.clip(dj + 1, 0, 2)], 0.0)
    ev_a = np.linalg.eigvalsh(A)
    # S A is similar to S^(1/2) A S^(1/2): real eigenvalues, positive if S is positive definite
    ev_s = np.linalg.eigvalsh(S)
    assert ev_s.min() > 0
    root = (np.linalg.eigh(S)[1] * np.sqrt(ev_s)) @ np.linalg.eigh(S)[1].T
    ev_sa = np.linalg.eigvalsh(root @ A @ root)
    cond_a, cond_sa = ev_a.max() / ev_a.min(), ev_sa.max() / ev_sa.min()
    assert ev_sa.min() > 0
    assert cond_sa < cond_a / 3


def test_solve_on_the_box_of_touching_cells_matches_the_whole_window():
    """A window with a wide margin the ball cannot reach is solved on the box of the cells that
    can (a smaller transform); the pressures equal those of the whole window's solve within the
    solver's tolerance, and the margin carries none."""
    hs, gaps, _ = _skewed_windows(4.04e-6, n=5)
    allowed = gaps < 4.04e-6
    rows = np.flatnonzero(allowed.any(axis=(0, 2)))
    assert rows[0] >= 2 and rows[-1] <= hs.nx - 3          # there is a margin to leave out
    p_box, _ = hs.solve_batch(gaps, 4.04e-6, tol=1e-8)
    p_all, _ = hs._iterate(gaps, 4.04e-6, 1e-8, 3000, None, True)
    assert np.abs(p_box - p_all).max() < 1e-5 * p_all.max()
    assert np.all(p_box[~allowed] == 0)


@pytest.mark.parametrize("direct", [True, False])
@pytest.mark.parametrize("shear", [0, 2])
def test_displacement_is_the_direct_sum_of_the_influence(direct, shear, monkeypatch):
    """The pruned single-precision convolution, through pocketfft directly and through the public
    scipy.fft functions (the fallback for another scipy), against the direct sum of Love's rectangle
    influence over every pair of cells (in a sheared layout, cell (i, j) being the grid's
    (i, j + m i)), for a batch of random pressures: within 1e-6 of the largest displacement (single
    precision), each problem on its own."""
    from bearing_lab.sim.defects import _transforms
    monkeypatch.setattr(_transforms, "DIRECT", [direct])
    nx, ny = 9, 7
    hs = HalfSpace(nx, ny, 2e-5, 1e-5, e_star_of(), shear=shear)
    p = np.random.default_rng(5).random((3, nx, ny)) * 1e9
    p[1] = 0.0
    i, j = np.meshgrid(np.arange(nx), np.arange(ny), indexing="ij")
    di = np.abs(i.ravel()[:, None] - i.ravel()[None, :])
    dj = np.abs((j.ravel() + shear * i.ravel())[:, None] - (j.ravel() + shear * i.ravel())[None, :])
    kern = love_influence(nx, ny + shear * nx, 2e-5, 1e-5, e_star_of())
    brute = np.einsum("ab,kb->ka", kern[di, dj], p.reshape(3, -1)).reshape(p.shape)
    u = hs.displacement(p)
    assert u.dtype == np.float64 and u.shape == p.shape
    assert np.all(u[1] == 0.0)
    assert np.abs(u - brute).max() < 1e-6 * np.abs(brute).max()
    np.testing.assert_allclose(hs.displacement(p[0]), u[0], rtol=0, atol=1e-7 * np.abs(brute).max())


@pytest.mark.parametrize("race", ["outer", "inner"])
@pytest.mark.parametrize("depth", [0.0, 0.5e-3])
def test_compiled_window_gap_is_the_geometry_gap(race, depth):
    """The skewed windows' compiled gap against RaceGeometry.approach (numpy) at random points,
    a third of them out of the ball's reach (there 1.0, where approach gives +inf): equal to
    the last bits."""
    geom = RaceGeometry.from_bearing(B6308, race)
    rng = np.random.default_rng(3)
    S, Z = rng.uniform(-8e-3, 8e-3, (3, 40, 30)), rng.uniform(-9e-3, 9e-3, (3, 40, 30))
    ref = geom.approach(S / geom.track_radius, Z, depth=depth)
    assert 0.2 < np.mean(~np.isfinite(ref)) < 0.6
    got = hsk._gap(geom, S, Z, depth)
    assert got.shape == S.shape
    np.testing.assert_allclose(got, np.where(np.isfinite(ref), ref, 1.0), rtol=1e-13, atol=1e-18)


@pytest.mark.parametrize("race", ["outer", "inner"])
@pytest.mark.parametrize("delta", [0.5e-6, 4.04e-6, 15e-6])
def test_compiled_windows_are_the_numpy_windows(race, delta):
    """A skewed ratio curve's windows from the one compiled pass (the floor's gap only where it is
    read) against the numpy windows they stand for (intact gap everywhere, the floor's inside the
    outline, combined where the intact gap is below the approach): the same gaps, cells and sub-cell
    offsets to the last bit, for ball positions across and beyond a pit deep and a pit shallower
    than the approach."""
    geom = RaceGeometry.from_bearing(B6308, race)
    for depth in (0.5e-3, 2e-6):
        d = Defect(length=3e-3, width=1e-3, depth=depth, offset=0.3e-3, skew=math.radians(-45.0), race=race)
        g = hsk.skewed_grid(d, geom, delta, TABLE_CELLS)
        s = np.linspace(-3e-3, 3e-3, 23)
        gi, gf, ins, (fu, fv) = hsk.windows(d, geom, g, s)
        ins &= gi < delta
        gap, ins_c, (fu_c, fv_c) = hsk.window_gaps(d, geom, g, s, delta)
        assert 0 < ins.sum() < ins.size and np.any(gap < delta)
        np.testing.assert_array_equal(ins_c, ins)
        np.testing.assert_array_equal(gap, np.where(ins, gf, gi))
        np.testing.assert_array_equal(fu_c, fu)
        np.testing.assert_array_equal(fv_c, fv)


def test_skewed_window_is_solved_in_a_sheared_layout_with_the_same_solution():
    """The contact over a skewed window lies along a diagonal of its cells: the batch is solved on
    the box of a sheared layout (cell (i, j) of the array is the grid's (i, j + m i)), whose
    transform is at most 0.65 of the unsheared box's (measured 0.56 at 30 degrees), and the
    pressures equal those of the unsheared solve on the whole window within the solver's
    tolerance, cell by cell."""
    hs, gaps, _ = _skewed_windows(4.04e-6, n=5)
    p_shear, it_shear = hs.solve_batch(gaps, 4.04e-6, tol=1e-8)
    sheared = [c for (_, _, m), c in hs._crops.items() if m != 0]
    assert len(sheared) == 1
    allowed = (gaps < 4.04e-6).any(axis=0)
    rows, cols = np.flatnonzero(allowed.any(axis=1)), np.flatnonzero(allowed.any(axis=0))
    plain = HalfSpace(rows[-1] - rows[0] + 1, cols[-1] - cols[0] + 1, hs.dx, hs.dy, hs.e_star)
    assert sheared[0].mx * sheared[0].my <= 0.65 * plain.mx * plain.my
    p_all, it_all = hs._iterate(gaps, 4.04e-6, 1e-8, 3000, None, True)
    assert np.abs(p_shear - p_all).max() < 1e-5 * p_all.max()
    assert np.all(p_shear[gaps >= 4.04e-6] == 0)


@pytest.mark.parametrize("shrink", [False, True])
def test_solve_near_the_start_gives_the_whole_window_solution(shrink, monkeypatch):
    """A batch with a start is solved first on the box around the cells the start presses (a
    smaller transform) and then checked on every cell that can touch.  From the intact pressure
    (over the pit most of it lies on cells that cannot touch) and from a start pressing only the
    middle of the contact (so that the box misses the contact's edge and the check must send
    problems on), the pressures equal the whole window's solve from no start within the solver's
    tolerance, cell by cell, and none falls outside the cells that can touch."""
    delta = 4.04e-6
    hs, gaps, gi = _skewed_windows(delta, n=7)
    p_int, _ = hs.solve(gi, delta, tol=1e-8)
    start = np.where(p_int > 0.8 * p_int.max(), p_int, 0.0) if shrink else p_int
    calls = []
    on_box = HalfSpace._on_box

    def record(self, *a):
        out = on_box(self, *a)
        calls.append((self, int(out[2].sum())))
        return out
    monkeypatch.setattr(HalfSpace, "_on_box", record)
    p_near, _ = hs.solve_batch(gaps, delta, tol=1e-8, p0=np.broadcast_to(start, gaps.shape))
    p_all, _ = hs._iterate(gaps, delta, 1e-8, 3000, None, True)
    assert np.abs(p_near - p_all).max() < 1e-5 * p_all.max()
    assert np.all(p_near[gaps >= delta] == 0)
    # a smaller box was solved, and the start that under-reaches sent problems to the next stage
    box = calls[0][0]
    assert any(c.mx * c.my <= 0.9 * box.mx * box.my for c in box._crops.values())
    if shrink:
        assert calls[0][1] > 0
