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
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import InputError
from .nastran_sections import Section, section_of

__all__ = ["Deck", "Element", "PointMass", "read_deck", "SUPPORTED", "pynastran_bdf"]

SUPPORTED = (
    "GRID",
    "CORD2R",
    "CORD1R",
    "CBAR",
    "CBEAM",
    "PBAR",
    "PBARL",
    "PBEAM",
    "MAT1",
    "CONM2",
    "CMASS2",
    "SPC",
    "SPC1",
)
"""Cards mapped to the wing."""

IGNORED = ("PARAM", "EIGRL", "EIGR", "SPCADD", "ENDDATA")
"""Cards accepted and left out (solution control; ``PARAM,WTMASS`` scales the masses)."""


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
class PointMass:
    """A CONM2 (rigid mass with CG and inertia) or a grounded CMASS2 (scalar mass)."""

    card: str
    eid: int
    grid: int
    mass: float  # [kg], WTMASS applied
    cg: np.ndarray  # CG position [m, basic]
    inertia: np.ndarray  # 3x3 inertia tensor about the CG [kg m^2, basic]
    direction: np.ndarray | None = None  # CMASS2: the direction of its component [basic]


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


def pynastran_bdf():
    """pyNastran's ``BDF`` class, or a one-line :class:`InputError` saying how to install it."""
    try:
        import numpy as np_

        old = "in1d"  # pyNastran 1.4 binds np.in1d on import; numpy 2.4 removed it
        shim = not hasattr(np_, old)
        if shim:
            setattr(np_, old, lambda a, b, **kw: np_.isin(np_.ravel(a), b, **kw))
        try:
            from pyNastran.bdf.bdf import BDF
        finally:
            if shim:
                delattr(np_, old)
    except ImportError:
        raise InputError(
            "reading a Nastran deck needs pyNastran, an optional dependency: "
            "pip install 'aeroservo[nastran]' (docs/nastran.md)"
        ) from None
    return BDF


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip()
    line = text.splitlines()[0].strip() if text else type(exc).__name__
    card = re.search(r"card=\[\s*'(\w+)'\s*,\s*'?(\w+)", text)
    if card:
        line += f" (card {card.group(1)} {card.group(2)})"
    return line[:300]


def read_deck(path: str | Path) -> Deck:
    """Read a stick-model deck.

    Parameters
    ----------
    path : str or Path
        Nastran bulk data (``.bdf``, ``.dat``, ``.nas``), with or without executive and case
        control (``BEGIN BULK``).

    Raises
    ------
    InputError
        One line: pyNastran missing, an unreadable deck, an unsupported card, a missing
        reference, or a field the import does not model.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError as exc:
        raise InputError(f"{path}: cannot read the deck: {exc.strerror or exc}") from None
    BDF = pynastran_bdf()
    from cpylog import SimpleLogger

    model = BDF(log=SimpleLogger(level="critical"))
    punch = re.search(r"^\s*BEGIN\s+BULK", text, re.I | re.M) is None
    sink = io.StringIO()
    try:
        with contextlib.redirect_stdout(sink), contextlib.redirect_stderr(sink):
            model.read_bdf(str(path), punch=punch, xref=False)
    except Exception as exc:  # pyNastran raises many kinds on a malformed deck
        raise InputError(f"{path}: cannot read the deck: {_first_line(exc)}") from None
    _check_cards(path, model)
    _check_references(path, model)
    try:
        with contextlib.redirect_stdout(sink), contextlib.redirect_stderr(sink):
            model.cross_reference()
    except Exception as exc:
        raise InputError(f"{path}: {_first_line(exc)}") from None
    return _extract(path, model)


def _check_cards(path: Path, model) -> None:
    counts = dict(getattr(model, "card_count", {}))
    for name in getattr(model, "reject_count", {}) or {}:
        counts.setdefault(name, 1)
    bad = sorted(c for c in counts if c not in SUPPORTED + IGNORED)
    if bad:
        n = counts[bad[0]]
        more = f" (and {', '.join(bad[1:4])}{'...' if len(bad) > 4 else ''})" if bad[1:] else ""
        raise InputError(
            f"{path}: card {bad[0]} ({n} of them){more} is not supported: aeroservo imports a "
            f"cantilever stick model of {', '.join(SUPPORTED)} (docs/nastran.md)"
        )
    if not model.elements:
        raise InputError(f"{path}: no CBAR or CBEAM element: nothing to import")


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
        if prop.type not in ("PBAR", "PBARL", "PBEAM"):
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


def _axes(coord) -> np.ndarray:
    """Rows: the frame's unit axes in the basic frame."""
    if coord is None or coord.cid == 0:
        return np.eye(3)
    return np.array([coord.i, coord.j, coord.k], dtype=float)


