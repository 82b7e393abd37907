"""A Nastran stick-model deck read with pyNastran into plain data (SI units, basic frame).

Only the cards of a cantilever beam model are accepted (:data:`SUPPORTED`); every other card,
a reference to a missing card, a non-rectangular frame or a field the import does not model is
refused in one line naming the deck, the card and its id. pyNastran is an optional dependency
(``pip install 'aeroservo[nastran]'``); it is imported only here, on first use.
The mapping of each card is in ``docs/nastran.md``.
"""

from __future__ import annotations

import contextlib
import io
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ...errors import InputError
from .aero import AERO_CARDS, AeroDeck, aero_deck, check_aero_references
from .masses import (
    MASS_CARDS,
    PointMass,
    check_mass_references,
    frame_axes,
    point_mass,
)
from .reader import first_line, parse_deck, pynastran_bdf
from .sections import Section, section_of, tapered
from .units import UnitSystem, unit_hint, unit_system

__all__ = ["Deck", "Element", "PointMass", "read_deck", "SUPPORTED", "pynastran_bdf"]

SUPPORTED = (
    "GRID",
    "GRDSET",
    "CORD2R",
    "CORD1R",
    "CBAR",
    "CBEAM",
    "PBAR",
    "PBARL",
    "PBEAM",
    "PBEAML",
    "MAT1",
    *MASS_CARDS,
    "SPC",
    "SPC1",
    *AERO_CARDS,
)
"""Cards mapped to the wing, its aerodynamic grid and its flutter case."""

MAX_ELEMENTS = 10_000
"""Most beam elements a deck may have (a stick model has tens to a few hundred)."""

IGNORED = ("PARAM", "EIGRL", "EIGR", "EIGC", "SPCADD", "MDLPRM", "ENDDATA")
"""Cards accepted and left out silently (solution control; ``PARAM,WTMASS`` scales the masses,
``PARAM,LMODES`` sets the doublet lattice's modes)."""

NOTED = (
    # loads and dynamic excitation
    "FORCE", "FORCE1", "FORCE2", "MOMENT", "MOMENT1", "MOMENT2", "LOAD", "GRAV", "PLOAD",
    "PLOAD1", "PLOAD2", "PLOAD4", "DAREA", "DLOAD", "TLOAD1", "TLOAD2", "RLOAD1", "RLOAD2",
    "FREQ", "FREQ1", "FREQ2", "TSTEP", "TABLED1", "TABLED2", "TABLED3", "TABLED4", "TABDMP1",
    "TABRND1", "RANDPS", "GUST", "DELAY", "DPHASE", "EPOINT", "USET", "ASET", "ASET1",
    "OMIT", "OMIT1", "SUPORT", "SUPORT1", "TEMP", "TEMPD",
    # static aeroelasticity, monitors and output
    "TRIM", "AESTAT", "AELINK", "AEPARM", "AECOMP", "AECOMPL", "MONPNT1", "MONDSP1", "PLOTEL",
    "DIVERG", "CSSCHD", "UXVEC",
    # design optimisation
    "DESVAR", "DVPREL1", "DVPREL2", "DVCREL1", "DVMREL1", "DRESP1", "DRESP2", "DRESP3",
    "DCONSTR", "DCONADD", "DOPTPRM", "DEQATN", "DLINK", "DTABLE", "DSCREEN",
)  # fmt: skip
"""Load, output and design cards: left out with one note listing them."""


@dataclass(frozen=True)
class Element:
    """A CBAR or CBEAM: end grids, the orientation vector in the basic frame and its section."""

    card: str
    eid: int
    ga: int
    gb: int
    v: np.ndarray | None  # orientation vector [basic]; None: from the grid g0 (see g0)
    g0: int | None
    section: Section


@dataclass(frozen=True)
class Deck:
    """What the wing import needs from a deck, in the basic frame."""

    path: Path
    grids: dict[int, np.ndarray]  # positions [m]
    elements: tuple[Element, ...]
    masses: tuple[PointMass, ...]
    constraints: dict[int, list[tuple[str, np.ndarray]]]  # grid -> [("T"|"R", axis [basic])]
    wtmass: float
    notes: tuple[str, ...]
    units: UnitSystem
    aero: AeroDeck | None = None


