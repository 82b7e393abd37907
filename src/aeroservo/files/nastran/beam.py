"""A Nastran stick model (:class:`~.deck.Deck`) as an aeroservo wing.

The grids of the beam line are the elastic axis. From the clamped root grid the elements are
followed outward (no branching); each element's length adds to the span along the elastic
axis, its in-plane angle to the normal of the free stream is its sweep (+ aft), and its
section gives EI about the chordwise axis, GJ, the mass per length and the pitch inertia per
length. Consecutive elements with equal values make one segment. Point masses become
:class:`~aeroservo.structure.wing.ConcentratedMass` at their grid's station, with the CG
offset resolved along the chord (normal to the beam, + aft) and up. Card by card:
``docs/nastran.md``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...errors import InputError
from ...structure.wing import MAX_SWEEP, Segment, check_sweep
from .companion import ImportOptions
from .deck import Deck, Element, vector_text

__all__ = [
    "BeamElement",
    "beam_line",
    "element_values",
    "segments",
    "PLANE_TOLERANCE",
]

PLANE_TOLERANCE = 1e-4
"""Largest angle [rad] of an element out of the wing's plane (rounding in the deck's fields)."""

ORIENTATION_TOLERANCE = 1e-3
"""Largest angle [rad] between a section's principal axis and the wing's vertical."""


@dataclass(frozen=True)
class BeamElement:
    """An element on the beam line, in order from the root."""

    element: Element
    inboard: int  # grid
    outboard: int  # grid
    start: float  # [m] along the elastic axis
    end: float
    span_dir: np.ndarray  # unit, in the wing plane, root to tip
    aft: np.ndarray  # unit, in the wing plane, normal to the beam, + downstream
    sweep: float  # [rad]
    flap_plane: str  # "I1" or "I2"
    axes: np.ndarray  # rows: the element's y and z axes [basic]


def _clamped_root(deck: Deck, up: np.ndarray) -> int:
    """The one grid whose constraints clamp the out-of-plane motion."""
    path = deck.path
    clamps = {}
    for nid, cons in deck.constraints.items():
        trans = [a for k, a in cons if k == "T"]
        rots = [a for k, a in cons if k == "R"]
        out_of_plane = any(abs(a @ up) > 1e-6 for a in trans) or any(
            np.linalg.norm(a - (a @ up) * up) > 1e-6 for a in rots
        )
        if out_of_plane:
            clamps[nid] = (trans, rots)
    if not clamps:
        raise InputError(
            f"{path}: no SPC clamps a grid (a free-free model): aeroservo's wing is a cantilever; "
            "add SPC1 with components 123456 at the root grid"
        )
    if len(clamps) > 1:
        raise InputError(
            f"{path}: SPCs restrain the out-of-plane motion of GRIDs {sorted(clamps)}: aeroservo's "
            "wing is clamped at one root grid only"
        )
    ((nid, (trans, rots)),) = clamps.items()
    basis = np.linalg.svd(np.array([[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0]]) - np.outer(up, up))[0]
    in_plane = basis[:, :2].T

    def spans(vectors, targets) -> bool:
        if not vectors:
            return False
        m = np.array(vectors).T
        for t in targets:
            coef = np.linalg.lstsq(m, t, rcond=None)[0]
            if np.linalg.norm(m @ coef - t) > 1e-6:
                return False
        return True

    if not (spans(trans, [up]) and spans(rots, list(in_plane))):
        raise InputError(
            f"{path}: GRID {nid}: the SPCs restrain it only partly: the root must be clamped "
            "(the vertical translation and the rotations about the in-plane axes; SPC1 123456)"
        )
    return nid


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def beam_line(deck: Deck, opts: ImportOptions) -> tuple[int, list[BeamElement]]:
    """The root grid and the elements from the root to the tip.

    Raises
    ------
    InputError
        No clamp, branching, elements not connected to the root, zero length, an element out
        of the wing plane or swept beyond 60 deg, or a section not aligned with the vertical.
    """
    path, up = deck.path, opts.up
    root = _clamped_root(deck, up)
    at: dict[int, list[Element]] = {}
    pairs: dict[frozenset, int] = {}
    for e in deck.elements:
        key = frozenset((e.ga, e.gb))
        if len(key) == 1:
            raise InputError(f"{path}: {e.card} {e.eid}: both ends on GRID {e.ga}")
        if key in pairs:
            raise InputError(
                f"{path}: {e.card} {pairs[key]} and {e.card} {e.eid} both join GRIDs "
                f"{sorted(key)} (parallel beams): one beam line is imported"
            )
        pairs[key] = e.eid
        for g in (e.ga, e.gb):
            at.setdefault(g, []).append(e)
    for g, elems in sorted(at.items()):
        if len(elems) > 2:
            ids = ", ".join(f"{e.card} {e.eid}" for e in elems)
            raise InputError(
                f"{path}: GRID {g} joins {len(elems)} elements ({ids}): branching beam lines are "
                "not supported; import one wing without its branches"
            )
    if root not in at:
        raise InputError(f"{path}: the clamped GRID {root} is on no beam element")
    if len(at[root]) != 1:
        raise InputError(
            f"{path}: the clamped GRID {root} is inside the beam line (elements on both sides, a "
            "two-wing model?): import one wing, clamped at its root"
        )
    flow = opts.free_stream - (opts.free_stream @ up) * up
    flow = _unit(flow)
    line: list[BeamElement] = []
    node, seen, x = root, set(), 0.0
    lateral = None
    while True:
        nxt = [e for e in at[node] if e.eid not in seen]
        if not nxt:
            break
        e = nxt[0]
        seen.add(e.eid)
        out = e.gb if e.ga == node else e.ga
        d = deck.grids[out] - deck.grids[node]
        length = float(np.linalg.norm(d))
        where = f"{path}: {e.card} {e.eid} (GRID {node} to {out})"
        if length == 0.0:
            raise InputError(f"{where}: zero length (the grids coincide)")
        s = d / length
        rise = math.asin(max(-1.0, min(1.0, float(s @ up))))
        if abs(rise) > PLANE_TOLERANCE:
            raise InputError(
                f"{where}: {math.degrees(rise):.3g} deg out of the wing plane (normal to up = "
                f"{vector_text(up)}): dihedral and bent beam lines are not modelled "
                "(aeroservo's wing is flat; only in-plane sweep kinks are allowed)"
            )
        sp = _unit(s - (s @ up) * up)
        if lateral is None:
            lateral = _unit(np.cross(up, flow))
            lateral = lateral if lateral @ sp >= 0.0 else -lateral
        sweep = math.atan2(float(sp @ flow), float(sp @ lateral))
        if abs(sweep) > MAX_SWEEP + 5e-5:
            check_sweep(f"{where}: sweep", sweep)
        aft = _unit(flow - (flow @ sp) * sp) if abs(sweep) < math.pi / 2 else -lateral
        plane, axes = _flap_plane(deck, e, up)
        line.append(BeamElement(e, node, out, x, x + length, sp, aft, sweep, plane, axes))
        x += length
        node = out
    missing = [e for e in deck.elements if e.eid not in seen]
    if missing:
        e = missing[0]
        raise InputError(
            f"{path}: {e.card} {e.eid} (GRIDs {e.ga}, {e.gb}) is not connected to the root GRID "
            f"{root} through the beam line: one connected beam is imported"
        )
    return root, line


def _flap_plane(deck: Deck, e: Element, up: np.ndarray) -> tuple[str, np.ndarray]:
    """``"I1"`` when plane 1 (element x and its orientation vector) is vertical, ``"I2"`` when
    plane 2 is (a section with equal I1 and I2 takes either), and the element's y, z axes."""
    where = f"{deck.path}: {e.card} {e.eid}"
    s = _unit(deck.grids[e.gb] - deck.grids[e.ga])
    v = deck.grids[e.g0] - deck.grids[e.ga] if e.v is None else e.v
    y = v - (v @ s) * s
    if np.linalg.norm(y) <= 1e-9 * max(1.0, float(np.linalg.norm(v))):
        raise InputError(f"{where}: its orientation vector is parallel to the beam")
    y = _unit(y)
    z = np.cross(s, y)
    cos_tol = math.cos(ORIENTATION_TOLERANCE)
    axes = np.array([y, z])
    if abs(y @ up) >= cos_tol:
        return "I1", axes
    if abs(z @ up) >= cos_tol:
        return "I2", axes
    sec = e.section
    if math.isclose(sec.I1, sec.I2, rel_tol=1e-9) and not (sec.m1 or sec.m2):
        return "I1", axes
    angle = math.degrees(math.acos(min(1.0, abs(float(y @ up)))))
    raise InputError(
        f"{where}: its orientation vector puts plane 1 {angle:.3g} deg from the vertical with I1 "
        f"!= I2: flapwise and in-plane bending would couple, which is not modelled; orient the "
        "element vertically (or in the wing plane)"
    )


