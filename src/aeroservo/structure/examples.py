"""Built-in wings.

* :func:`goland` - the clean Goland wing (Goland 1945; SI values as used by SHARPy, AeroBeams.jl,
  Aeroelasticity.jl; see ``shared/reference`` case ``goland_clean_modes``).
* :func:`goland_aileron` - the Goland wing with a trailing-edge aileron from 60 % span to the tip.
  **Illustrative**: the aileron data of Mozaffari-Jovin et al. (2015), used by the seed paper,
  are not publicly available, so the aileron parameters below are aeroservo's own choice and
  its flutter speed is not comparable with the seed's 109.5 m/s.
"""

from __future__ import annotations

from .wing import Actuator, ControlSurface, Segment, Wing

__all__ = ["goland", "goland_aileron", "BUILTIN_WINGS"]

GOLAND_SPAN = 6.096  # m (20 ft)
GOLAND_SEMICHORD = 0.9144  # m (chord 6 ft)


def goland(GJ: float = 0.99e6, EI: float = 9.77e6) -> Wing:
    """The clean Goland wing.

    Semi-span 6.096 m, chord 1.8288 m, elastic axis at 33 % chord (a = -0.34), CG at 43 % chord
    (x_alpha = 0.2), 35.71 kg/m, 8.64 kg m about the elastic axis.

    Parameters
    ----------
    GJ : float
        Torsional stiffness [N m^2]; 0.99e6 (AeroBeams.jl, Aeroelasticity.jl) by default,
        0.987581e6 in SHARPy.
    EI : float
        Bending stiffness [N m^2]; 9.77e6 by default (SHARPy: 9.77221e6).
    """
    seg = Segment(
        start=0.0,
        end=GOLAND_SPAN,
        semichord=GOLAND_SEMICHORD,
        a=-0.34,
        mass=35.71,
        x_alpha=0.2,
        inertia=8.64,
        EI=EI,
        GJ=GJ,
        name="goland",
    )
    return Wing(span=GOLAND_SPAN, segments=(seg,), name="Goland wing")


AILERON = {
    "start": 0.6 * GOLAND_SPAN,
    "end": GOLAND_SPAN,
    "hinge": 0.6,  # 80 % chord: aileron chord 0.366 m
    "static_moment": 0.36576,  # kg m/m: 2 kg/m of aileron, CG at mid aileron chord
    "inertia": 0.089177,  # kg m: 2 kg/m x (0.36576 m)^2 / 3 about the hinge
    "GJ": 2.0e4,  # N m^2
    "hinge_stiffness": 500.0,  # N m/rad per m
    "actuator_stations": (0.7 * GOLAND_SPAN, 0.9 * GOLAND_SPAN),
    "actuator_stiffness": 8.0e3,  # N m/rad each
}
"""Illustrative aileron parameters of :func:`goland_aileron` (aeroservo's choice, not published)."""


def goland_aileron(
    actuator_stiffness: float = AILERON["actuator_stiffness"],
    hinge_stiffness: float = AILERON["hinge_stiffness"],
) -> Wing:
    """Goland wing with an aileron from 60 % span to the tip (illustrative parameters).

    The wing section properties are those of :func:`goland` (they include the aileron). The
    aileron spans 3.658-6.096 m with the hinge at 80 % chord, 2 kg/m of aileron mass with its CG
    at mid aileron chord (mass unbalanced), two actuators at 70 % and 90 % span and a weak
    distributed hinge spring. See ``AILERON`` for the numbers.

    Parameters
    ----------
    actuator_stiffness : float
        Stiffness of each of the two actuators [N m/rad].
    hinge_stiffness : float
        Distributed hinge stiffness [N m/rad per m].
    """
    base = goland()
    p = AILERON
    aileron = ControlSurface(
        name="aileron",
        start=p["start"],
        end=p["end"],
        hinge=p["hinge"],
        static_moment=p["static_moment"],
        inertia=p["inertia"],
        GJ=p["GJ"],
        hinge_stiffness=hinge_stiffness,
        actuators=tuple(
            Actuator(station=s, stiffness=actuator_stiffness, name=f"actuator{i + 1}")
            for i, s in enumerate(p["actuator_stations"])
        ),
    )
    return Wing(
        span=base.span,
        segments=base.segments,
        control_surfaces=(aileron,),
        name="Goland wing with aileron (illustrative)",
    )


BUILTIN_WINGS = {"goland": goland, "goland_aileron": goland_aileron}
"""Wings available by name on the command line and in scenario files."""
