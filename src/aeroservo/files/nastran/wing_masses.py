"""The mass cards of a deck (``files/nastran/masses.py``) as the wing's concentrated masses.

Each mass is placed at its grid's station along the beam line. A CONM2 keeps its CG (along the
span: a shifted station; along the chord: ``offset``, + aft; up: ``vertical_offset``) and its
inertia about the beam axis; a 6 x 6 matrix (CONM1, rotational scalar masses) is projected on
the vertical translation and the pitch about the beam axis; a vertical scalar mass is a point
mass on the axis. What the wing has no motion for (in-plane, bending rotation) is left out and
said so.
"""

from __future__ import annotations

import math

import numpy as np

from ...errors import InputError
from ...structure.wing import ConcentratedMass
from .beam import ORIENTATION_TOLERANCE, BeamElement
from .deck import Deck

__all__ = ["point_masses"]


def point_masses(
    deck: Deck, root: int, line: list[BeamElement], up: np.ndarray
) -> tuple[list[ConcentratedMass], list[str], list[str]]:
    """Concentrated masses of the mass cards (``files/nastran/masses.py``), their notes, and what
    is left out."""
    station = {root: 0.0}
    frame = {root: line[0]}
    for be in line:
        station[be.outboard] = be.end
        frame[be.outboard] = be
    span = line[-1].end
    masses, notes, left = [], [], []
    for pm in deck.masses:
        label = f"{pm.card} {pm.eid}"
        if pm.grid not in station:
            raise InputError(
                f"{deck.path}: {label} is on GRID {pm.grid}, which is on no beam element"
            )
        be = frame[pm.grid]
        if pm.grid == root:
            left.append(f"{label} on the clamped root GRID {root} (it does not move)")
            continue
        if pm.matrix is not None:
            mass = _matrix_mass(deck, pm, be, up, station[pm.grid])
            if mass is None:
                left.append(f"{label} (only in-plane and bending rotary terms)")
            else:
                masses.append(mass)
                notes.append(
                    f"{label} at GRID {pm.grid}: its 6x6 mass matrix on the vertical translation "
                    "and the pitch about the beam axis (in-plane and bending rotary terms left out)"
                )
            continue
        if pm.direction is not None:
            if abs(pm.direction @ up) >= math.cos(ORIENTATION_TOLERANCE):
                masses.append(_mass(deck, pm, station[pm.grid], pm.mass))
                notes.append(f"{label}: vertical scalar mass at GRID {pm.grid}")
            elif abs(pm.direction @ up) <= math.sin(ORIENTATION_TOLERANCE):
                left.append(f"{label} (in-plane: the wing has no in-plane motion)")
            else:
                raise InputError(
                    f"{deck.path}: {label}: its component is oblique to the vertical: only "
                    "vertical (or in-plane, left out) scalar masses are supported"
                )
            continue
        r = pm.cg - deck.grids[pm.grid]
        x = station[pm.grid] + float(r @ be.span_dir)
        if not 0.0 < x <= span * (1 + 1e-12):
            raise InputError(
                f"{deck.path}: {label}: its CG lies {float(r @ be.span_dir):g} m along the span "
                f"from GRID {pm.grid}, at station {x:g} m, outside the wing (0, {span:g}] m"
            )
        inertia = float(be.span_dir @ pm.inertia @ be.span_dir)
        if pm.mass == 0.0 and not inertia > 0.0:
            left.append(f"{label} (no mass and no inertia about the beam axis)")
            continue
        if pm.mass == 0.0:
            r = np.zeros(3)
        masses.append(
            _mass(
                deck,
                pm,
                min(x, span),
                pm.mass,
                offset=float(r @ be.aft),
                inertia=max(inertia, 0.0),
                vertical_offset=float(r @ up),
            )
        )
        shift = f", CG {float(r @ be.span_dir):g} m outboard" if r @ be.span_dir else ""
        notes.append(f"{label} at GRID {pm.grid}{shift}; inertia = I about the beam axis")
    return masses, notes, left


def _matrix_mass(deck, pm, be: BeamElement, up: np.ndarray, x: float):
    """A 6 x 6 mass matrix at a grid projected on the wing's vertical translation w and pitch
    phi (nose up), ``[[m, -m y], [-m y, I + m y^2]]``; None if both are free of it."""
    pitch = -float(np.cross(be.span_dir, be.aft) @ up) * be.span_dir  # nose-up rotation axis
    m = pm.matrix
    m_ww = float(up @ m[:3, :3] @ up)
    m_wp = float(up @ m[:3, 3:] @ pitch)
    m_pp = float(pitch @ m[3:, 3:] @ pitch)
    tol = 1e-12 * max(1.0, float(np.abs(m).max()))
    if m_ww <= tol and m_pp <= tol:
        return None
    if m_ww <= tol:
        return _mass(deck, pm, x, 0.0, inertia=m_pp)
    y = -m_wp / m_ww
    inertia = max(m_pp - m_ww * y * y, 0.0)
    return _mass(deck, pm, x, m_ww, offset=y, inertia=inertia)


def _mass(deck: Deck, pm, x: float, mass: float, **kw) -> ConcentratedMass:
    """A :class:`ConcentratedMass` of a mass card; its checks name the deck and the card."""
    label = f"{pm.card} {pm.eid}"
    try:
        return ConcentratedMass(x, mass, name=label, **kw)
    except InputError as exc:
        why = str(exc).replace(f"mass '{label}'.", "", 1)
        read = "SI" if deck.units.name == "si" else f"{deck.units.name} converted to SI"
        raise InputError(
            f"{deck.path}: {label} at GRID {pm.grid}: {why} (the deck read as {read}, PARAM "
            f"WTMASS = {deck.wtmass:g}: check --units)"
        ) from None