def element_values(
    be: BeamElement, opts: ImportOptions, geometry: dict | None = None
) -> dict[str, tuple[float, str]]:
    """Segment values of one element, key -> (value, where it came from); ``geometry``: the
    semichord and elastic axis of each element from the deck's CAERO1 panels (by element id),
    used where the options give none."""
    sec, e = be.element.section, be.element
    mid = 0.5 * (be.start + be.end)
    out: dict[str, tuple[float, str]] = {}
    for key in ("semichord", "a"):
        given = opts.value(key, mid)
        if given is None and geometry:
            given = geometry.get(e.eid, {}).get(key)
        if given is None:
            what = "--chord or --semichord" if key == "semichord" else "--elastic-axis"
            raise InputError(
                f"no {'semichord' if key == 'semichord' else 'elastic-axis position a'} for "
                f"{e.card} {e.eid}: a beam deck has no aerodynamic chord; give {what} or "
                f"'{key}' in the companion table (docs/nastran.md)"
            )
        out[key] = given
    plane = be.flap_plane
    i_flap = sec.I1 if plane == "I1" else sec.I2
    if not i_flap > 0.0:
        raise InputError(
            f"{sec.label}: {plane} = 0 is the flapwise moment of {e.card} {e.eid} (its plane "
            f"{plane[1]} is vertical by its orientation vector): give {plane}, or orient the "
            "element's vector up"
        )
    out["EI"] = (sec.E * i_flap, f"E*{plane} of {sec.label} (plane {plane[1]} is vertical)")
    out["GJ"] = (sec.G * sec.J, f"G*J of {sec.label}")
    given = opts.value("mass", mid)
    m = sec.rho * sec.A + sec.nsm
    out["mass"] = given or (m, f"rho*A + NSM of {sec.label}")
    # the non-structural mass's CG (PBEAM M1, M2, element axes) along the chord and up
    yv = sec.m1 * be.axes[0] + sec.m2 * be.axes[1] if (sec.m1 or sec.m2) else None
    c_off = float(yv @ be.aft) if yv is not None else 0.0
    z_off = float(yv @ opts.up) if yv is not None else 0.0
    b = out["semichord"][0]
    given = opts.value("x_alpha", mid)
    if given is not None:
        out["x_alpha"] = given
    elif yv is not None:
        out["x_alpha"] = (sec.nsm * c_off / (out["mass"][0] * b), f"NSM CG M1, M2 of {sec.label}")
    else:
        out["x_alpha"] = (0.0, "the deck gives no CG offset (CG on the elastic axis)")
    given = opts.value("inertia", mid)
    if given is not None:
        out["inertia"] = given
    else:
        inertia = sec.rho * (sec.I1 + sec.I2) + sec.nsi + sec.nsm * (c_off**2 + z_off**2)
        if not inertia > 0.0:
            raise InputError(
                f"{sec.label}: no pitch inertia per length (rho*(I1+I2) = 0): give 'inertia' "
                "[kg m] in the companion table"
            )
        what = "rho*(I1+I2) + NSI + NSM r^2" if sec.gives_inertia else "rho*(I1+I2)"
        out["inertia"] = (inertia, f"{what} of {sec.label}")
    out["sweep"] = (be.sweep, "in-plane angle of the beam line, + aft")
    return out


