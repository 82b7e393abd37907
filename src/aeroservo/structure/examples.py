"""Built-in wings.

* :func:`goland` - the clean Goland wing (Goland 1945; SI values as used by SHARPy, AeroBeams.jl,
  Aeroelasticity.jl; see ``shared/reference`` case ``goland_clean_modes``).
* :func:`goland_aileron` - the Goland wing with a trailing-edge aileron from 60 % span to the tip.
  **Illustrative**: the aileron data of Mozaffari-Jovin et al. (2015), used by the seed paper,
  are not publicly available, so the aileron parameters below are aeroservo's own choice and
  its flutter speed is not comparable with the seed's 109.5 m/s.
* :func:`goland_store` - the Goland wing with a 60 kg underwing store at 75 % span
  (illustrative): a concentrated mass aft of the elastic axis that lowers the flutter speed.
* :func:`goland_swept` - the Goland wing swept back 30 deg (modified strip theory,
  ``docs/sweep.md``); illustrative: the section properties are Goland's, taken normal to the
  swept elastic axis, and the span is measured along it.
"""

from __future__ import annotations

from dataclasses import replace

from .wing import Actuator, ConcentratedMass, ControlSurface, Segment, Wing

__all__ = ["goland", "goland_aileron", "goland_swept", "goland_store", "BUILTIN_WINGS"]

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


def goland_swept(sweep: float = 0.5235987755982988) -> Wing:
    """Goland wing swept back 30 deg (illustrative; sections normal to the elastic axis).

    Goland's section properties and stiffnesses normal to the elastic axis, the 6.096 m span
    measured along it, swept by ``sweep`` [rad] (+ backward, default pi/6 = 30 deg). Same as
    ``scenarios/goland_swept.toml``.

    Parameters
    ----------
    sweep : float
        Sweep angle of the elastic axis [rad], within +-60 deg.
    """
    seg = replace(goland().segments[0], sweep=sweep, name="goland_swept")
    return Wing(span=GOLAND_SPAN, segments=(seg,), name="Goland wing, swept (illustrative)")


def goland_store(mass: float = 60.0, offset: float = 0.3) -> Wing:
    """Goland wing carrying an underwing store at 75 % span (illustrative).

    A pylon-mounted store (e.g. a fuel tank) of ``mass`` [kg] (default 60 kg, 28 % of the
    wing's 218 kg) at 4.572 m, its CG ``offset`` [m] aft of the elastic axis (default 0.3 m, at
    about 50 % chord) and 0.3 m below it, 5 kg m^2 of pitch inertia about its own CG. The aft
    store lowers the flutter speed from 137.8 to 128.3 m/s at sea level (10 elements); moved
    0.3 m ahead of the elastic axis it raises it to 196.4 m/s. Same as
    ``scenarios/goland_store.toml``.

    Parameters
    ----------
    mass : float
        Store mass [kg].
    offset : float
        Chordwise position of the store's CG aft of the elastic axis [m].
    """
    store = ConcentratedMass(
        station=0.75 * GOLAND_SPAN,
        mass=mass,
        offset=offset,
        inertia=5.0,
        vertical_offset=-0.3,
        name="store",
    )
    base = goland()
    return Wing(
        span=base.span,
        segments=base.segments,
        name="Goland wing with store (illustrative)",
        masses=(store,),
    )


BUILTIN_WINGS = {
    "goland": goland,
    "goland_aileron": goland_aileron,
    "goland_swept": goland_swept,
    "goland_store": goland_store,
}
"""Wings available by name on the command line and in scenario files."""
