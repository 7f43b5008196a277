"""The compiled kernels' arguments, grouped by role into named tuples numba compiles for.

A named tuple is passed to a compiled function as its fields, its fields are read by name, and
numba's disk cache keys the code on the field types, so one compiled loop serves every scene of a
kind (the time loop runs as fast as with separate arguments, within 1 %, measured).  The fields'
types must not change from call to call (``int`` stays ``int``, ``float`` stays ``float``, arrays
keep their dtype and number of dimensions), or the loop is compiled again for the new types.

Where the tuples stop: the small helpers inlined at many call sites (``_kernels.rel_angle``,
``find_zone``, ``_zone_candidates``, the geometry of ``_stepper.step_limit``) and the contact laws
(``contact_force``, ``_qs_ball``) keep their scalar and array arguments.  Building or unpacking a
tuple there cost compile time on a fresh install (``step_limit`` building a :class:`Cage`:
0.1-0.3 CPU s more for the first ``simulate``; the contact laws taking a :class:`Model`: 0.04 s).

- :class:`Model`: the bearing, its loads and speed, the defect tables (what the right-hand side
  reads; built by :attr:`.assembly.Assembly.model`);
- :class:`Cage`: the shaft and the kinematic cage at one time, as the ball models get it;
- :class:`Solver`: the step control's settings;
- :class:`Work`: the state the loop carries from call to call and its scratch arrays
  (:func:`new_work`);
- :class:`Output`: the grids one call writes its dense output on.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np


class Model(NamedTuple):
    """The bearing model the right-hand side evaluates.  All float64 but ``dint`` (int64); constant
    during a run except ``dflt[:, F_REACH]``, which the loop raises (see ``_kernels``)."""

    p: np.ndarray      #: (P_SIZE + 2 Z,) parameter vector, SI units, indices ``_kernels.P_*``
    sp_t: np.ndarray   #: (n,) s: knots of the piecewise-linear shaft speed
    sp_w: np.ndarray   #: (n,) rad/s: shaft speed at the knots
    sp_th: np.ndarray  #: (n,) rad: shaft angle at the knots
    dint: np.ndarray   #: (defects, 7) integer table layout, columns ``_kernels.D_*``
    dflt: np.ndarray   #: (defects, N_DFLT) rad (angles) and m (approaches), columns ``_kernels.F_*``
    hbuf: np.ndarray   #: m: the defects' drop profiles h(psi), end to end
    gbuf: np.ndarray   #: m: the defects' equivalent penetrations G^(2/3)(psi, delta), end to end


class Cage(NamedTuple):
    """The shaft and a kinematic cage at time t (:func:`._kernels.cage_at`)."""

    z: int             #: number of balls
    phic: float        #: rad: cage angle (ball 0 of a kinematic cage)
    c0: float          #: cos(phic)
    s0: float          #: sin(phic)
    phidot: float      #: rad/s: cage angular speed
    theta_s: float     #: rad: shaft angle
    omega_s: float     #: rad/s: shaft speed


class Solver(NamedTuple):
    """Settings of the time loop's step control."""

    method: int          #: 0 Dormand-Prince 5(4), 1 Bogacki-Shampine 3(2), 2 classic RK4 (fixed step)
    rtol: float          #: relative tolerance (1)
    atol: np.ndarray     #: (n,) absolute tolerance of each state, in the state's unit
    hmax: float          #: s: largest step (RK4: its step)
    nsteps_def: float    #: least number of steps per crossing of a defect zone


class Work(NamedTuple):
    """The state the loop carries from one call to the next, and its scratch arrays."""

    y: np.ndarray      #: (n,) the state (SI units), advanced in place
    ctrl: np.ndarray   #: (2,) step controller memory: log of the previous error, last step rejected (1)
    stats: np.ndarray  #: (3,) int64 counts: steps taken, steps rejected, extra right-hand sides
    k: np.ndarray      #: (7, n) the stages' derivatives (k[0]: at the current point)
    ytmp: np.ndarray   #: (n,) a stage's input state (also scratch derivative of ``loads_at``)
    ynew: np.ndarray   #: (n,) the step's new point
    err: np.ndarray    #: (n,) the step's error estimate
    fi: np.ndarray     #: (Z,) N: ball-inner race loads of the last right-hand side
    fo: np.ndarray     #: (Z,) N: ball-outer race loads of the last right-hand side


class Output(NamedTuple):
    """The dense output one call of the loop writes, on two grids (times within the call's span)."""

    vel_idx: np.ndarray    #: (channels, 2) int64: the state indices summed into each velocity channel (-1: none)
    vel_sign: np.ndarray   #: (channels, 2): their signs
    fine_t: np.ndarray     #: (nf,) s: the fine (accelerometer) grid
    fine_out: np.ndarray   #: (nf, channels) m/s: the velocity channels at ``fine_t`` (written)
    out_t: np.ndarray      #: (no,) s: the output grid
    out_state: np.ndarray  #: (no, n): the whole state at ``out_t`` (written)


def new_work(y0, z) -> Work:
    """The loop's :class:`Work` for a run from state ``y0`` (copied) with ``z`` balls."""
    n = y0.size
    return Work(y=y0.copy(), ctrl=np.array([math.log(1e-4), 0.0]), stats=np.zeros(3, dtype=np.int64),
                k=np.zeros((7, n)), ytmp=np.empty(n), ynew=np.empty(n), err=np.empty(n), fi=np.empty(z),
                fo=np.empty(z))
