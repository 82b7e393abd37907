"""A deck's aerodynamic model and flutter case as the wing's chord, its doublet lattice and a
flutter scenario.

* **Chord and elastic axis.** Each beam element's midpoint is placed on the CAERO1 panel that
  spans it (across the flow): the panel's streamwise chord c and leading edge there give the
  axis's chord fraction f, so ``a = 2 f - 1`` and the semichord normal to the beam
  ``b = c cos(sweep) / 2`` (aeroservo's sections are normal to the elastic axis,
  ``docs/sweep.md``).
* **Boxes.** NCHORD boxes along the chord, the panels' NSPAN strips summed along the span;
  SYMXZ = 1 is a symmetric root, 0 an isolated wing; PARAM,LMODES the aerodynamic basis.
* **Flutter case.** The FLUTTER card's first density ratio x RHOREF, its first Mach number and
  its velocities (PK) become a flutter scenario whose ``[sol145]`` table asks for the p-k at
  those velocities in Nastran's flutter-summary vocabulary (``stability/sol145.py``).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ...errors import InputError, check_quantity
from .aero import PK_METHODS, AeroDeck, Panel

__all__ = [
    "panel_geometry",
    "surface_geometry",
    "analysis_tables",
    "scenario_text",
    "case_v_max",
    "box_counts",
]

COVER_TOLERANCE = 1e-3
"""Largest part of the beam's extent across the flow [-] a panel may leave uncovered."""


def _lateral(aero: AeroDeck, up: np.ndarray) -> np.ndarray:
    lat = np.cross(up, aero.flow)
    return lat / np.linalg.norm(lat)


def _at(panel: Panel, eta: float, lat: np.ndarray, tol: float) -> tuple | None:
    """The leading-edge point and streamwise chord of a panel at ``eta`` across the flow."""
    e1, e4 = float(panel.p1 @ lat), float(panel.p4 @ lat)
    t = (eta - e1) / (e4 - e1)
    if not -tol <= t <= 1.0 + tol:
        return None
    t = min(max(t, 0.0), 1.0)
    return panel.p1 + t * (panel.p4 - panel.p1), panel.c1 + t * (panel.c4 - panel.c1)


def _section(aero: AeroDeck, eta: float, lat: np.ndarray, tol: float) -> tuple | None:
    """The wing's section at ``eta``: leading edge and trailing edge along the flow over every
    panel that spans it (a wing panel and a control-surface panel behind it make one chord),
    and the panels' ids; None where no panel does."""
    hits = [(p, *r) for p in aero.panels if (r := _at(p, eta, lat, tol)) is not None]
    if not hits:
        return None
    le = min(float(pt @ aero.flow) for _, pt, _ in hits)
    te = max(float(pt @ aero.flow) + c for _, pt, c in hits)
    return le, te, [p.eid for p, _, _ in hits]


def panel_geometry(path: Path, aero: AeroDeck, line, grids: dict, up: np.ndarray) -> dict:
    """Semichord (normal to the beam) and elastic-axis position of each element, by element id.

    Raises
    ------
    InputError
        The panels do not cover the beam across the flow, or the beam lies outside the chord.
    """
    if not aero.panels:
        return {}
    lat = _lateral(aero, up)
    span = max(abs(float((grids[be.outboard] - grids[line[0].inboard]) @ lat)) for be in line)
    tol = COVER_TOLERANCE
    etas = [float(grids[g] @ lat) for g in (line[0].inboard, line[-1].outboard)]
    cover = [float(p @ lat) for pan in aero.panels for p in (pan.p1, pan.p4)]
    lo, hi = min(cover), max(cover)
    if min(etas) < lo - tol * span or max(etas) > hi + tol * span:
        raise InputError(
            f"{path}: the CAERO1 panels span {lo:.6g} to {hi:.6g} m across the flow, the beam "
            f"{min(etas):.6g} to {max(etas):.6g} m: the aerodynamic grid does not cover the beam"
        )
    out = {}
    for be in line:
        mid = 0.5 * (grids[be.inboard] + grids[be.outboard])
        eta = float(mid @ lat)
        section = _section(aero, eta, lat, tol * span / 100)
        e = be.element
        if section is None:
            raise InputError(
                f"{path}: {e.card} {e.eid}: no CAERO1 panel spans its midpoint ({eta:.6g} m "
                "across the flow): the aerodynamic grid does not cover the beam"
            )
        le, te, ids = section
        chord = te - le
        frac = (float(mid @ aero.flow) - le) / chord
        names = "CAERO1 " + ", ".join(map(str, ids))
        if not 0.0 <= frac <= 1.0:
            raise InputError(
                f"{path}: {e.card} {e.eid}: the beam lies {frac * 100:.3g} % of the chord of "
                f"{names} behind its leading edge, outside the chord: the elastic axis must lie "
                "within the panels (or give --elastic-axis)"
            )
        b = 0.5 * chord * math.cos(be.sweep)
        src = f"{names}: streamwise chord {chord:.6g} m"
        out[e.eid] = {
            # to the 7 digits of the deck's 8-character fields, so that the elements of one
            # straight panel make one segment
            "semichord": (float(f"{b:.7g}"), f"{src} x cos(sweep) / 2 (normal to the beam)"),
            "a": (round(2.0 * frac - 1.0, 6), f"{names}: the beam at {frac:.6g} chord"),
        }
    return out


