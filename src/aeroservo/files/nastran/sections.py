"""Section properties of a Nastran beam property card (PBAR, PBARL, PBEAM) with its MAT1.

Everything is in the element's own axes: ``I1`` is the area moment for bending in plane 1
(the plane of the element axis and its orientation vector, deflection along the element y),
``I2`` for bending in plane 2; ``m1``, ``m2`` the element y and z of the non-structural mass's
centre of gravity (PBEAM). Which of ``I1``, ``I2`` is the wing's flapwise one is decided by the
element's orientation (``files/nastran/beam.py``). Formulas of the PBARL shapes in
``docs/nastran.md``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...errors import InputError
from .units import UnitSystem

__all__ = ["Section", "section_of", "pbarl_section", "tapered", "PBARL_TYPES"]

PBARL_TYPES = ("BAR", "ROD", "TUBE", "BOX")
"""PBARL cross-section types whose area, moments and torsion constant are computed here."""


@dataclass(frozen=True)
class Section:
    """One property card's section, material and mass terms (SI, WTMASS applied).

    ``nsi`` is the non-structural mass's pitch inertia per length about its own CG [kg m];
    ``label`` names the cards (e.g. ``"PBAR 1, MAT1 1"``).
    """

    label: str
    pid: int
    E: float
    G: float
    rho: float
    A: float
    I1: float
    I2: float
    J: float
    nsm: float
    nsi: float = 0.0
    m1: float = 0.0
    m2: float = 0.0
    gives_inertia: bool = False  # PBEAM: the section's torsional inertia is part of the card


def pbarl_section(kind: str, dim: list[float]) -> tuple[float, float, float, float]:
    """Area, I1, I2 and J of a PBARL shape (``DIM2`` along the element y, ``DIM1`` along z).

    Raises
    ------
    ValueError
        An unsupported type or inconsistent dimensions (the caller names the card).
    """
    d = [float(x) for x in dim]
    if kind == "BAR":
        b, h = d  # width (element z), height (element y)
        a_, t_ = max(b, h), min(b, h)
        j = a_ * t_**3 * (1.0 / 3.0 - 0.21 * t_ / a_ * (1.0 - t_**4 / (12.0 * a_**4)))
        return b * h, b * h**3 / 12.0, h * b**3 / 12.0, j
    if kind == "ROD":
        (r,) = d
        return math.pi * r**2, math.pi * r**4 / 4.0, math.pi * r**4 / 4.0, math.pi * r**4 / 2.0
    if kind == "TUBE":
        ro, ri = d
        if not ro > ri >= 0.0:
            raise ValueError(f"TUBE needs DIM1 > DIM2 >= 0 (outer and inner radius), got {d}")
        i = math.pi * (ro**4 - ri**4) / 4.0
        return math.pi * (ro**2 - ri**2), i, i, 2.0 * i
    if kind == "BOX":
        b, h, t1, t2 = d  # width, height, top/bottom and side wall thicknesses
        if not (b > 2 * t2 and h > 2 * t1):
            raise ValueError(f"BOX needs DIM1 > 2 DIM4 and DIM2 > 2 DIM3, got {d}")
        bi, hi = b - 2 * t2, h - 2 * t1
        bm, hm = b - t2, h - t1  # wall centre lines: Bredt's thin-walled torsion constant
        j = 2.0 * t1 * t2 * bm**2 * hm**2 / (bm * t2 + hm * t1)
        return b * h - bi * hi, (b * h**3 - bi * hi**3) / 12.0, (h * b**3 - hi * bi**3) / 12.0, j
    raise ValueError(f"TYPE = {kind!r} is not supported ({', '.join(PBARL_TYPES)} are)")


def _mean(prop, values) -> float:
    """A PBEAM/PBEAML value averaged over the element's length, linear between its stations
    (XXB; the end values held outside them): the mid-length value when it has two."""
    arr = np.atleast_1d(np.asarray(values, dtype=float))
    xxb = np.atleast_1d(np.asarray(getattr(prop, "xxb", [0.0]), dtype=float))
    if arr.size < 2 or xxb.size != arr.size:
        return float(arr[0]) if arr.size else 0.0
    order = np.argsort(xxb)
    x, y = xxb[order], arr[order]
    x, y = np.concatenate([[0.0], x, [1.0]]), np.concatenate([[y[0]], y, [y[-1]]])
    return float(np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(x)))


def tapered(prop) -> bool:
    """Whether a PBEAM/PBEAML's section varies along the element."""
    for key in ("A", "i1", "i2", "j", "dim"):
        arr = getattr(prop, key, None)
        if arr is not None and len(arr) > 1:
            arr = np.asarray(arr, dtype=float)
            if not np.allclose(arr, arr[0], rtol=1e-12, atol=0.0):
                return True
    return False


