"""Tables of nonlinear hinges: ``[[lco.hinges]]`` of a limit-cycle scenario and the top-level
``[[hinges]]`` of a wing file (the same keys).

Keys (SI, radians): ``target`` (an actuator's or a control surface's name; ``"flap"`` for a
typical section), ``law`` (``"freeplay"``, ``"bilinear"`` or ``"cubic"``), ``gap`` [rad, total
width], ``offset`` [rad, centre of the gap], ``inner_ratio`` [-, stiffness inside the gap over
the spring's], ``coefficient`` [N m/rad^3, cubic]. Every error names the file, the key and the
value (:class:`aeroservo.errors.InputError`).
"""

from __future__ import annotations

from ..errors import InputError, show_value
from ..structure.hinge_laws import Bilinear, Cubic, Freeplay
from ..system.hinge_elements import NonlinearHinge
from .toml_tables import Table

__all__ = ["LAWS", "hinges_from_list", "check_targets"]

LAWS = ("freeplay", "bilinear", "cubic")
"""The names of the hinge laws (:mod:`aeroservo.structure.hinge_laws`)."""

_KEYS = {
    "freeplay": (("gap",), ("offset", "inner_ratio")),
    "bilinear": (("gap", "inner_ratio"), ("offset",)),
    "cubic": (("coefficient",), ()),
}
MAX_GAP = 0.5
"""Largest total gap or offset [rad] (about 29 deg), as :class:`Freeplay` allows."""

MAX_HINGES = 100
"""Most hinge tables in one file."""


def hinges_from_list(items: object, file: str, where: str = "hinges") -> tuple[NonlinearHinge, ...]:
    """The nonlinear hinges of an array of tables.

    Parameters
    ----------
    items : object
        The array as read from TOML (a list of tables, at least one).
    file : str
        The file, named in every message.
    where : str
        Dotted name of the array (``"hinges"`` in a wing file, ``"lco.hinges"`` in a scenario).

    Returns
    -------
    tuple of NonlinearHinge
    """
    if not isinstance(items, list) or not items:
        raise InputError(
            f"{file}: {where} = {show_value(items)}: expected [[{where}]] tables (target, law, "
            "gap or coefficient)"
        )
    if len(items) > MAX_HINGES:
        raise InputError(f"{file}: {where}: {len(items)} tables; at most {MAX_HINGES}")
    return tuple(_hinge(Table(item, f"{where}[{i}]", file)) for i, item in enumerate(items))


def _hinge(ht: Table) -> NonlinearHinge:
    """One hinge table."""
    law = ht.string("law", required=True, choices=LAWS)
    required, optional = _KEYS[law]
    for key in ("gap", "offset", "inner_ratio", "coefficient"):
        if ht.has(key) and key not in required + optional:
            ht.fail(key, ht.data[key], f"not used by law {law!r}")
    ht.check_keys(("target", "law") + required, optional)
    target = ht.string("target", required=True)
    if not target.strip() or not target.isprintable():
        ht.fail("target", target, "expected an actuator or control surface name")
    if law == "cubic":
        coef = ht.number("coefficient", unit="N m/rad^3", lo=-1e12, hi=1e12, required=True)
        if coef == 0.0:
            ht.fail(
                "coefficient",
                coef,
                "0 is the linear spring; give a hardening (> 0) or softening (< 0) coefficient",
            )
        return NonlinearHinge(target, Cubic(coef))
    gap = ht.number("gap", unit="rad", lo=0.0, lo_open=True, hi=MAX_GAP, required=True)
    offset = ht.number("offset", 0.0, unit="rad", lo=-MAX_GAP, hi=MAX_GAP)
    lo_open = law == "bilinear"  # a bilinear band of zero stiffness is a freeplay
    ratio = ht.number("inner_ratio", 0.0, lo=0.0, lo_open=lo_open, hi=100.0)
    cls = Bilinear if law == "bilinear" else Freeplay
    return NonlinearHinge(target, cls(gap, offset, ratio))


def check_targets(hinges, wing, file: str, where: str = "hinges") -> None:
    """Each hinge's target an actuator or a control surface (with actuators) of ``wing``,
    and no actuator given two laws."""
    actuators = {a.name: cs.name for cs in wing.control_surfaces for a in cs.actuators}
    surfaces = {cs.name: [a.name for a in cs.actuators] for cs in wing.control_surfaces}
    seen: dict = {}
    for i, h in enumerate(hinges):
        key = f"{where}[{i}].target"
        if h.target in actuators:
            acts = [h.target]
        elif h.target in surfaces:
            acts = surfaces[h.target]
            if not acts:
                raise InputError(
                    f"{file}: {key} = {h.target!r}: the surface has no actuators (a nonlinear law "
                    "acts on an actuator; the distributed hinge stiffness stays linear)"
                )
        else:
            known = sorted(actuators) + sorted(surfaces)
            raise InputError(
                f"{file}: {key} = {h.target!r}: not an actuator or control surface of wing "
                f"{wing.name!r}; known: {', '.join(known) or 'none'}"
            )
        for a in acts:
            if a in seen:
                raise InputError(
                    f"{file}: {key} = {h.target!r}: actuator {a!r} already has the law of "
                    f"{where}[{seen[a]}]; give each actuator one law"
                )
            seen[a] = i