def surface_geometry(aero: AeroDeck, line, grids: dict, up: np.ndarray) -> dict:
    """Each AESURF's span interval along the beam [m] and its hinge [semichords aft of
    mid-chord]: the span of its boxes' strips, the hinge line their forward edge, as a fraction
    of the wing's chord (every panel spanning the strip) at its middle."""
    lat = _lateral(aero, up)
    out = {}
    root = float(grids[line[0].inboard] @ lat)
    cos_l = abs(float(line[0].span_dir @ lat))  # lateral distance per length along the beam
    for label, boxes in aero.surfaces:
        spans, hinges = [], []
        for p in aero.panels:
            for b in boxes:
                hit = p.box(b)
                if hit is None:
                    continue
                strip, k = hit
                e1, e4 = float(p.p1 @ lat), float(p.p4 @ lat)
                ends = [e1 + (e4 - e1) * (strip + f) / p.nspan for f in (0.0, 1.0)]
                spans += ends
                eta = 0.5 * sum(ends)
                le_pt, chord = _at(p, eta, lat, 1e-9)
                x_h = float(le_pt @ aero.flow) + chord * k / p.nchord
                le, te, _ = _section(aero, eta, lat, 1e-9)
                hinges.append(2.0 * (x_h - le) / (te - le) - 1.0)
        if not spans:
            continue
        start, end = sorted(abs(e - root) / cos_l for e in (min(spans), max(spans)))
        out[label] = {"start": start, "end": end, "hinge": min(hinges)}
    return out


def case_v_max(aero: AeroDeck, frequencies) -> float | None:
    """The upper end of the speed search [m/s] that covers the flutter case: 1.25 x its
    highest velocity (PK methods), or the speed at which the highest mode of the aerodynamic
    basis reaches the lowest reduced frequency (K, KE: ``V = omega (REFC/2) / k``)."""
    fc = aero.flutter
    if fc is None:
        return None
    if fc.velocities:
        return 1.25 * max(fc.velocities)
    ks = [k for k in fc.reduced_frequencies if k > 0]
    if not ks or not aero.ref_chord or len(frequencies) == 0:
        return None
    v = 2 * math.pi * max(frequencies) * 0.5 * aero.ref_chord / min(ks)
    return float(min(v, 1000.0))


def analysis_tables(
    aero: AeroDeck, n_elements: int, boxes: tuple, v_max: float | None = None
) -> str:
    """The wing file's ``[analysis]`` and ``[dlm]`` tables of the deck's aerodynamic model
    (``v_max``: :func:`case_v_max`)."""
    lines = ["[analysis]"]
    fc = aero.flutter
    if n_elements <= 300:
        lines.append(f"elements = {n_elements}  # one per CBAR/CBEAM: nodes at the deck's grids")
    density = _density(aero)
    if density is not None:
        lines.append(f"density = {density:.10g}  # {aero.density_card[0]} [kg/m^3]")
    if aero.panels:
        lines.append('aero = "dlm"  # CAERO1 panels: the doublet lattice')
        if fc and fc.machs:
            lines.append(f"mach = {fc.machs[0]:.10g}  # FLUTTER {fc.sid}: its Mach FLFACT")
    if v_max is not None:
        lines.append(f"v_max = {v_max:.6g}  # covers FLUTTER {fc.sid}'s velocities or k")
    if aero.panels:
        lines += ["", "[dlm]"] + _dlm_keys(aero, boxes)
    return "\n".join(lines) + "\n"


def _density(aero: AeroDeck) -> float | None:
    if aero.rho_ref is None:
        return None
    value = aero.rho_ref * aero.density_ratio
    return check_quantity(aero.density_card[0], value, "density")


