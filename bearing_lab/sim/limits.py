"""Physical limits of a scene, checked before anything runs, and the warning type for likely typos
(:class:`SceneWarning`, warned by :func:`.auto.warn_off_track` and the auto choice).

Why apart from :mod:`.scene`'s per-key checks: these need several keys at once (speed with
the bearing's size, a support's stiffness with the load and the masses) and each guards a
failure that otherwise surfaces deep inside a solver as a foreign exception (a root finder
without a sign change, a filter design without a pass band) or as hours of computing.
"""
from __future__ import annotations

import numpy as np

from ..errors import SceneError


class SceneWarning(UserWarning):
    """A valid scene that probably does not say what was meant (e.g. a defect off the track)."""


MAX_SPEED_FACTOR = 3e6
"""n·d_m (r/min × mm) above which no ball bearing runs: about 1e6 is the usual oil-lubricated
limit, 3e6 the highest in special designs (Harris & Kotzalas, *Rolling Bearing Analysis*, 5th
ed., 2007, vol. 1, ch. 1)."""
MAX_SENSOR_HZ = 1e6
"""Hz: mounted accelerometer resonances lie between a few and some tens of kHz."""
MAX_SUPPORT_DEFLECTION = 1e-2
"""m: a shaft or mount spring that sags more than this under the load and the weights holds no
bearing (a 100 N/m shaft spring put both rings 1.5 m off centre, and softer ones made the
solver fail at its first step)."""


def check_limits(scene) -> None:
    """Raise :class:`SceneError` for a scene outside physical or numerical limits."""
    d = scene.data
    n_out = round(scene.duration * scene.fs_out)
    if n_out < 2:
        raise SceneError(f"output.duration_s={scene.duration:g} s at output.sample_rate_hz="
                         f"{scene.fs_out:g} gives {n_out} sample(s); a record needs at least 2")
    if d["output"]["oversample"] < 2:
        raise SceneError(f"output.oversample={d['output']['oversample']}: the anti-alias filter "
                         "needs a fine grid at least twice the output rate (use 2 or more; "
                         "default 8)")
    f_sensor = d["sensor"]["frequency_hz"]
    if f_sensor > MAX_SENSOR_HZ:
        raise SceneError(f"sensor.frequency_hz={f_sensor:g}: no mounted accelerometer resonates "
                         f"above {MAX_SENSOR_HZ:.0e} Hz (typical mounted resonances: 5-60 kHz)")
    _check_speed(scene)
    _check_supports(scene)


def _check_speed(scene) -> None:
    dm_mm = scene.bearing.pitch_diameter * 1e3
    rpm = float(np.max(scene.speed_profile()[1]))
    if rpm * dm_mm > MAX_SPEED_FACTOR:
        raise SceneError(f"speed {rpm:g} r/min: n·d_m = {rpm * dm_mm:.3g} mm/min is beyond any "
                         f"ball bearing (at most {MAX_SPEED_FACTOR:.0e}; this bearing's limit is "
                         f"{MAX_SPEED_FACTOR / dm_mm:.0f} r/min)")


def _check_supports(scene) -> None:
    """The springs that carry the load to ground must not sag more than a centimetre.

    With ``load.path = "bearing"`` the loaded ring's own spring is preloaded to its static
    position, so the load reaches ground through the other ring's spring; with "springs"
    both share it.
    """
    d, b = scene.data, scene.bearing
    m_i, m_o, m_b = scene.masses()
    g = d["gravity"]["g_m_s2"] if d["gravity"]["enabled"] else 0.0
    load = max(d["load"]["radial_n"], d["load"]["step_radial_n"] or 0.0)
    force = load + (m_i + m_o + b.n_balls * m_b) * g
    carrying = ("shaft", "mount")
    if d["load"]["path"] == "bearing":
        carrying = ("shaft",) if d["load"]["on"] == "outer" else ("mount",)
    for sec in carrying:
        for axis in ("x", "y"):
            k = d[sec][f"stiffness_{axis}_n_m"]
            if force / k > MAX_SUPPORT_DEFLECTION:
                raise SceneError(f"{sec}.stiffness_{axis}_n_m={k:g}: under {force:.3g} N (load "
                                 f"and weights) this support would sag {force / k:.3g} m; a "
                                 f"bearing support gives less than "
                                 f"{MAX_SUPPORT_DEFLECTION * 1e3:g} mm (stiffness at least "
                                 f"{force / MAX_SUPPORT_DEFLECTION:.3g} N/m)")