def read_deck(path: str | Path, units: str | UnitSystem | None = None) -> Deck:
    """Read a stick-model deck and convert it to SI.

    Parameters
    ----------
    path : str or Path
        Nastran bulk data (``.bdf``, ``.dat``, ``.nas``), with or without executive and case
        control (``BEGIN BULK``).
    units : str, optional
        The deck's unit system (:data:`~.units.UNIT_SYSTEMS`; default ``"si"``).

    Raises
    ------
    InputError
        One line: pyNastran missing, an unreadable deck, an unsupported card, a missing
        reference, or a field the import does not model.
    """
    units = unit_system(units)
    path = Path(path)
    model = parse_deck(path)
    sink = io.StringIO()
    noted = _check_cards(path, model)
    grdset = _apply_grdset(model)
    _check_references(path, model)
    check_aero_references(path, model)
    check_mass_references(path, model)
    try:
        with contextlib.redirect_stdout(sink), contextlib.redirect_stderr(sink):
            model.cross_reference()
    except Exception as exc:
        raise InputError(f"{path}: {first_line(exc)}") from None
    deck = _extract(path, model, units)
    aero = aero_deck(path, model, units)
    evidence = {
        f"material {mat.mid}": (deck.wtmass * float(mat.rho), f"MAT1 {mat.mid}", "RHO x WTMASS")
        for mat in model.materials.values()
        if getattr(mat, "rho", None)
    }
    if aero is not None and aero.rho_ref_deck:
        evidence = {"air": (aero.rho_ref_deck * aero.density_ratio, *aero.density_card)} | evidence
    unit_hint(path, units, evidence)
    notes = list(deck.notes) + ([grdset] if grdset else [])
    if noted:
        notes.append(f"left out (loads, output, design, trim): {noted}")
    if aero is not None:
        notes += aero.notes
    return replace(deck, notes=tuple(notes), aero=aero)


def _apply_grdset(model) -> str:
    """GRDSET's CP, CD and PS on every GRID that leaves them blank (or 0), and a note saying so
    ('' without a GRDSET)."""
    gs = getattr(model, "grdset", None)
    if gs is None:
        return ""
    for grid in model.nodes.values():
        if not grid.cp and gs.cp:
            grid.cp = gs.cp
        if not grid.cd and gs.cd:
            grid.cd = gs.cd
        if not grid.ps and gs.ps:
            grid.ps = str(gs.ps)
    model.grdset = None
    given = [f"{k} {v}" for k, v in (("CP", gs.cp), ("CD", gs.cd), ("PS", gs.ps)) if v]
    return (
        f"GRDSET {', '.join(given)} applied to every GRID whose field is blank or 0 (pyNastran "
        "cannot tell an explicit 0 from a blank)"
        if given
        else ""
    )


_WHY = {
    ("RBAR", "RBE1", "RBE2", "RBE3", "RROD", "RTRPLT", "RSPLINE", "MPC"): (
        "rigid elements and multipoint constraints are not modelled (the wing is one beam)"
    ),
    ("CQUAD4", "CQUAD8", "CTRIA3", "CTRIA6", "CSHEAR", "CHEXA", "CPENTA", "CTETRA", "CQUAD2",
     "CTRIA2", "CHEXA1"): "a plate or solid model is not a stick model",
    ("CELAS1", "CELAS2", "CELAS3", "CELAS4", "CBUSH", "CDAMP1", "CDAMP2", "CVISC", "GENEL"): (
        "springs, dampers and general elements are not modelled"
    ),
    ("CROD", "CONROD", "CTUBE"): "rods carry no bending: a stick model needs CBAR or CBEAM",
    ("DMI", "DMIG", "DMIJ", "DMIK", "DMIJI", "K2PP", "M2PP", "B2PP"): (
        "direct matrix input is not read (aeroservo builds its own matrices)"
    ),
    ("CAERO2", "CAERO3", "CAERO4", "CAERO5", "PAERO2", "SPLINE3", "SPLINE4", "SPLINE5"): (
        "only CAERO1 lifting surfaces with SPLINE1/SPLINE2 are read"
    ),
}  # fmt: skip


def _card_id(model, name: str) -> str:
    """The id of the first card called ``name`` in the model's dictionaries ('' if none)."""
    for store in (
        "rigid_elements", "elements", "properties", "masses", "caeros", "paeros", "splines",
        "materials", "coords", "mpcs", "loads", "dloads", "dload_entries", "aesurf",
    ):  # fmt: skip
        table = getattr(model, store, None) or {}
        for key, value in sorted(table.items(), key=lambda kv: str(kv[0])):
            cards = value if isinstance(value, list) else [value]
            if any(getattr(c, "type", None) == name for c in cards):
                return f" {key}"
    return ""


