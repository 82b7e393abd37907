"""The unit system of a Nastran deck, its conversion to SI and a check of its plausibility.

Nastran has no units: a deck is consistent in whatever units its author chose, and most public
flutter decks use inch, pound-force and second (mass in lbf s^2/in). The user says which
(``--units``); every length, force, mass and density is converted to SI once, when the deck is
read (``files/nastran/deck.py``). Mass is the derived unit force s^2 / length of each system
(``PARAM,WTMASS`` multiplies a deck's masses first: a deck with masses in lbm has
WTMASS = 1/386.09). Frequencies do not depend on the units; densities and stiffnesses do, and
they tell a deck read in the wrong units (:func:`unit_hint`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ...errors import InputError

__all__ = ["UnitSystem", "UNIT_SYSTEMS", "unit_system", "unit_hint", "chord_hint", "span_hint"]

LBF = 4.4482216152605
"""One pound-force [N] (exact by the 1959 definition: 0.45359237 kg x 9.80665 m/s^2)."""


@dataclass(frozen=True)
class UnitSystem:
    """A consistent unit system: its length and force units in SI, time in seconds.

    Attributes
    ----------
    name : str
        ``"si"``, ``"in-lbf-s"``, ``"ft-slug-s"`` or ``"mm-t-s"``.
    length : float
        Its length unit [m].
    force : float
        Its force unit [N].
    mass_label : str
        How the mass unit is written.
    """

    name: str
    length: float
    force: float
    length_label: str
    force_label: str
    mass_label: str

    @property
    def mass(self) -> float:
        """The mass unit [kg]: force s^2 / length."""
        return self.force / self.length

    @property
    def density(self) -> float:
        """The mass-density unit [kg/m^3]."""
        return self.mass / self.length**3

    @property
    def stress(self) -> float:
        """The stress (modulus) unit [Pa]."""
        return self.force / self.length**2

    def describe(self) -> str:
        """One line for the written wing file: what a unit of each kind was converted by."""
        if self.name == "si":
            return "units: SI (N, m, kg, s) as read"
        return (
            f"units: {self.name} converted to SI: length 1 {self.length_label} = "
            f"{self.length:.10g} m, force 1 {self.force_label} = {self.force:.10g} N, mass "
            f"1 {self.mass_label} = {self.mass:.10g} kg, density 1 {self.mass_label}/"
            f"{self.length_label}^3 = {self.density:.10g} kg/m^3, modulus 1 {self.force_label}/"
            f"{self.length_label}^2 = {self.stress:.10g} Pa"
        )


UNIT_SYSTEMS: dict[str, UnitSystem] = {
    "si": UnitSystem("si", 1.0, 1.0, "m", "N", "kg"),
    "in-lbf-s": UnitSystem("in-lbf-s", 0.0254, LBF, "in", "lbf", "lbf s^2/in"),
    "ft-slug-s": UnitSystem("ft-slug-s", 0.3048, LBF, "ft", "lbf", "slug"),
    "mm-t-s": UnitSystem("mm-t-s", 1e-3, 1.0, "mm", "N", "t"),
}
"""The unit systems a deck may be given in (``--units``)."""


def unit_system(name: str | UnitSystem | None) -> UnitSystem:
    """The :class:`UnitSystem` of a name (None: SI).

    Raises
    ------
    InputError
        An unknown name (the message lists the known ones).
    """
    if isinstance(name, UnitSystem):
        return name
    key = "si" if name is None else str(name).lower()
    if key not in UNIT_SYSTEMS:
        raise InputError(f"units = {name!r}: expected one of {', '.join(UNIT_SYSTEMS)}")
    return UNIT_SYSTEMS[key]


AIR_DENSITY = (0.01, 2.0)
"""Air densities [kg/m^3] taken as plausible (sea level 1.225, 0.012 at 30 km)."""

MATERIAL_DENSITY = (30.0, 25000.0)
"""Structural material densities [kg/m^3] taken as plausible (foam 30, tungsten 19 300)."""


def _plausible(values: dict[str, tuple[float, str, str]], units: UnitSystem) -> list[str]:
    """The evidence items that are implausible in ``units`` (each already in SI of the deck's
    own numbers times the units' factor)."""
    bad = []
    for kind, (raw, _label, _what) in values.items():
        lo, hi = AIR_DENSITY if kind.startswith("air") else MATERIAL_DENSITY
        value = raw * units.density
        if not lo <= value <= hi:
            bad.append(kind)
    return bad


def unit_hint(path, units: UnitSystem, evidence: dict[str, tuple[float, str, str]]) -> None:
    """Refuse a deck whose densities are implausible in the units given, naming the likely
    system.

    Parameters
    ----------
    path
        The deck (named in the message).
    units : UnitSystem
        The units the user gave.
    evidence : dict
        key -> (value in the deck's own units, the card, what it is), for the air density
        (``AERO RHOREF`` x the flutter density ratios, keys starting with ``air``) and the
        material densities (``MAT1 RHO`` x ``WTMASS``).

    Raises
    ------
    InputError
        One line naming the card, its value in SI and the unit system in which it is plausible.
    """
    if not evidence:
        return
    bad = _plausible(evidence, units)
    if not bad:
        return
    key = bad[0]
    raw, card, what = evidence[key]
    value = raw * units.density
    fits = [u for u in UNIT_SYSTEMS.values() if not _plausible(evidence, u)]
    lo, hi = AIR_DENSITY if key.startswith("air") else MATERIAL_DENSITY
    hint = (
        f"the deck looks like {fits[0].name} units: give --units {fits[0].name}"
        if fits
        else "no unit system makes every density plausible: check the deck's units"
    )
    raise InputError(
        f"{path}: {card}: {what} = {value:.4g} kg/m^3 in {units.name} units, outside the "
        f"plausible [{lo:g}, {hi:g}] kg/m^3; {hint} (docs/nastran.md, 'Units')"
    )


SPAN_CHORDS = (0.2, 100.0)
"""Beam lengths [chords] taken as plausible when the chord is given apart from the deck (a
store pylon 0.2 chords long, a sailplane's wing 40)."""


def chord_hint(path, span: float, segments, sources, units: UnitSystem) -> None:
    """Refuse a chord given by option or companion table (in m) that is implausible against
    the deck's beam length in the units given, naming the unit system that fits.

    A chord from the deck's CAERO1 is in the deck's own units and scales with the beam, so only
    a chord given apart from the deck can reveal wrong units here.
    """
    given = [
        s.semichord
        for s, src in zip(segments, sources, strict=True)
        if "CAERO1" not in src["semichord"]
    ]
    if not given:
        return
    chord = 2.0 * max(given)
    ratio = span / chord
    lo, hi = SPAN_CHORDS
    if lo <= ratio <= hi:
        return
    fits = sorted(
        (abs(math.log(ratio * u.length / units.length / 10.0)), u.name)
        for u in UNIT_SYSTEMS.values()
        if lo <= ratio * u.length / units.length <= hi
    )
    names = " or ".join(f"--units {name}" for _, name in fits)
    hint = f"give {names}" if fits else "check the chord and the deck's units"
    raise InputError(
        f"{path}: the beam is {span:.4g} m long in {units.name} units and the chord given is "
        f"{chord:.4g} m: {ratio:.3g} chords, outside the plausible [{lo:g}, {hi:g}]; {hint} "
        "(docs/nastran.md, 'Units')"
    )


SPAN_MAX = 200.0
"""Longest beam line [m] taken as plausible (a semi-span or a rotor blade: the largest
aircraft's semi-span is 59 m, the longest wind-turbine blades 120 m)."""

MASS_PER_SPAN3 = (1e-5, 1e4)
"""A beam line's mass over its length cubed [kg/m^3] taken as plausible: about 0.002 for a
human-powered aircraft's wing, 0.05 for a wind-turbine blade, 0.5 for an airliner's, 10 for a
solid metal wind-tunnel model; a deck read in units 25 times too long is 1e5 times lighter."""


def _span_fits(span: float, mass: float | None) -> bool:
    lo, hi = MASS_PER_SPAN3
    return span <= SPAN_MAX and (mass is None or lo <= mass / span**3 <= hi)


def span_hint(
    path, span: float, mass: float, units: UnitSystem, mass_given: bool, heaviest: str = ""
) -> None:
    """Refuse a beam line whose length or mass is implausible for a wing in the units given
    (a deck in mm read as SI is a wing kilometres long and as light as paper), naming the unit
    system in which both are plausible.

    Parameters
    ----------
    path
        The deck (named in the message).
    span : float
        The beam line's length in SI [m], as read in ``units``.
    mass : float
        The mass the deck gives it [kg], as read in ``units`` (0: none, not checked).
    units : UnitSystem
        The units the user gave.
    mass_given : bool
        The options or companion table give the mass per length (SI): the deck's mass is
        not checked.
    heaviest : str
        The card that gives most of the mass (named in the message), or ''.
    """
    mass = mass if mass > 0.0 and not mass_given else None
    if _span_fits(span, mass):
        return
    fits = []
    for u in UNIT_SYSTEMS.values():
        s_u = span * u.length / units.length
        m_u = None if mass is None else mass * u.mass / units.mass
        if _span_fits(s_u, m_u):  # the likeliest first: nearest a 10 m wing of 0.1 kg/m^3
            fits.append(
                (abs(math.log10(s_u / 10.0 if m_u is None else m_u / s_u**3 / 0.1)), u.name)
            )
    fits = [name for _, name in sorted(fits)]
    hint = (
        f"the deck looks like {' or '.join(fits)} units: give --units {fits[0]}"
        if fits
        else "check the deck's units (--units) and PARAM WTMASS"
    )
    lo, hi = MASS_PER_SPAN3
    what = (
        f"longer than the {SPAN_MAX:g} m of any wing"
        if span > SPAN_MAX
        else f"mass / length^3 = {mass / span**3:.3g} kg/m^3, outside the plausible [{lo:g}, "
        f"{hi:g}] of wings"
    )
    weighs = (
        ""
        if mass is None
        else f" and weighs {mass:.4g} kg" + (f" (most of it {heaviest})" if heaviest else "")
    )
    raise InputError(
        f"{path}: the beam line is {span:.4g} m long{weighs} in {units.name} units: {what}; "
        f"{hint} (docs/nastran.md, 'Units')"
    )
