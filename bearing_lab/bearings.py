"""Bearing catalog and kinematic (no-slip) fault frequencies.

Geometry is stored in SI (metres, radians).  The kinematic frequencies follow the
standard formulas (Harris & Kotzalas; Randall & Antoni 2011) with
``gamma = D_b / d_m * cos(alpha)``::

    FTF  = f_r / 2 * (1 - gamma)
    BPFO = Z * FTF
    BPFI = Z * f_r / 2 * (1 + gamma)
    BSF  = d_m / (2 D_b) * f_r * (1 - gamma**2)

The paper prints BPFO/BPFI with the wrong form; these are the correct ones.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
import math

from .errors import SceneError

INCH = 0.0254


@dataclass(frozen=True)
class BearingGeometry:
    """Geometry of a rolling bearing (SI units).

    Attributes
    ----------
    name : catalog designation.
    n_balls : number of rolling elements per row (Z).
    ball_diameter : D_b, m.
    pitch_diameter : d_m, m.
    contact_angle : alpha, rad.
    bore, outer_diameter, width : ring envelope, m (None where unknown).
    inner_conformity, outer_conformity : groove radius / ball diameter (f_i, f_o).
    element : "ball" or "roller".
    rows : number of rows.
    source : where the numbers come from.

    See Also
    --------
    get_bearing : a catalog bearing.
    """

    name: str
    n_balls: int
    ball_diameter: float
    pitch_diameter: float
    contact_angle: float = 0.0
    bore: float | None = None
    outer_diameter: float | None = None
    width: float | None = None
    inner_conformity: float = 0.52
    outer_conformity: float = 0.53
    element: str = "ball"
    rows: int = 1
    source: str = ""

    def __post_init__(self):
        if self.n_balls < 3:
            raise SceneError(f"bearing {self.name!r}: n_balls={self.n_balls} must be at least 3")
        if not (self.ball_diameter > 0 and self.pitch_diameter > 0):
            raise SceneError(f"bearing {self.name!r}: ball_diameter and pitch_diameter must be positive")
        if self.ball_diameter >= self.pitch_diameter:
            raise SceneError(
                f"bearing {self.name!r}: ball_diameter={self.ball_diameter} m is not smaller than "
                f"pitch_diameter={self.pitch_diameter} m")
        if self.bore is not None and self.outer_diameter is not None:
            gap = (self.outer_diameter - self.bore) / 2
            if self.ball_diameter >= gap:
                raise SceneError(
                    f"bearing {self.name!r}: ball_diameter={self.ball_diameter*1e3:.3f} mm does not fit "
                    f"in the ring gap (outer_diameter - bore)/2 = {gap*1e3:.3f} mm")
            if not (self.bore < self.pitch_diameter < self.outer_diameter):
                raise SceneError(f"bearing {self.name!r}: pitch_diameter must lie between bore and outer_diameter")
        if self.element == "ball":
            for key in ("inner_conformity", "outer_conformity"):
                f = getattr(self, key)
                if not (0.5 < f < 0.6):
                    raise SceneError(f"bearing {self.name!r}: {key}={f} must lie in (0.5, 0.6) "
                                     "(groove radius over ball diameter; 0.515-0.53 is usual)")
        if self.n_balls * self.ball_diameter >= math.pi * self.pitch_diameter:
            raise SceneError(f"bearing {self.name!r}: {self.n_balls} balls of {self.ball_diameter*1e3:.3f} mm "
                             f"do not fit around the pitch circle")

    @property
    def gamma(self) -> float:
        return self.ball_diameter / self.pitch_diameter * math.cos(self.contact_angle)

    def frequency_factors(self) -> dict:
        """Fault frequencies per unit shaft frequency: ftf, bpfo, bpfi, bsf."""
        g = self.gamma
        z = self.n_balls
        return {
            "ftf": 0.5 * (1 - g),
            "bpfo": z * 0.5 * (1 - g),
            "bpfi": z * 0.5 * (1 + g),
            "bsf": self.pitch_diameter / (2 * self.ball_diameter) * (1 - g * g),
        }

    def fault_frequencies(self, shaft_hz: float) -> dict:
        """Kinematic fault frequencies (Hz) at shaft frequency ``shaft_hz`` (Hz)."""
        return {k: v * shaft_hz for k, v in self.frequency_factors().items()}

    def surface_speed(self, shaft_rad_s: float) -> float:
        """Rolling speed (m/s): the speed at which a ball's contact point travels along either
        raceway, ``omega (d_m^2 - D_b^2) / (4 d_m)`` (the cage's speed relative to the race times
        the contact radius; pure rolling, zero contact angle)."""
        dm, db = self.pitch_diameter, self.ball_diameter
        return shaft_rad_s * (dm * dm - db * db) / (4 * dm)

    def with_(self, **changes) -> "BearingGeometry":
        return replace(self, **changes)


CATALOG: dict[str, BearingGeometry] = {
    "6308": BearingGeometry(
        "6308", 8, 15.081e-3, 65.0e-3, 0.0, bore=40e-3, outer_diameter=90e-3, width=23e-3,
        source="Liu et al., Table 1 (6308-2RZ); conformities 0.52/0.53 assumed "
               "(Harris & Kotzalas typical deep-groove values)"),
    "6205": BearingGeometry(
        "6205", 9, 0.3126 * INCH, 1.537 * INCH, 0.0, bore=25e-3, outer_diameter=52e-3, width=15e-3,
        source="CWRU drive end, 6205-2RS JEM SKF (CWRU bearing data center)"),
    "6203": BearingGeometry(
        "6203", 8, 0.2656 * INCH, 1.122 * INCH, 0.0, bore=17e-3, outer_diameter=40e-3, width=12e-3,
        source="CWRU fan end, 6203-2RS JEM SKF (CWRU bearing data center)"),
    "ZA-2115": BearingGeometry(
        "ZA-2115", 16, 0.331 * INCH, 2.815 * INCH, math.radians(15.17), element="roller", rows=2,
        source="IMS/NASA run-to-failure rig, Rexnord ZA-2115 double-row (Qiu et al. 2006)"),
    "MFPT": BearingGeometry(
        "MFPT", 8, 0.235 * INCH, 1.245 * INCH, 0.0, element="roller",
        source="MFPT fault data set (NICE bearing), 8 rollers 0.235 in, pitch 1.245 in"),
}


def get_bearing(name: str) -> BearingGeometry:
    """Return the catalog bearing ``name`` (e.g. "6308", "6205").

    Raises
    ------
    SceneError
        An unknown name, with the catalog's names.

    See Also
    --------
    BearingGeometry, CATALOG, bearing_lab.sim.load_scene

    Examples
    --------
    >>> b = get_bearing("6308")
    >>> b.n_balls, round(b.fault_frequencies(30.0)["bpfo"], 2)     # Z/2 (1 - D_b/d_m) f_r at 30 Hz
    (8, 92.16)
    """
    try:
        return CATALOG[str(name)]
    except KeyError:
        msg = (f"unknown bearing {name!r}; the catalog has {', '.join(sorted(CATALOG))} "
               "(or give the geometry explicitly)")
        raise SceneError(msg) from None