def _check_cards(path: Path, model) -> str:
    """Refuse an unsupported card in one line naming it and its id; the load, output and
    design cards left out, as text for the note ('' if none)."""
    counts = dict(getattr(model, "card_count", {}))
    for name in getattr(model, "reject_count", {}) or {}:
        counts.setdefault(name, 1)
    rank = {c: i for i, names in enumerate(_WHY) for c in names}  # the structure's first
    bad = sorted(
        (c for c in counts if c not in SUPPORTED + IGNORED + NOTED),
        key=lambda c: (rank.get(c, len(_WHY)), c),
    )
    if bad:
        name, n = bad[0], counts[bad[0]]
        why = next((w for names, w in _WHY.items() if name in names), None)
        more = f"; also {', '.join(bad[1:4])}{'...' if len(bad) > 4 else ''}" if bad[1:] else ""
        what = why or "this card is not read (docs/nastran.md lists the cards that are)"
        raise InputError(
            f"{path}: {name}{_card_id(model, name)} ({n} card{'s' * (n != 1)}): {what}{more}"
        )
    if not model.elements:
        raise InputError(f"{path}: no CBAR or CBEAM element: nothing to import")
    if len(model.elements) > MAX_ELEMENTS:
        raise InputError(
            f"{path}: {len(model.elements)} beam elements, more than the {MAX_ELEMENTS} of a "
            "stick model"
        )
    return ", ".join(f"{c} ({counts[c]})" for c in sorted(counts) if c in NOTED)


def _check_references(path: Path, model) -> None:
    """Missing grids, properties, materials and frames, named before pyNastran would."""
    for cid, coord in model.coords.items():
        if cid != 0 and coord.type not in ("CORD2R", "CORD1R"):
            raise InputError(f"{path}: {coord.type} {cid}: only rectangular frames are supported")
    for nid, grid in model.nodes.items():
        for key in ("cp", "cd"):
            cid = getattr(grid, key) or 0
            if cid not in model.coords:
                raise InputError(
                    f"{path}: GRID {nid}: {key.upper()} = {cid}: no such coordinate system"
                )
    for eid, elem in sorted(model.elements.items()):
        for nid in elem.node_ids:
            if nid not in model.nodes:
                raise InputError(f"{path}: {elem.type} {eid}: GRID {nid} is missing")
        if elem.pid not in model.properties:
            raise InputError(f"{path}: {elem.type} {eid}: property {elem.pid} is missing")
        prop = model.properties[elem.pid]
        if prop.type not in ("PBAR", "PBARL", "PBEAM", "PBEAML"):
            raise InputError(
                f"{path}: {elem.type} {eid}: property {prop.type} {prop.pid} is not supported"
            )
        if prop.mid not in model.materials:
            raise InputError(
                f"{path}: {prop.type} {prop.pid}: material {prop.mid} (MAT1) is missing"
            )
    for eid, mass in sorted(model.masses.items()):
        for nid in mass.node_ids:
            if nid and nid not in model.nodes:
                raise InputError(f"{path}: {mass.type} {eid}: GRID {nid} is missing")
        cid = getattr(mass, "cid", 0) or 0
        if cid > 0 and cid not in model.coords:
            raise InputError(f"{path}: CONM2 {eid}: CID = {cid}: no such coordinate system")


def vector_text(v) -> str:
    """A vector as ``[0, 0.5, 1]`` for messages (no numpy reprs)."""
    return "[" + ", ".join(f"{float(x):.6g}" for x in np.ravel(v)) + "]"