def section_of(path: Path, prop, mat, wtmass: float, units: UnitSystem) -> Section:
    """The :class:`Section` of a pyNastran property card and its MAT1, in SI.

    A PBEAM or PBEAML with stations (a tapered element) gives each value averaged over the
    element, linear between the stations (its mid-length value with two stations).
    """
    where = f"{path}: {prop.type} {prop.pid}"
    label = f"{prop.type} {prop.pid}, MAT1 {mat.mid}"
    E, G = float(mat.e or 0.0) * units.stress, float(mat.g or 0.0) * units.stress
    if not E > 0.0 or not G > 0.0:
        raise InputError(f"{path}: MAT1 {mat.mid}: E = {E:g}, G = {G:g}: both must be > 0 [Pa]")
    rho = wtmass * float(mat.rho or 0.0) * units.density
    L, m_len = units.length, wtmass * units.mass / units.length  # NSM [mass/length]
    if prop.type in ("PBAR", "PBEAM"):
        vals = {k: _mean(prop, getattr(prop, k)) for k in ("A", "i1", "i2", "i12", "j")}
        if vals["i12"] != 0.0:
            raise InputError(
                f"{where}: I12 = {vals['i12']:g}: a section whose principal axes are not the "
                "element's couples flapwise and in-plane bending, which is not modelled"
            )
    if prop.type == "PBAR":
        vals = (vals["A"] * L**2, vals["i1"] * L**4, vals["i2"] * L**4, vals["j"] * L**4)
        sec = Section(label, prop.pid, E, G, rho, *vals, m_len * float(prop.nsm or 0.0))
    elif prop.type in ("PBARL", "PBEAML"):
        kind = getattr(prop, "beam_type", None) or getattr(prop, "Type", None)
        dims = prop.dim if prop.type == "PBARL" else np.asarray(prop.dim, dtype=float)
        if prop.type == "PBEAML":
            dims = [_mean(prop, dims[:, k]) for k in range(dims.shape[1])]
        try:
            a_, i1, i2, j_ = pbarl_section(str(kind), list(dims))
        except ValueError as exc:
            raise InputError(f"{where}: {exc}; or give A, I1, I2, J on a PBAR") from None
        nsm = _mean(prop, prop.nsm) if prop.type == "PBEAML" else float(prop.nsm or 0.0)
        vals = (a_ * L**2, i1 * L**4, i2 * L**4, j_ * L**4)
        sec = Section(f"{label} ({kind})", prop.pid, E, G, rho, *vals, m_len * nsm)
    elif prop.type == "PBEAM":
        for key in ("n1a", "n2a", "n1b", "n2b"):
            if float(getattr(prop, key, 0.0) or 0.0) != 0.0:
                raise InputError(
                    f"{where}: {key.upper()} = {getattr(prop, key):g}: a neutral axis offset "
                    "from the shear centre is not modelled"
                )
        ends = {}
        for key in ("m1", "m2", "nsi"):
            a_ = float(getattr(prop, key + "a", 0.0) or 0.0)
            b_ = getattr(prop, key + "b", None)
            ends[key] = 0.5 * (a_ + (a_ if b_ is None else float(b_)))
        sec = Section(
            label,
            prop.pid,
            E,
            G,
            rho,
            vals["A"] * L**2,
            vals["i1"] * L**4,
            vals["i2"] * L**4,
            vals["j"] * L**4,
            m_len * _mean(prop, getattr(prop, "nsm", [0.0])),
            nsi=m_len * L**2 * ends["nsi"],
            m1=ends["m1"] * L,
            m2=ends["m2"] * L,
            gives_inertia=True,
        )
    else:
        raise InputError(f"{where}: property type not supported (PBAR, PBARL, PBEAM, PBEAML)")
    for name in ("A", "I1", "I2", "J"):
        value = getattr(sec, name)
        if not (math.isfinite(value) and value >= 0.0):
            raise InputError(f"{where}: {name} = {value:g}: must be >= 0")
    if sec.J == 0.0:
        raise InputError(f"{where}: J = 0: no torsional stiffness (give J)")
    if sec.nsm < 0.0:
        raise InputError(f"{where}: NSM = {sec.nsm:g}: must be >= 0 [kg/m]")
    return sec
