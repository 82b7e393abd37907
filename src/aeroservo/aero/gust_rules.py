"""The numbers of the discrete-gust rule CS-25.341(a) / 14 CFR 25.341(a) (SI interfaces).

* :func:`reference_gust_velocity` - U_ref: 56 ft/s EAS at sea level, 44 ft/s at 15 000 ft,
  20.86 ft/s at 60 000 ft, linear in altitude between; one half at V_D (25.341(a)(5)(i), (iii));
* :func:`flight_profile_alleviation` - F_g (25.341(a)(6)): at sea level
  ``(F_gz + F_gm) / 2`` with ``F_gz = 1 - Z_mo / 250 000 ft`` and
  ``F_gm = sqrt(R2 tan(pi R1 / 4))``, ``R1 = MLW/MTOW``, ``R2 = MZFW/MTOW``; rising linearly to 1
  at Z_mo (the maximum operating altitude) and 1 above;
* :func:`design_gust_velocity` - ``U_ds = U_ref F_g (H / 350 ft)^(1/6)`` EAS, H the gust
  gradient from 30 ft (9.144 m) to 350 ft (106.68 m) (25.341(a)(2), (a)(4));
* :func:`gust_tas` - an EAS velocity turned into a true one through the ISA density.

The rule is written in feet; the feet appear here only in the table constants, converted by the
international foot (1 ft = 0.3048 m exactly, :data:`aeroservo.aero.atmosphere.FT`). Altitudes
are pressure altitudes [m] (the ISA geopotential altitude of :func:`aeroservo.aero.atmosphere.isa`).
The gust profile itself is ``U(s) = U_ds / 2 (1 - cos(pi s / H))`` over ``0 <= s <= 2 H``
(:mod:`aeroservo.studies.gust.tuned`).
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import InputError, check_number
from .atmosphere import FT, isa, tas_from_eas

__all__ = [
    "GRADIENT_RANGE",
    "U_REF_TABLE",
    "design_gust_velocity",
    "flight_profile_alleviation",
    "gust_tas",
    "reference_gust_velocity",
]

U_REF_TABLE = (
    (0.0, 56.0 * FT),
    (15000.0 * FT, 44.0 * FT),
    (60000.0 * FT, 20.86 * FT),
)
"""(altitude [m], U_ref [m/s EAS]) of 25.341(a)(5)(i), linear between the rows."""
GRADIENT_RANGE = (30.0 * FT, 350.0 * FT)
"""Gust gradient distances H [m] the rule searches: 30 ft to 350 ft (9.144 m to 106.68 m)."""

GRADIENT_ROUNDING = 0.02
"""Relative tolerance at the ends of :data:`GRADIENT_RANGE`: the field's usual metric values
9 m and 107 m (30 ft and 350 ft rounded) are taken as the ends (a value within 2 % outside
them is the end itself)."""
Z_REF = 250000.0 * FT
"""The 250 000 ft of F_gz [m]."""


def _altitude(altitude: float) -> float:
    top = U_REF_TABLE[-1][0]
    return check_number(
        "altitude", altitude, unit="m (the rule's table: 0 to 60 000 ft)", lo=0.0, hi=top
    )


def reference_gust_velocity(altitude: float, *, at_vd: bool = False) -> float:
    """U_ref [m/s EAS] at a pressure altitude [m] (0 to 18 288 m); one half at V_D.

    Parameters
    ----------
    altitude : float
        Altitude [m].
    at_vd : bool
        At the design dive speed V_D the rule's values are halved (25.341(a)(5)(iii)).
    """
    h = _altitude(altitude)
    if not isinstance(at_vd, bool):
        raise InputError(f"at_vd = {at_vd!r}: expected True or False")
    hs, us = zip(*U_REF_TABLE, strict=True)
    u = float(np.interp(h, hs, us))
    return 0.5 * u if at_vd else u


def flight_profile_alleviation(
    mlw: float, mzfw: float, mtow: float, z_mo: float, altitude: float = 0.0
) -> float:
    """Flight profile alleviation factor F_g [-] of 25.341(a)(6).

    Parameters
    ----------
    mlw, mzfw, mtow : float
        Maximum landing, zero-fuel and take-off masses [kg] (MLW, MZFW <= MTOW).
    z_mo : float
        Maximum operating altitude [m], in (0, 250 000 ft).
    altitude : float
        Altitude [m]: F_g rises linearly from its sea-level value to 1 at ``z_mo``; 1 above.
    """
    mtow = check_number("mtow", mtow, unit="kg", lo=0.0, lo_open=True)
    mlw = check_number("mlw", mlw, unit="kg (<= mtow)", lo=0.0, lo_open=True, hi=mtow)
    mzfw = check_number("mzfw", mzfw, unit="kg (<= mtow)", lo=0.0, lo_open=True, hi=mtow)
    z_mo = check_number("z_mo", z_mo, unit="m", lo=0.0, lo_open=True, hi=Z_REF, hi_open=True)
    h = check_number("altitude", altitude, unit="m", lo=0.0)
    r1, r2 = mlw / mtow, mzfw / mtow
    f_gz = 1.0 - z_mo / Z_REF
    f_gm = math.sqrt(r2 * math.tan(math.pi * r1 / 4.0))
    f_g0 = 0.5 * (f_gz + f_gm)
    if h >= z_mo:
        return 1.0
    return f_g0 + (1.0 - f_g0) * h / z_mo


def design_gust_velocity(
    gradient: float, altitude: float, f_g: float, *, at_vd: bool = False
) -> float:
    """Design gust velocity U_ds [m/s EAS] = U_ref F_g (H / 350 ft)^(1/6).

    Parameters
    ----------
    gradient : float
        Gust gradient distance H [m] (half the gust length), in :data:`GRADIENT_RANGE`.
    altitude : float
        Altitude [m].
    f_g : float
        Flight profile alleviation factor, in (0, 1].
    at_vd : bool
        Halve U_ref (design dive speed).
    """
    lo, hi = GRADIENT_RANGE
    h_g = check_number(
        "gust gradient H",
        gradient,
        unit="m",
        lo=lo * (1 - GRADIENT_ROUNDING),
        hi=hi * (1 + GRADIENT_ROUNDING),
    )
    h_g = min(max(h_g, lo), hi)  # 9 m and 107 m: the rule's 30 ft and 350 ft, rounded
    f_g = check_number("f_g", f_g, lo=0.0, lo_open=True, hi=1.0)
    u_ref = reference_gust_velocity(altitude, at_vd=at_vd)
    return u_ref * f_g * (h_g / GRADIENT_RANGE[1]) ** (1.0 / 6.0)


def gust_tas(eas_velocity: float, altitude: float) -> float:
    """True gust velocity [m/s] of an equivalent one [m/s EAS] at an altitude [m] (ISA)."""
    return tas_from_eas(eas_velocity, isa(_altitude(altitude)).density)
