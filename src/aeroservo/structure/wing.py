"""Wing description: spanwise segments, control surfaces and actuators (SI units).

Every quantity follows ``docs/conventions.md``: x spanwise from the root, y aft, z up;
``a`` and ``hinge`` in semichords aft of mid-chord; ``x_alpha`` = (CG - EA)/b, positive aft.
Section properties (``mass``, ``x_alpha``, ``inertia``) are those of the *whole* section,
control surface included; a control surface adds its own static moment and inertia about
the hinge, which couple the flap rotation to the wing motion.

All classes validate on construction and raise :class:`~aeroservo.errors.InputError` with the
field, the value and the allowed range.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import RANGES, InputError, check_number, check_quantity
from .masses import ConcentratedMass, check_masses

__all__ = ["Segment", "Actuator", "ControlSurface", "Wing", "MAX_SWEEP", "ConcentratedMass"]


@dataclass(frozen=True)
class Segment:
    """A spanwise piece of wing with constant cross-section properties.

    Parameters
    ----------
    start, end : float
        Spanwise stations of the inboard and outboard ends [m], measured from the root.
    semichord : float
        Semichord b [m].
    a : float
        Elastic-axis position in semichords aft of mid-chord [-] (-1 leading edge, +1 trailing
        edge).
    mass : float
        Mass per unit length m [kg/m] (whole section, control surface included).
    x_alpha : float
        Centre-of-gravity offset (CG - EA)/b [-], positive when the CG is aft of the EA.
    inertia : float
        Polar mass moment of inertia per unit length about the elastic axis I_alpha [kg m].
    EI : float
        Flapwise bending stiffness [N m^2].
    GJ : float
        Torsional stiffness [N m^2].
    sweep : float
        Sweep angle of the elastic axis [rad], positive backward (aft), within
        +-:data:`MAX_SWEEP`. Section properties and the strip are normal to the elastic axis
        and ``start``/``end`` are measured along it (``docs/sweep.md``).
    """

    start: float
    end: float
    semichord: float
    a: float
    mass: float
    x_alpha: float
    inertia: float
    EI: float
    GJ: float
    name: str = "segment"
    sweep: float = 0.0

    def __post_init__(self) -> None:
        n = _name("segment", self.name)
        span_hi = RANGES["span"].hi
        check_number(f"{n}.start", self.start, unit="m", lo=0.0, hi=span_hi)
        check_number(f"{n}.end", self.end, unit="m", lo=self.start, hi=span_hi, lo_open=True)
        check_quantity(f"{n}.semichord", self.semichord, "semichord")
        check_number(f"{n}.a", self.a, lo=-1.0, hi=1.0)
        check_quantity(f"{n}.mass", self.mass, "mass_per_length")
        check_number(f"{n}.x_alpha", self.x_alpha, lo=-1.0 - self.a, hi=1.0 - self.a)
        check_quantity(f"{n}.inertia", self.inertia, "inertia_per_length")
        s_alpha = self.mass * self.x_alpha * self.semichord
        i_min = s_alpha**2 / self.mass
        if not self.inertia > i_min:
            raise InputError(
                f"{n}.inertia = {self.inertia:g}: allowed range is ({i_min:g}, inf) [kg m], "
                "above m (x_alpha b)^2, the inertia of the static unbalance alone (mass "
                f"{self.mass:g} kg/m, x_alpha {self.x_alpha:g}, semichord {self.semichord:g} m); "
                + (_unit_hint(self.semichord, self.end - self.start) or "check them")
            )
        check_quantity(f"{n}.EI", self.EI, "stiffness")
        check_quantity(f"{n}.GJ", self.GJ, "stiffness")
        object.__setattr__(self, "sweep", check_sweep(f"{n}.sweep", self.sweep))

    @property
    def static_moment(self) -> float:
        """Static unbalance S_alpha = m x_alpha b about the elastic axis [kg m/m]."""
        return self.mass * self.x_alpha * self.semichord


@dataclass(frozen=True)
class Actuator:
    """A point rotational spring between wing and control surface (the actuator).

    Parameters
    ----------
    station : float
        Spanwise position [m]; must lie on its control surface (need not be a mesh node).
    stiffness : float
        Rotational stiffness k_act [N m/rad].
    """

    station: float
    stiffness: float
    name: str = "actuator"

    def __post_init__(self) -> None:
        n = _name("actuator", self.name)
        check_number(f"{n}.station", self.station, unit="m", lo=0.0, hi=RANGES["span"].hi)
        check_quantity(f"{n}.stiffness", self.stiffness, "actuator_stiffness")


@dataclass(frozen=True)
class ControlSurface:
    """A trailing-edge control surface hinged to the wing over a span interval.

    Parameters
    ----------
    name : str
        Identifier used for inputs/outputs (e.g. ``"aileron"``).
    start, end : float
        Spanwise extent [m].
    hinge : float
        Hinge-line position c in semichords aft of mid-chord [-], in [-1, 1); not ahead of the
        elastic axis.
    static_moment : float
        Flap static moment per unit length about the hinge S_beta [kg m/m], positive when the
        flap CG is aft of the hinge.
    inertia : float
        Flap mass moment of inertia per unit length about the hinge I_beta [kg m].
    GJ : float
        Flap torsional stiffness G_f J_f [N m^2], acting on the spanwise gradient of the flap
        rotation (the seed's diagonal stiffness operator).
    hinge_stiffness : float
        Distributed hinge stiffness k_delta per unit length [N m/rad per m].
    actuators : tuple of Actuator
        Point springs k_act at given stations (Dirac deltas in the stiffness).
    """

    name: str
    start: float
    end: float
    hinge: float
    static_moment: float
    inertia: float
    GJ: float = 0.0
    hinge_stiffness: float = 0.0
    actuators: tuple[Actuator, ...] = field(default_factory=tuple)

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name.isidentifier():
            raise InputError(
                f"control_surface.name = {self.name!r}: must be an identifier "
                "(letters, digits, underscore; used in signal names)"
            )
        n = f"control_surface '{self.name}'"
        object.__setattr__(self, "actuators", _sequence(f"{n}.actuators", self.actuators))
        span_hi = RANGES["span"].hi
        check_number(f"{n}.start", self.start, unit="m", lo=0.0, hi=span_hi)
        check_number(f"{n}.end", self.end, unit="m", lo=self.start, hi=span_hi, lo_open=True)
        check_number(f"{n}.hinge", self.hinge, lo=-1.0, hi=1.0, hi_open=True)
        check_quantity(f"{n}.static_moment", self.static_moment, "static_moment")
        check_quantity(f"{n}.inertia", self.inertia, "inertia_per_length")
        check_quantity(f"{n}.GJ", self.GJ, "flap_stiffness")
        check_quantity(f"{n}.hinge_stiffness", self.hinge_stiffness, "hinge_stiffness")
        for i, act in enumerate(self.actuators):
            if not isinstance(act, Actuator):
                raise InputError(f"{n}.actuators[{i}] = {act!r}: expected an Actuator")
            check_number(
                f"{n}.actuators[{i}].station", act.station, unit="m", lo=self.start, hi=self.end
            )
        if self.hinge_stiffness == 0.0 and not self.actuators:
            raise InputError(
                f"{n}: hinge_stiffness = 0 and no actuators: the surface would float freely "
                "(a zero-frequency rigid mode); give hinge_stiffness > 0 [N m/rad/m] or at "
                "least one actuator"
            )


@dataclass(frozen=True)
class Wing:
    """A cantilever wing clamped at x = 0 (straight, or swept per segment: ``Segment.sweep``).

    Parameters
    ----------
    span : float
        Semi-span L [m].
    segments : tuple of Segment
        Consecutive segments covering [0, span] without gaps or overlaps.
    control_surfaces : tuple of ControlSurface
        Non-overlapping trailing-edge surfaces inside [0, span].
    name : str
        Label used in reports.
    masses : tuple of ConcentratedMass
        Concentrated masses (stores, engines, balance weights), ``structure/masses.py``.
    """

    span: float
    segments: tuple[Segment, ...]
    control_surfaces: tuple[ControlSurface, ...] = field(default_factory=tuple)
    name: str = "wing"
    masses: tuple[ConcentratedMass, ...] = field(default_factory=tuple)

    def __post_init__(self) -> None:
        if not isinstance(self.name, str):
            raise InputError(f"wing.name = {self.name!r}: expected a string")
        object.__setattr__(self, "segments", _sequence("wing.segments", self.segments))
        surfaces = _sequence("wing.control_surfaces", self.control_surfaces)
        object.__setattr__(self, "control_surfaces", surfaces)
        span = check_quantity("wing.span", self.span, "span")
        tol = 1e-9 * span
        if not self.segments:
            raise InputError("wing.segments = []: at least one segment is required")
        x = 0.0
        for i, seg in enumerate(self.segments):
            if not isinstance(seg, Segment):
                raise InputError(f"wing.segments[{i}] = {seg!r}: expected a Segment")
            if abs(seg.start - x) > tol:
                raise InputError(
                    f"wing.segments[{i}].start = {seg.start:g}: must equal the end of the "
                    f"previous segment ({x:g} m); segments must tile [0, span] in order"
                )
            x = seg.end
        if abs(x - span) > tol:
            raise InputError(f"wing.segments[-1].end = {x:g}: must equal wing.span = {span:g} [m]")
        names = set()
        for i, cs in enumerate(self.control_surfaces):
            if not isinstance(cs, ControlSurface):
                raise InputError(f"wing.control_surfaces[{i}] = {cs!r}: expected a ControlSurface")
        surfaces = sorted(self.control_surfaces, key=lambda s: s.start)
        for i, cs in enumerate(surfaces):
            if not isinstance(cs, ControlSurface):
                raise InputError(f"wing.control_surfaces[{i}] = {cs!r}: expected a ControlSurface")
            if cs.name in names:
                raise InputError(f"control_surface.name = {cs.name!r}: duplicate name")
            names.add(cs.name)
            if cs.end > span + tol:
                raise InputError(
                    f"control_surface '{cs.name}'.end = {cs.end:g}: outside the wing, allowed "
                    f"range is [0, {span:g}] [m]"
                )
            if i > 0 and cs.start < surfaces[i - 1].end - tol:
                raise InputError(
                    f"control_surface '{cs.name}'.start = {cs.start:g}: overlaps "
                    f"'{surfaces[i - 1].name}' which ends at {surfaces[i - 1].end:g} [m]"
                )
            for seg in self.segments:
                if seg.end > cs.start + tol and seg.start < cs.end - tol:
                    _check_flap_section(seg, cs)
        for seg in self.segments:
            _check_frequencies(seg, span)
        object.__setattr__(self, "masses", _sequence("wing.masses", self.masses))
        check_masses(self)
        chord = max(seg.semichord for seg in self.segments) * 2
        if chord > span:
            import warnings

            warnings.warn(
                f"wing '{self.name}': chord {chord:g} m longer than the span {span:g} m (aspect "
                "ratio below 1: strip theory does not apply); "
                + (_unit_hint(chord / 2, span) or "check the semichords"),
                UserWarning,
                stacklevel=3,
            )

    def segment_at(self, x: float) -> Segment:
        """Segment containing station ``x`` [m] (the inboard one at a boundary)."""
        for seg in self.segments:
            if x <= seg.end:
                return seg
        return self.segments[-1]

    def surface(self, name: str) -> ControlSurface:
        """Control surface by name; raises :class:`InputError` listing the known names."""
        for cs in self.control_surfaces:
            if cs.name == name:
                return cs
        known = [cs.name for cs in self.control_surfaces] or "none"
        raise InputError(f"control surface {name!r}: unknown; this wing has {known}")

    @property
    def mass(self) -> float:
        """Total wing mass [kg], concentrated masses included."""
        distributed = sum(s.mass * (s.end - s.start) for s in self.segments)
        return float(distributed + sum(pm.mass for pm in self.masses))


def _name(kind: str, name: object) -> str:
    if not isinstance(name, str):
        raise InputError(f"{kind}.name = {name!r}: expected a string")
    return name


def _sequence(field: str, value: object) -> tuple:
    """A tuple of the items of a list or tuple (a single item or a string is refused)."""
    if not isinstance(value, (list, tuple)):
        raise InputError(
            f"{field} = {value!r}: expected a list or tuple (put a single item in a list)"
        )
    return tuple(value)


MAX_SWEEP = float(np.deg2rad(60.0))
"""Largest sweep angle of the elastic axis [rad] (60 deg), forward or backward."""


def check_sweep(field: str, value: object, *, degrees: bool = False) -> float:
    """Validate a sweep angle: a real number within +-:data:`MAX_SWEEP` (+-60 deg), refused with
    the reason beyond it. Returns it in radians (``degrees``: given in degrees)."""
    v = check_number(field, value, unit="deg" if degrees else "rad")
    rad = float(np.deg2rad(v)) if degrees else v
    if abs(rad) > MAX_SWEEP + 5e-5:  # 1.0472 (60 deg to 4 decimals) is accepted, then clipped
        in_deg = f" ({math.degrees(v):.4g} deg)" if abs(v) < 1e6 else ""  # no overflow
        shown = f"{v:g} deg" if degrees else f"{v:g} rad{in_deg}"
        allowed = "[-60, 60] deg" if degrees else "[-1.0472, 1.0472] rad (+-60 deg)"
        raise InputError(
            f"{field} = {shown}: allowed range is {allowed}: the strip theory takes the flow "
            "normal to the elastic axis, V cos(sweep), and the modified strip method is "
            "validated only to about 60 deg (beyond it the spanwise flow dominates)"
            + ("" if degrees else "; an angle in degrees is a unit error")
        )
    return float(np.clip(rad, -MAX_SWEEP, MAX_SWEEP))


FREQUENCY_RANGE = (1e-3, 1e5)
"""Allowed first bending and torsion frequencies of a cantilever with a segment's properties
over the whole span [Hz]: a value outside it is a unit error, and beyond it the eigenvalue
problems lose their accuracy."""


def _check_frequencies(seg: Segment, span: float) -> None:
    """The segment's properties, as a uniform cantilever of the wing's span, must give first
    bending and torsion frequencies within :data:`FREQUENCY_RANGE` (a unit check)."""
    two_pi = 2.0 * np.pi
    f_bending = 1.875**2 / two_pi * np.sqrt(seg.EI / (seg.mass * span**4))
    f_torsion = 0.25 / span * np.sqrt(seg.GJ / seg.inertia)
    lo, hi = FREQUENCY_RANGE
    checks = (("bending", f_bending, "EI, mass"), ("torsion", f_torsion, "GJ, inertia"))
    for what, f, keys in checks:
        if not lo <= f <= hi:
            raise InputError(
                f"{seg.name}: its {keys} and the span give a first {what} frequency of "
                f"{f:.3g} Hz, outside [{lo:g}, {hi:g}] Hz: check the units [SI]"
            )


def _check_flap_section(seg: Segment, cs: ControlSurface) -> None:
    """The section mass matrix with the flap coupling must be positive definite."""
    b = seg.semichord
    if cs.hinge < seg.a:
        raise InputError(
            f"control_surface '{cs.name}'.hinge = {cs.hinge:g}: must not lie ahead of the elastic "
            f"axis of {seg.name} (a = {seg.a:g}) [semichords aft of mid-chord]"
        )
    y_h = b * (cs.hinge - seg.a)
    s_a, s_b = seg.static_moment, cs.static_moment
    m_sec = np.array(
        [
            [seg.mass, -s_a, -s_b],
            [-s_a, seg.inertia, cs.inertia + y_h * s_b],
            [-s_b, cs.inertia + y_h * s_b, cs.inertia],
        ]
    )
    if np.linalg.eigvalsh(m_sec).min() <= 0.0:
        raise InputError(
            f"control_surface '{cs.name}': static_moment = {s_b:g} kg m/m and inertia = "
            f"{cs.inertia:g} kg m are inconsistent with {seg.name} (mass {seg.mass:g} kg/m, "
            f"inertia {seg.inertia:g} kg m): the section mass matrix is not positive definite; "
            "the section properties must include the flap"
        )


def _unit_hint(semichord: float, length: float) -> str:
    """A hint when a semichord [m] looks like millimetres ("" otherwise)."""
    if semichord > max(length, 5.0):
        return (
            f"the semichord {semichord:g} m is longer than {length:g} m: if it is in "
            f"millimetres, write {semichord / 1000:g}"
        )
    return ""