def _extract(path: Path, model, units: UnitSystem) -> Deck:
    notes = []
    wtmass = 1.0
    param = model.params.get("WTMASS")
    if param is not None:
        wtmass = float(param.values[0])
        if not wtmass > 0.0:  # a NaN too
            raise InputError(
                f"{path}: PARAM WTMASS = {wtmass:g}: must be > 0 (it multiplies every mass, "
                "inertia and density: 1, or 1/386.09 for masses in lbm)"
            )
        notes.append(f"PARAM,WTMASS,{wtmass:g} scales every mass and inertia")
    for mid, mat in sorted(model.materials.items()):
        if float(getattr(mat, "rho", 0.0) or 0.0) < 0.0:
            raise InputError(f"{path}: {mat.type} {mid}: RHO = {mat.rho:g}: a density must be >= 0")
    grids = {
        nid: np.asarray(g.get_position(), dtype=float) * units.length
        for nid, g in model.nodes.items()
    }
    cd_axes = {nid: frame_axes(model.coords[g.cd or 0]) for nid, g in model.nodes.items()}
    elements, taper = [], []
    for eid, elem in sorted(model.elements.items()):
        where = f"{path}: {elem.type} {eid}"
        if elem.type not in ("CBAR", "CBEAM"):
            raise InputError(f"{where}: element type not supported (CBAR, CBEAM)")
        for key in ("pa", "pb"):
            if getattr(elem, key, 0):
                raise InputError(
                    f"{where}: pin flag {key.upper()} = {getattr(elem, key)}: released ends are "
                    "not modelled (the beam is continuous)"
                )
        for key in ("wa", "wb"):
            w = getattr(elem, key, None)
            if w is not None and np.any(np.abs(np.asarray(w, dtype=float)) > 0.0):
                raise InputError(
                    f"{where}: offset {key.upper()} = {vector_text(w)}: element "
                    "offsets are not modelled; put the grids on the elastic axis"
                )
        if elem.type == "CBEAM" and (getattr(elem, "sa", 0) or getattr(elem, "sb", 0)):
            raise InputError(f"{where}: warping scalar points SA/SB are not modelled")
        offt = getattr(elem, "offt", None) or "GGG"
        if not isinstance(offt, str):  # field 9 as the flag of older decks (1: X1-X3 a vector)
            if int(offt) == 2 and getattr(elem, "g0", None) is None:
                raise InputError(
                    f"{where}: field 9 = 2 says field 6 is a grid G0, but X1-X3 are real numbers"
                )
            offt = "GGG"
        if getattr(elem, "bit", None) is not None:
            raise InputError(f"{where}: BIT field (curved beam) is not supported; use OFFT")
        ga, gb = elem.node_ids[:2]
        g0 = getattr(elem, "g0", None) or None
        v = None
        if g0 is None:
            if getattr(elem, "x", None) is None:
                raise InputError(
                    f"{where}: no orientation vector (field 6 read as grid G0 = 0: write X1, X2, "
                    "X3 as real numbers, e.g. 0., 0., 1.)"
                )
            x = np.asarray(elem.x, dtype=float)
            v = x if offt[0] == "B" else cd_axes[ga].T @ x
        mat = model.materials[model.properties[elem.pid].mid]
        if mat.type != "MAT1":
            raise InputError(f"{where}: material {mat.type} {mat.mid}: only MAT1 is supported")
        prop = model.properties[elem.pid]
        section = section_of(path, prop, mat, wtmass, units)
        if prop.type in ("PBEAM", "PBEAML") and tapered(prop) and prop.pid not in taper:
            taper.append(prop.pid)
        elements.append(Element(elem.type, eid, ga, gb, v, g0, section))
    if taper:
        notes.append(
            f"tapered PBEAM/PBEAML {', '.join(map(str, taper))}: each element takes its section "
            "averaged over its length (linear between the stations)"
        )
    masses = [
        point_mass(path, m, model, cd_axes, wtmass, units) for _, m in sorted(model.masses.items())
    ]
    constraints: dict[int, list] = {}

    def constrain(nid: int, comps: str, where: str) -> None:
        if nid not in grids:
            raise InputError(f"{path}: {where}: GRID {nid} is missing")
        for c in str(comps):
            if c in "123456":
                k = int(c) - 1
                kind = "T" if k < 3 else "R"
                constraints.setdefault(nid, []).append((kind, cd_axes[nid][k % 3]))

    for nid, g in model.nodes.items():
        if g.ps:
            constrain(nid, g.ps, f"GRID {nid} PS")
    for sid, cards in model.spcs.items():
        for card in cards:
            if card.type == "SPC1":
                for nid in card.node_ids:
                    constrain(nid, card.components, f"SPC1 {sid}")
            else:
                for nid, comps, value in zip(
                    card.node_ids, card.components, card.enforced, strict=False
                ):
                    if value:
                        raise InputError(
                            f"{path}: SPC {sid}: enforced displacement {value:g} at GRID {nid} "
                            "is not modelled (a clamp is zero)"
                        )
                    constrain(nid, comps, f"SPC {sid}")
    return Deck(
        path, grids, tuple(elements), tuple(masses), constraints, wtmass, tuple(notes), units
    )