def _extract(path: Path, model) -> Deck:
    notes = []
    wtmass = 1.0
    param = model.params.get("WTMASS")
    if param is not None:
        wtmass = float(param.values[0])
        notes.append(f"PARAM,WTMASS,{wtmass:g} scales every mass and inertia")
    grids = {nid: np.asarray(g.get_position(), dtype=float) for nid, g in model.nodes.items()}
    cd_axes = {nid: _axes(model.coords[g.cd or 0]) for nid, g in model.nodes.items()}
    elements = []
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
                    f"{where}: offset {key.upper()} = {list(np.asarray(w, float))}: element "
                    "offsets are not modelled; put the grids on the elastic axis"
                )
        if elem.type == "CBEAM" and (getattr(elem, "sa", 0) or getattr(elem, "sb", 0)):
            raise InputError(f"{where}: warping scalar points SA/SB are not modelled")
        offt = getattr(elem, "offt", None) or "GGG"
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
        section = section_of(path, model.properties[elem.pid], mat, wtmass)
        elements.append(Element(elem.type, eid, ga, gb, v, g0, section))
    masses = [_point_mass(path, m, model, cd_axes, wtmass) for _, m in sorted(model.masses.items())]
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
    return Deck(path, grids, tuple(elements), tuple(masses), constraints, wtmass, tuple(notes))


def _point_mass(path: Path, card, model, cd_axes: dict, wtmass: float) -> PointMass:
    where = f"{path}: {card.type} {card.eid}"
    if card.type == "CONM2":
        nid = card.nid
        x = np.asarray(card.X, dtype=float)
        i11, i21, i22, i31, i32, i33 = (float(v) for v in card.I)
        local = np.array([[i11, -i21, -i31], [-i21, i22, -i32], [-i31, -i32, i33]])
        cid = card.cid if card.cid is not None else 0
        if cid == -1:  # X is the CG in the basic frame, the inertia in the basic frame
            cg, axes = x, np.eye(3)
        else:
            axes = _axes(model.coords[cid]) if cid else np.eye(3)
            cg = np.asarray(model.nodes[nid].get_position(), dtype=float) + axes.T @ x
        inertia = axes.T @ local @ axes
        if np.linalg.eigvalsh(0.5 * (inertia + inertia.T)).min() < -1e-12 * max(
            1e-300, np.abs(inertia).max()
        ):
            raise InputError(f"{where}: its inertia matrix is not positive semi-definite")
        return PointMass("CONM2", card.eid, nid, wtmass * float(card.mass), cg, wtmass * inertia)
    if card.type == "CMASS2":
        nids = [n for n in card.node_ids if n]
        comps = [c for c in (card.c1, card.c2) if c]
        if len(nids) != 1 or len(comps) != 1:
            raise InputError(
                f"{where}: a scalar mass between two grids (or without a component) is not "
                "supported; give one grid and one component"
            )
        comp = int(comps[0])
        if comp > 3:
            raise InputError(
                f"{where}: component {comp} is a rotation: a rotational scalar mass is not "
                "supported (give the inertia on a CONM2)"
            )
        nid = nids[0]
        pos = np.asarray(model.nodes[nid].get_position(), dtype=float)
        return PointMass(
            "CMASS2",
            card.eid,
            nid,
            wtmass * float(card.mass),
            pos,
            np.zeros((3, 3)),
            direction=cd_axes[nid][comp - 1],
        )
    raise InputError(f"{where}: mass card not supported (CONM2, CMASS2)")
