"""The rigid-wing check of the gust loads: the quasi-static loads of the same wing, rigid and
clamped, in the rule's largest discrete gust.

A sharp-edged gust ``U`` [m/s TAS] on a rigid strip-theory wing (lift slope 2 pi, no lag, no
plunge: the wing is clamped) gives the lift per unit span ``L'(y) = 2 pi rho V b(y) U`` at the
quarter chord; integrated outboard of a station ``x``:

* shear ``int_x^l L'``, bending moment ``int_x^l (y - x) L'``, torque about the elastic axis
  ``int_x^l (1/2 + a) b L'`` (positive nose-up, the lift ahead of an elastic axis aft of the
  quarter chord).

This is the Pratt and Walker (NACA TR 1206, 1954) load of the wing alone, without its gust
alleviation factor: a clamped wing has no plunge to relieve it. With ``U`` the rule's largest
design gust (H = 350 ft, CS-25.341(a)(4)), the ratio of a limit load to it reads as a loads
engineer's sanity check: about 1 for a stiff wing in a long gust (the Kussner lag lowers it a
little), above 1 for dynamic and aeroelastic amplification. Defined for unswept strip-theory
wings and the shear, bending moment and torque at the root and at load stations.
"""

from __future__ import annotations

import math

import numpy as np

from ...linear.signals import station_of

__all__ = ["rigid_gust_loads"]


def rigid_gust_loads(wing, loads, density: float, speed: float, gust: float) -> dict:
    """Quasi-static loads of the rigid clamped wing in a sharp-edged gust.

    Parameters
    ----------
    wing : aeroservo.Wing
    loads : sequence of str
        Load names; those that are not a root or station shear, bending moment or torque are
        left out of the result.
    density : float
        [kg/m^3]
    speed : float
        True airspeed [m/s].
    gust : float
        Gust velocity [m/s TAS].

    Returns
    -------
    dict
        Load name -> value [N or N m]; empty for a swept wing (its strips are not the
        streamwise ones of this check).
    """
    if any(abs(getattr(s, "sweep", 0.0)) > 0.0 for s in wing.segments):
        return {}
    out = {}
    q = 2 * math.pi * density * speed * gust  # lift per unit span per metre of semichord
    for name in loads:
        which = station_of(name)
        if which is None:
            continue
        kind, x = which
        total = 0.0
        for seg in wing.segments:
            lo, hi = max(seg.start, x), seg.end
            if hi <= lo:
                continue
            lift = q * seg.semichord  # per unit span, uniform on the segment
            if kind == "shear":
                total += lift * (hi - lo)
            elif kind == "bending_moment":
                total += lift * ((hi - x) ** 2 - (lo - x) ** 2) / 2
            else:
                total += lift * (0.5 + seg.a) * seg.semichord * (hi - lo)
        out[name] = float(total) if np.isfinite(total) else float("nan")
    return out