def segments(
    line: list[BeamElement], opts: ImportOptions, geometry: dict | None = None
) -> tuple[list[Segment], list[str], list[dict[str, str]]]:
    """Merge equal consecutive elements into segments: segments, headers, sources per key
    (``geometry``: as :func:`element_values`)."""
    groups: list[tuple[list[BeamElement], dict]] = []
    for be in line:
        vals = element_values(be, opts, geometry)
        if groups and _same(groups[-1][1], vals):
            groups[-1][0].append(be)
        else:
            groups.append(([be], vals))
    segs, headers, sources = [], [], []
    for i, (members, vals) in enumerate(groups):
        first, last = members[0], members[-1]
        e0, e1 = first.element, last.element
        ids = f"{e0.card} {e0.eid}" + (f" to {e1.eid}" if len(members) > 1 else "")
        name = f"segment {i} ({ids})"
        sweep = vals["sweep"][0]
        if len(members) > 1:
            d = sum((m.span_dir * (m.end - m.start) for m in members), np.zeros(3))
            sweep = math.atan2(float(d @ _flow(first)), float(d @ _lateral(first)))
        kw = {k: v for k, (v, _s) in vals.items() if k != "sweep"}
        segs.append(Segment(start=first.start, end=last.end, name=name, sweep=sweep, **kw))
        labels = list(dict.fromkeys(m.element.section.label for m in members))
        shown = "; ".join(labels[:3]) + ("; ..." if len(labels) > 3 else "")
        headers.append(
            f"{ids} ({len(members)} element{'s' * (len(members) > 1)}), GRID {first.inboard} "
            f"to {last.outboard}, {shown}"
        )
        sources.append({k: s for k, (_v, s) in vals.items()})
    return segs, headers, sources


def _flow(be: BeamElement) -> np.ndarray:
    return math.sin(be.sweep) * be.span_dir + math.cos(be.sweep) * be.aft


def _lateral(be: BeamElement) -> np.ndarray:
    return math.cos(be.sweep) * be.span_dir - math.sin(be.sweep) * be.aft


def _same(a: dict, b: dict) -> bool:
    """Equal values (the cards they came from may differ)."""
    for k in a:
        va, vb = a[k][0], b[k][0]
        if k == "sweep":
            if abs(va - vb) > 1e-9:
                return False
        elif not math.isclose(va, vb, rel_tol=1e-12, abs_tol=0.0):
            return False
    return True
