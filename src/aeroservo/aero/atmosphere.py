"""The 1976 U.S. Standard Atmosphere (= ICAO/ISA up to 32 km) and the speeds of the field.

Geopotential altitude ``H`` [m] from -1 000 m to 47 000 m (or geometric altitude
``Z = r0 H / (r0 - H)``, r0 = 6 356 766 m, with ``geometric=True``: tables by geometric
altitude differ by 1 % in density at 20 km); layers with constant lapse rates
(-6.5 K/km to 11 km, isothermal to 20 km, +1 K/km to 32 km, +2.8 K/km to 47 km). Temperature
``T`` [K], pressure ``p`` [Pa] (hydrostatic), density ``rho = p / (R T)`` [kg/m^3] and speed of
sound ``a = sqrt(gamma R T)`` [m/s], with R = 287.05287 J/(kg K) (R* / M0 of the standard),
gamma = 1.4, g0 = 9.80665 m/s^2.

Speeds: true airspeed (TAS) ``V`` [m/s]; equivalent airspeed ``EAS = V sqrt(rho / rho0)`` with
rho0 = 1.225 kg/m^3; Mach number ``M = V / a``; knots = m/s / 0.514444.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import InputError, check_number

__all__ = [
    "Atmosphere",
    "isa",
    "isa_ft",
    "isa_slopes",
    "on_layer_boundary",
    "FT",
    "KNOT",
    "RHO0",
    "eas",
    "tas_from_eas",
    "ALTITUDE_RANGE",
]

G0 = 9.80665
R_AIR = 287.05287
GAMMA = 1.4
R_EARTH = 6356766.0

T0 = 288.15
P0 = 101325.0
RHO0 = 1.225
"""Sea-level standard density [kg/m^3] (the reference of equivalent airspeed)."""

FT = 0.3048
"""One foot [m]."""

KNOT = 1852.0 / 3600.0
"""One knot [m/s]."""

# layer base geopotential altitude [m], lapse rate [K/m]
_LAYERS = ((0.0, -0.0065), (11000.0, 0.0), (20000.0, 0.001), (32000.0, 0.0028))
ALTITUDE_RANGE = (-1000.0, 47000.0)
"""Geopotential altitudes the model covers [m]."""


@dataclass(frozen=True)
class Atmosphere:
    """The standard atmosphere at one altitude (SI units).

    Attributes
    ----------
    altitude : float
        Geopotential altitude [m].
    temperature : float
        [K]
    pressure : float
        [Pa]
    density : float
        [kg/m^3]
    speed_of_sound : float
        [m/s]
    """

    altitude: float
    temperature: float
    pressure: float
    density: float
    speed_of_sound: float

    def mach(self, speed: float) -> float:
        """Mach number of a true airspeed [m/s]."""
        return speed / self.speed_of_sound

    def eas(self, speed: float) -> float:
        """Equivalent airspeed [m/s] of a true airspeed [m/s]."""
        return eas(speed, self.density)


def _layer_state(h: float) -> tuple[float, float]:
    """Temperature [K] and pressure [Pa] at geopotential altitude h [m] (layer by layer)."""
    T, p = T0, P0
    for i, (base, lapse) in enumerate(_LAYERS):
        top = _LAYERS[i + 1][0] if i + 1 < len(_LAYERS) else math.inf
        dh = min(h, top) - base
        if lapse == 0.0:
            p *= math.exp(-G0 * dh / (R_AIR * T))
        else:
            T_end = T + lapse * dh
            p *= (T_end / T) ** (-G0 / (lapse * R_AIR))
            T = T_end
        if h <= top:
            break
    return T, p


def isa(altitude: float, *, geometric: bool = False) -> Atmosphere:
    """The standard atmosphere at an altitude [m].

    Parameters
    ----------
    altitude : float
        Geopotential altitude [m] (the standard's own variable), or geometric altitude (height
        above mean sea level) with ``geometric=True``.
    geometric : bool
        Whether ``altitude`` is geometric.

    Returns
    -------
    Atmosphere
        Its ``altitude`` is the geopotential one.

    Raises
    ------
    InputError
        Outside :data:`ALTITUDE_RANGE`.
    """
    h = check_number("altitude", altitude, unit="m", lo=ALTITUDE_RANGE[0], hi=ALTITUDE_RANGE[1])
    if not isinstance(geometric, bool):
        raise InputError(f"geometric = {geometric!r}: expected True or False")
    if geometric:
        h = R_EARTH * h / (R_EARTH + h)
    T, p = _layer_state(h)
    rho = p / (R_AIR * T)
    return Atmosphere(h, T, p, rho, math.sqrt(GAMMA * R_AIR * T))


def isa_at_density(density: float) -> Atmosphere:
    """The standard atmosphere whose density is ``density`` [kg/m^3] (the altitude clipped to
    :data:`ALTITUDE_RANGE`): the speed of sound a density-only flight condition implies."""
    rho = check_number("density", density, unit="kg/m^3", lo=0.0, lo_open=True)
    lo, hi = ALTITUDE_RANGE
    if rho >= isa(lo).density:
        return isa(lo)
    if rho <= isa(hi).density:
        return isa(hi)
    for _ in range(200):  # bisection: the density decreases with altitude
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if isa(mid).density > rho else (lo, mid)
        if hi - lo < 1e-6:
            break
    return isa(0.5 * (lo + hi))


def isa_slopes(atmosphere: Atmosphere, side: int = -1) -> tuple[float, float]:
    """Derivatives of density and speed of sound with geopotential altitude.

    From the hydrostatic equation and the ideal gas, ``drho/dH = -rho (g0 / (R T) + T' / T)``
    and ``da/dH = a T' / (2 T)``, with the lapse rate ``T'`` of the layer. At a layer's top
    (:func:`on_layer_boundary`) the slopes have a kink: ``side`` -1 gives those of the layer
    below, +1 of the layer above.

    Returns
    -------
    (drho_dH, da_dH) : float
        [kg/m^3 per m], [1/s].
    """
    h, T = atmosphere.altitude, atmosphere.temperature
    above = side > 0 and on_layer_boundary(h)
    lapse = next(
        lp for base, lp in reversed(_LAYERS) if (h >= base if above else h > base) or base == 0.0
    )
    drho = -atmosphere.density * (G0 / (R_AIR * T) + lapse / T)
    return drho, atmosphere.speed_of_sound * lapse / (2.0 * T)


def on_layer_boundary(altitude: float) -> bool:
    """Whether a geopotential altitude [m] is a boundary between two layers of different
    lapse rates (11, 20 and 32 km), where density and speed of sound have kinks."""
    return any(abs(altitude - base) <= 1e-9 * base for base, _ in _LAYERS[1:])


def isa_ft(altitude_ft: float, *, geometric: bool = False) -> Atmosphere:
    """The standard atmosphere at an altitude given in feet (geopotential by default)."""
    ft = check_number(
        "altitude_ft",
        altitude_ft,
        unit="ft",
        lo=ALTITUDE_RANGE[0] / FT,
        hi=ALTITUDE_RANGE[1] / FT,
    )
    return isa(ft * FT, geometric=geometric)


def eas(speed: float, density: float) -> float:
    """Equivalent airspeed [m/s] of a true airspeed [m/s] at a density [kg/m^3]."""
    return speed * math.sqrt(density / RHO0)


def tas_from_eas(eas_speed: float, density: float) -> float:
    """True airspeed [m/s] of an equivalent airspeed [m/s] at a density [kg/m^3]."""
    return eas_speed * math.sqrt(RHO0 / density)
