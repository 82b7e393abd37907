"""The aerodynamic and flutter cards of a Nastran deck, in SI: the panels, splines, control
surfaces and the flutter case (AERO, AEROS, CAERO1, PAERO1, SPLINE1, SPLINE2, SET1, AESURF,
AELIST, AEFACT, MKAERO1, MKAERO2, FLFACT, FLUTTER).

They are read into :class:`AeroDeck`; ``files/nastran/case.py`` turns them into the wing's
chord and elastic-axis position, the doublet lattice's box division and the flutter scenario.
The card-by-card mapping is in ``docs/nastran.md``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ...errors import InputError
from .units import UnitSystem

__all__ = [
    "AERO_CARDS",
    "AeroDeck",
    "Panel",
    "FlutterCase",
    "aero_deck",
    "check_aero_references",
    "PK_METHODS",
]

AERO_CARDS = (
    "AERO", "AEROS", "CAERO1", "PAERO1", "SPLINE1", "SPLINE2", "SET1", "AESURF", "AELIST",
    "AEFACT", "MKAERO1", "MKAERO2", "FLFACT", "FLUTTER",
)  # fmt: skip
"""Aerodynamic and flutter cards read."""

MAX_BOXES = 100_000
"""Most boxes a CAERO1 may have (NSPAN x NCHORD; a wing's panel has tens to a few thousand)."""

PK_METHODS = ("PK", "PKNL", "PKS", "PKNLS")
"""FLUTTER methods that list velocities (the others, K and KE, list reduced frequencies)."""


@dataclass(frozen=True)
class Panel:
    """A CAERO1 lifting surface in SI and the basic frame.

    ``p1``, ``p4`` are the leading-edge corners (root and tip), ``c1``, ``c4`` the streamwise
    chords there [m]; ``nspan``, ``nchord`` its boxes (``uniform`` False when AEFACT cards
    divide it unequally); boxes are numbered from ``eid``, chordwise first.
    """

    eid: int
    p1: np.ndarray
    p4: np.ndarray
    c1: float
    c4: float
    nspan: int
    nchord: int
    uniform: bool

    def box(self, box_id: int) -> tuple[int, int] | None:
        """(spanwise strip, chordwise box) of a box id, or None if not on this panel."""
        k = box_id - self.eid
        if not 0 <= k < self.nspan * self.nchord:
            return None
        return divmod(k, self.nchord)


@dataclass(frozen=True)
class FlutterCase:
    """The FLUTTER card the deck's case control selects (or its only one), in SI."""

    sid: int
    method: str
    density_ratios: tuple[float, ...]
    machs: tuple[float, ...]
    velocities: tuple[float, ...]  # [m/s], PK methods
    reduced_frequencies: tuple[float, ...]  # K and KE methods
    imeth: str
    cards: str  # "FLUTTER 30 (PK; FLFACT 1, 2, 4)"
    density_fact: int | None = None  # the FLFACT of its density ratios


@dataclass(frozen=True)
class AeroDeck:
    """The aerodynamic model and flutter case of a deck (SI, basic frame)."""

    flow: np.ndarray  # unit, the aerodynamic x axis (AERO/AEROS ACSID)
    ref_chord: float | None  # [m] REFC
    rho_ref: float | None  # [kg/m^3] AERO RHOREF
    rho_ref_deck: float | None  # RHOREF in the deck's units (for the units check)
    symmetry: int  # SYMXZ: 1 symmetric, 0 none, -1 antisymmetric
    panels: tuple[Panel, ...]
    splines: tuple[tuple[str, int, int, tuple[int, ...]], ...]  # (card, eid, caero, grids)
    surfaces: tuple[tuple[str, tuple[int, ...]], ...]  # (label, box ids)
    flutter: FlutterCase | None
    lmodes: int | None
    density_ratio: float = 1.0
    density_card: tuple[str, str] = ("AERO", "RHOREF")
    notes: list[str] = field(default_factory=list)


def _flfact(path: Path, model, sid: int | None, what: str, card: str) -> tuple[float, ...]:
    if sid is None:
        return ()
    f = model.flfacts.get(sid)
    if f is None:
        raise InputError(f"{path}: {card}: {what} FLFACT {sid} is missing")
    return tuple(float(x) for x in np.atleast_1d(f.factors))


def _selected_flutter(path: Path, model, notes: list) -> object | None:
    """The FLUTTER card case control's FMETHOD names, or the only (else the lowest) one."""
    if not model.flutters:
        return None
    sids = sorted(model.flutters)
    chosen = None
    ccd = getattr(model, "case_control_deck", None)
    for sub in ccd.subcases.values() if ccd is not None else ():
        try:
            chosen = int(sub.get_parameter("FMETHOD")[0])
            break
        except (KeyError, ValueError, TypeError, IndexError):
            continue
    if chosen is not None and chosen not in model.flutters:
        raise InputError(
            f"{path}: case control FMETHOD = {chosen}: no FLUTTER {chosen} (the deck has "
            f"FLUTTER {', '.join(map(str, sids))})"
        )
    if chosen is None:
        chosen = sids[0]
        if len(sids) > 1:
            notes.append(f"no FMETHOD: FLUTTER {chosen} is the flutter case of FLUTTER {sids}")
    return model.flutters[chosen]


def _flutter_case(path: Path, model, units: UnitSystem, notes: list) -> FlutterCase | None:
    card = _selected_flutter(path, model, notes)
    if card is None:
        return None
    where = f"FLUTTER {card.sid}"
    method = str(card.method).upper()
    dens = _flfact(path, model, card.density, "density ratios", where)
    machs = _flfact(path, model, card.mach, "Mach numbers", where)
    third = _flfact(path, model, card.reduced_freq_velocity, "velocities", where)
    # a negative velocity asks Nastran to print the mode shape: its magnitude is the speed
    vel = tuple(abs(v) * units.length for v in third) if method in PK_METHODS else ()
    ks = () if method in PK_METHODS else third
    for m in machs:
        if not 0.0 <= m < 1.0:
            raise InputError(
                f"{path}: {where}: Mach {m:g} (FLFACT {card.mach}): aeroservo's flutter "
                "analysis takes Mach numbers in [0, 1)"
            )
    ids = ", ".join(str(x) for x in (card.density, card.mach, card.reduced_freq_velocity))
    return FlutterCase(
        card.sid, method, dens, machs, vel, ks, str(card.imethod or "L"),
        f"{where} ({method}; FLFACT {ids})", card.density,
    )  # fmt: skip


def _panels(path: Path, model, units: UnitSystem, notes: list) -> tuple[Panel, ...]:
    panels = []
    for eid, caero in sorted(model.caeros.items()):
        where = f"{path}: CAERO1 {eid}"
        paero = model.paeros[caero.pid]  # present: check_aero_references
        if any(getattr(paero, "caero_body_ids", None) or []):
            notes.append(f"PAERO1 {caero.pid}: its bodies are left out (no body aerodynamics)")
        p1, p2, p3, p4 = (np.asarray(p, dtype=float) * units.length for p in caero.get_points())
        c1, c4 = float(np.linalg.norm(p2 - p1)), float(np.linalg.norm(p3 - p4))
        if not (c1 > 0.0 and c4 > 0.0) or np.linalg.norm(p4 - p1) == 0.0:
            raise InputError(f"{where}: a zero chord or span (X12, X43, P1, P4)")
        nspan, nchord, uniform = caero.nspan, caero.nchord, True
        if caero.lspan:
            nspan, uniform = len(model.aefacts[caero.lspan].fractions) - 1, False
        if caero.lchord:
            nchord, uniform = len(model.aefacts[caero.lchord].fractions) - 1, False
        if not (nspan >= 1 and nchord >= 1):
            raise InputError(f"{where}: NSPAN = {nspan}, NCHORD = {nchord}: no boxes")
        panels.append(Panel(eid, p1, p4, c1, c4, int(nspan), int(nchord), uniform))
    return tuple(panels)


def _splines(path: Path, model, panels: tuple[Panel, ...]) -> tuple:
    out = []
    by_eid = {p.eid: p for p in panels}
    for eid, sp in sorted(model.splines.items()):
        where = f"{path}: {sp.type} {eid}"
        panel = by_eid[sp.caero]  # its CAERO1, SET1 and grids exist: check_aero_references
        for key in ("box1", "box2"):
            if panel.box(int(getattr(sp, key))) is None:
                last = panel.eid + panel.nspan * panel.nchord - 1
                raise InputError(
                    f"{where}: {key.upper()} = {getattr(sp, key)} is not a box of CAERO1 "
                    f"{panel.eid} (boxes {panel.eid} to {last})"
                )
        grids = tuple(int(g) for g in model.sets[sp.setg].ids)
        if not grids:
            raise InputError(f"{where}: SET1 {sp.setg} has no points: the spline carries nothing")
        out.append((sp.type, int(eid), int(sp.caero), grids))
    return tuple(out)


def _surfaces(path: Path, model, panels) -> tuple:
    out = []
    for _, surf in sorted(model.aesurf.items()):
        where = f"{path}: AESURF {surf.aesid} ({surf.label})"
        if surf.alid2:
            raise InputError(f"{where}: a second hinge line (CID2, ALID2) is not modelled")
        boxes = tuple(int(b) for b in model.aelists[surf.alid1].elements)  # present, as above
        stray = [b for b in boxes if not any(p.box(b) is not None for p in panels)]
        if stray:
            raise InputError(f"{where}: AELIST {surf.alid1}: box {stray[0]} is on no CAERO1")
        for p in panels:
            strips = sorted({p.box(b)[0] for b in boxes if p.box(b) is not None})
            if strips and strips != list(range(strips[0], strips[-1] + 1)):
                raise InputError(
                    f"{where}: AELIST {surf.alid1}: its boxes on CAERO1 {p.eid} lie in strips "
                    f"{strips}, not one continuous span"
                )
        out.append((str(surf.label), boxes))
    return tuple(out)


def aero_deck(path: Path, model, units: UnitSystem) -> AeroDeck | None:
    """The aerodynamic cards of a cross-referenced pyNastran model, or None without them.

    Raises
    ------
    InputError
        One line naming the card: a missing PAERO1, SET1, AELIST, FLFACT or CAERO1; a spline
        with no points or boxes outside its panel; a second hinge line.
    """
    if not (model.caeros or model.flutters or model.aero or model.aeros):
        return None
    notes: list[str] = []
    aero, aeros = model.aero, model.aeros
    ref = aero or aeros
    acsid = int(getattr(ref, "acsid", 0) or 0) if ref is not None else 0
    flow = np.array([1.0, 0.0, 0.0])
    if acsid:
        c = model.coords[acsid]
        flow = np.array(c.i, dtype=float)
    refc = getattr(ref, "cref", None) if ref is not None else None
    rho_deck = float(aero.rho_ref) if aero is not None and aero.rho_ref else None
    sym = int(getattr(ref, "sym_xz", 0) or 0) if ref is not None else 0
    panels = _panels(path, model, units, notes)
    flutter = _flutter_case(path, model, units, notes)
    if flutter is not None and not rho_deck:
        raise InputError(
            f"{path}: FLUTTER {flutter.sid}: its densities are ratios of AERO's RHOREF, and the "
            "deck has no AERO card (AEROS has no density): add AERO with RHOREF"
        )
    param = model.params.get("LMODES")
    ratio = flutter.density_ratios[0] if flutter and flutter.density_ratios else 1.0
    card = f"FLFACT {flutter.density_fact}" if flutter else "AERO"
    return AeroDeck(
        flow=flow,
        ref_chord=float(refc) * units.length if refc else None,
        rho_ref=rho_deck * units.density if rho_deck else None,
        rho_ref_deck=rho_deck,
        symmetry=sym,
        panels=panels,
        splines=_splines(path, model, panels),
        surfaces=_surfaces(path, model, panels),
        flutter=flutter,
        lmodes=int(param.values[0]) if param is not None else None,
        density_ratio=ratio,
        density_card=(f"AERO RHOREF x {card}", "the flutter case's air density"),
        notes=notes,
    )


def check_aero_references(path: Path, model) -> None:
    """Missing PAERO1, CAERO1, SET1, AELIST, AEFACT and FLFACT cards, named before pyNastran's
    cross-referencing would (one line each)."""
    for eid, caero in sorted(model.caeros.items()):
        if caero.pid not in model.paeros:
            raise InputError(f"{path}: CAERO1 {eid}: PAERO1 {caero.pid} is missing")
        boxes = int(caero.nspan or 1) * int(caero.nchord or 1)
        if boxes > MAX_BOXES:  # pyNastran numbers them in one array when cross-referencing
            raise InputError(
                f"{path}: CAERO1 {eid}: NSPAN = {caero.nspan}, NCHORD = {caero.nchord}: "
                f"{boxes} boxes, more than the {MAX_BOXES} a panel may have"
            )
        for key in ("lspan", "lchord"):
            fid = getattr(caero, key, 0)
            if fid and fid not in model.aefacts:
                raise InputError(f"{path}: CAERO1 {eid}: {key.upper()} = AEFACT {fid} is missing")
    for eid, sp in sorted(model.splines.items()):
        if sp.caero not in model.caeros:
            raise InputError(f"{path}: {sp.type} {eid}: CAERO1 {sp.caero} is missing")
        if sp.setg not in model.sets:
            raise InputError(
                f"{path}: {sp.type} {eid}: SETG = {sp.setg}: SET1 {sp.setg} is missing"
            )
        missing = [g for g in model.sets[sp.setg].ids if g not in model.nodes]
        if missing:
            raise InputError(f"{path}: SET1 {sp.setg}: GRID {missing[0]} is missing")
    for aesid, surf in sorted(model.aesurf.items()):
        for key in ("alid1", "alid2"):
            lid = getattr(surf, key, None)
            if lid and lid not in model.aelists:
                raise InputError(f"{path}: AESURF {aesid}: {key.upper()} = AELIST {lid} is missing")
    for sid, fl in sorted(model.flutters.items()):
        for key in ("density", "mach", "reduced_freq_velocity"):
            fid = getattr(fl, key, None)
            if fid and fid not in model.flfacts:
                raise InputError(f"{path}: FLUTTER {sid}: FLFACT {fid} ({key}) is missing")