def box_counts(aero: AeroDeck, up: np.ndarray, pieces: int, notes: list[str]) -> tuple:
    """The doublet lattice's boxes from the deck's: chordwise, the most boxes any section has
    across the panels stacked along the flow there; spanwise, the strips between the distinct
    strip edges of all panels (panels side by side add, stacked ones share), at least one per
    spanwise piece of the wing (``pieces``: segments and control-surface edges)."""
    lat = _lateral(aero, up)
    edges, chord = [], 0
    for p in aero.panels:
        e1, e4 = float(p.p1 @ lat), float(p.p4 @ lat)
        edges += [e1 + (e4 - e1) * k / p.nspan for k in range(p.nspan + 1)]
    scale = max(abs(e) for e in edges) or 1.0
    edges = np.unique(np.round(np.asarray(edges) / scale, 6))
    spanwise = 0
    for a, b in zip(edges[:-1], edges[1:], strict=False):
        mid = 0.5 * (a + b) * scale
        hits = [p for p in aero.panels if _at(p, mid, lat, 0.0) is not None]
        if hits:
            spanwise += 1
            chord = max(chord, sum(p.nchord for p in hits))
    if not all(p.uniform for p in aero.panels):
        notes.append("CAERO1 LSPAN/LCHORD (AEFACT): the doublet lattice takes equal boxes")
    if spanwise < pieces:
        notes.append(
            f"the deck's {spanwise} strips are fewer than the wing's {pieces} spanwise pieces "
            f"(segments and control-surface edges): the doublet lattice takes {pieces}"
        )
        spanwise = pieces
    return chord, spanwise


def _dlm_keys(aero: AeroDeck, boxes: tuple) -> list[str]:
    ids = ", ".join(str(p.eid) for p in aero.panels)
    keys = [
        f"chordwise = {boxes[0]}  # CAERO1 {ids}: NCHORD",
        f"spanwise = {boxes[1]}  # CAERO1 {ids}: NSPAN",
    ]
    if aero.symmetry == -1:
        raise InputError(
            "AERO SYMXZ = -1 (antisymmetric): aeroservo's doublet lattice has no antisymmetric "
            "image; import with SYMXZ = 0 (isolated wing) or 1 (symmetric)"
        )
    sym = "true" if aero.symmetry == 1 else "false"
    keys.append(f"symmetric = {sym}  # AERO SYMXZ = {aero.symmetry}")
    if aero.lmodes:
        keys.append(f"modes = {aero.lmodes}  # PARAM,LMODES")
    return keys


def scenario_text(
    aero: AeroDeck,
    wing_file: str,
    name: str,
    deck: Path,
    units,
    n_elements: int,
    boxes: tuple,
    v_max: float | None = None,
) -> str | None:
    """A flutter scenario running the deck's flutter case (None without a FLUTTER card)."""
    fc = aero.flutter
    if fc is None:
        return None
    density = _density(aero)
    rows = [
        f"# The flutter case of {deck.name} ({fc.cards}), written by 'aeroservo import nastran'.",
        f"# Run: aeroservo flutter {Path(wing_file).stem}_flutter.toml (docs/nastran.md).",
        "[scenario]",
        f'name = "{name}: FLUTTER {fc.sid} ({fc.method})"',
        'kind = "flutter"',
        "",
        "[wing]",
        f'file = "{Path(wing_file).name}"',
        "",
        "[flight]",
        f"density = {density if density is not None else 1.225:.10g}  # kg/m^3",
        "",
        "[model]",
        "pk = true",
    ]
    if n_elements <= 300:
        rows.append(f"elements = {n_elements}")
    if v_max is not None:
        rows.append(f"v_max = {v_max:.6g}  # m/s")
    if aero.panels:
        rows += ['aero = "dlm"']
        if fc.machs:
            rows.append(f"mach = {fc.machs[0]:.10g}")
        rows += ["", "[model.dlm]"] + [k.split("  #")[0] for k in _dlm_keys(aero, boxes)]
    rows += ["", "[sol145]", f'method = "{fc.method}"']
    if fc.method in PK_METHODS and fc.velocities:
        factor = units.length
        vals = ", ".join(f"{v:.10g}" for v in fc.velocities)
        rows.append(f"velocities = [{vals}]  # m/s")
        if units.name != "si":
            rows.append(f'velocity_unit = "{units.length_label}/s"  # shown next to m/s')
            rows.append(f"velocity_factor = {factor:.10g}  # m/s per {units.length_label}/s")
    elif fc.reduced_frequencies:
        ks = ", ".join(f"{k:.6g}" for k in fc.reduced_frequencies)
        rows.append(f"# the deck's reduced frequencies {ks}: the p-k is tabulated over speed")
    if aero.ref_chord:
        rows.append(f"reference_chord = {aero.ref_chord:.10g}  # m, AERO REFC: KFREQ = w c/2V")
    rows.append(f"density_ratio = {aero.density_ratio:.10g}")
    return "\n".join(rows) + "\n"
