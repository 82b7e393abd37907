"""Nastran mass cards as point masses in SI and the basic frame: CONM2, CONM1, CMASS1, CMASS2.

A CONM2 is a rigid body (mass, CG, inertia tensor; a CONM2 with inertia and no mass is a pure
rotary inertia). A CONM1 is a 6 x 6 mass matrix at its grid, a CMASS1/CMASS2 a scalar mass on
one component of one grid: a translation (a mass) or a rotation (an inertia about that axis).
They are kept as given, in SI and the basic frame; ``files/nastran/beam.py`` projects them on
the wing's motions (vertical translation and pitch about the beam axis).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...errors import InputError
from .units import UnitSystem

__all__ = ["PointMass", "point_mass", "frame_axes", "check_mass_references", "MASS_CARDS"]

MASS_CARDS = ("CONM2", "CONM1", "CMASS1", "CMASS2", "PMASS")
"""Mass cards read (PMASS: the property of CMASS1)."""


@dataclass(frozen=True)
class PointMass:
    """A mass card at one grid (SI, basic frame).

    ``matrix`` is set for a CONM1 and a rotational scalar mass: the 6 x 6 mass matrix on the
    grid's translations and rotations [kg, kg m, kg m^2]; ``direction`` for a translational
    scalar mass (CMASS1/CMASS2): the direction of its component.
    """

    card: str
    eid: int
    grid: int
    mass: float  # [kg], WTMASS applied
    cg: np.ndarray  # CG position [m, basic]
    inertia: np.ndarray  # 3x3 inertia tensor about the CG [kg m^2, basic]
    direction: np.ndarray | None = None
    matrix: np.ndarray | None = None


def frame_axes(coord) -> np.ndarray:
    """Rows: the frame's unit axes in the basic frame."""
    if coord is None or coord.cid == 0:
        return np.eye(3)
    return np.array([coord.i, coord.j, coord.k], dtype=float)


def _check_psd(where: str, matrix: np.ndarray) -> None:
    sym = 0.5 * (matrix + matrix.T)
    scale = max(1e-300, float(np.abs(sym).max()))
    if np.linalg.eigvalsh(sym).min() < -1e-9 * scale:
        raise InputError(f"{where}: its mass matrix is not positive semi-definite")


def point_mass(
    path: Path, card, model, cd_axes: dict, wtmass: float, units: UnitSystem
) -> PointMass:
    """The :class:`PointMass` of a pyNastran mass card (SI, basic frame).

    Raises
    ------
    InputError
        One line: a two-grid scalar mass, a scalar point, a missing PMASS, an inertia that is
        not positive semi-definite, an unsupported mass card.
    """
    where = f"{path}: {card.type} {card.eid}"
    m_unit, l_unit = wtmass * units.mass, units.length
    if card.type == "CONM2":
        nid = card.nid
        x = np.asarray(card.X, dtype=float) * l_unit
        i11, i21, i22, i31, i32, i33 = (float(v) for v in card.I)
        local = np.array([[i11, -i21, -i31], [-i21, i22, -i32], [-i31, -i32, i33]])
        cid = card.cid if card.cid is not None else 0
        if cid == -1:  # X is the CG in the basic frame, the inertia in the basic frame
            cg, axes = x, np.eye(3)
        else:
            axes = frame_axes(model.coords[cid]) if cid else np.eye(3)
            grid = np.asarray(model.nodes[nid].get_position(), dtype=float) * l_unit
            cg = grid + axes.T @ x
        inertia = axes.T @ local @ axes * (m_unit * l_unit**2)
        _check_psd(where, inertia)
        mass = m_unit * float(card.mass)
        if mass < 0.0:
            raise InputError(f"{where}: M = {card.mass:g}: a mass must be >= 0")
        if mass == 0.0 and not np.any(inertia):
            raise InputError(f"{where}: no mass and no inertia: remove the card")
        return PointMass("CONM2", card.eid, nid, mass, cg, inertia)
    if card.type == "CONM1":
        nid = card.nid
        low = np.asarray(card.mass_matrix, dtype=float)
        full = np.tril(low) + np.tril(low, -1).T
        scale = np.ones((6, 6))
        scale[:3, :3], scale[3:, 3:] = m_unit, m_unit * l_unit**2
        scale[:3, 3:] = scale[3:, :3] = m_unit * l_unit
        cid = card.cid or 0
        if cid and cid not in model.coords:
            raise InputError(f"{where}: CID = {cid}: no such coordinate system")
        a = frame_axes(model.coords[cid]) if cid else np.eye(3)
        t = np.zeros((6, 6))
        t[:3, :3] = t[3:, 3:] = a.T
        matrix = t @ (full * scale) @ t.T
        _check_psd(where, matrix)
        pos = np.asarray(model.nodes[nid].get_position(), dtype=float) * l_unit
        return PointMass("CONM1", card.eid, nid, 0.0, pos, np.zeros((3, 3)), matrix=matrix)
    if card.type in ("CMASS1", "CMASS2"):
        nids = [n for n in card.node_ids if n]
        comps = [c for c in (card.c1, card.c2) if c]
        if len(nids) != 1 or len(comps) != 1:
            raise InputError(
                f"{where}: a scalar mass between two grids (or on a scalar point) is not "
                "supported; give one grid and one component"
            )
        if card.type == "CMASS1":
            prop = model.properties_mass.get(card.pid)
            if prop is None or prop.type != "PMASS":
                raise InputError(f"{where}: PMASS {card.pid} is missing")
            value = float(prop.mass)
        else:
            value = float(card.mass)
        if value < 0.0:
            raise InputError(f"{where}: M = {value:g}: a mass must be >= 0")
        comp, nid = int(comps[0]), nids[0]
        if not 1 <= comp <= 6:
            raise InputError(f"{where}: component {comp}: expected 1 to 6")
        if nid not in model.nodes:
            raise InputError(f"{where}: GRID {nid} is missing (a scalar point is not supported)")
        pos = np.asarray(model.nodes[nid].get_position(), dtype=float) * l_unit
        axis = cd_axes[nid][(comp - 1) % 3]
        if comp <= 3:
            return PointMass(card.type, card.eid, nid, m_unit * value, pos, np.zeros((3, 3)), axis)
        matrix = np.zeros((6, 6))
        matrix[3:, 3:] = m_unit * l_unit**2 * value * np.outer(axis, axis)
        return PointMass(card.type, card.eid, nid, 0.0, pos, np.zeros((3, 3)), matrix=matrix)
    raise InputError(f"{where}: mass card not supported (CONM2, CONM1, CMASS1, CMASS2)")


def check_mass_references(path: Path, model) -> None:
    """A CMASS1's PMASS, named before pyNastran's cross-referencing would (one line)."""
    for eid, card in sorted(model.masses.items()):
        if card.type == "CMASS1" and card.pid not in model.properties_mass:
            raise InputError(f"{path}: CMASS1 {eid}: PMASS {card.pid} is missing")
