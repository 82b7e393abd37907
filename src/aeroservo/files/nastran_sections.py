"""Section properties of a Nastran beam property card (PBAR, PBARL, PBEAM) with its MAT1.

Everything is in the element's own axes: ``I1`` is the area moment for bending in plane 1
(the plane of the element axis and its orientation vector, deflection along the element y),
``I2`` for bending in plane 2; ``m1``, ``m2`` the element y and z of the non-structural mass's
centre of gravity (PBEAM). Which of ``I1``, ``I2`` is the wing's flapwise one is decided by the
element's orientation (``files/nastran_beam.py``). Formulas of the PBARL shapes in
``docs/nastran.md``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import InputError

__all__ = ["Section", "section_of", "pbarl_section", "PBARL_TYPES"]

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


def _constant(where: str, name: str, values) -> float:
    """One value of a PBEAM field that must not vary along the element."""
    arr = np.atleast_1d(np.asarray(values, dtype=float))
    if arr.size and not np.allclose(arr, arr[0], rtol=1e-12, atol=0.0):
        raise InputError(
            f"{where}: {name} varies along the element ({list(arr)}): tapered beams are not "
            "supported; split the element or give one section"
        )
    return float(arr[0]) if arr.size else 0.0


def section_of(path: Path, prop, mat, wtmass: float) -> Section:
    """The :class:`Section` of a pyNastran property card and its MAT1."""
    where = f"{path}: {prop.type} {prop.pid}"
    label = f"{prop.type} {prop.pid}, MAT1 {mat.mid}"
    E, G = float(mat.e or 0.0), float(mat.g or 0.0)
    if not E > 0.0 or not G > 0.0:
        raise InputError(f"{path}: MAT1 {mat.mid}: E = {E:g}, G = {G:g}: both must be > 0 [Pa]")
    rho = wtmass * float(mat.rho or 0.0)
    if prop.type == "PBAR":
        if float(prop.i12 or 0.0) != 0.0:
            raise InputError(
                f"{where}: I12 = {prop.i12:g}: a section whose principal axes are not the "
                "element's couples flapwise and in-plane bending, which is not modelled"
            )
        vals = (float(prop.A), float(prop.i1), float(prop.i2), float(prop.j))
        nsm = wtmass * float(prop.nsm or 0.0)
        sec = Section(label, prop.pid, E, G, rho, *vals, nsm)
    elif prop.type == "PBARL":
        kind = getattr(prop, "beam_type", None) or getattr(prop, "Type", None)
        try:
            vals = pbarl_section(str(kind), list(prop.dim))
        except ValueError as exc:
            raise InputError(f"{where}: {exc}; or give A, I1, I2, J on a PBAR") from None
        nsm = wtmass * float(prop.nsm or 0.0)
        sec = Section(f"{label} ({kind})", prop.pid, E, G, rho, *vals, nsm)
    elif prop.type == "PBEAM":
        c = {k: _constant(where, k, getattr(prop, k)) for k in ("A", "i1", "i2", "i12", "j")}
        c["nsm"] = _constant(where, "NSM", getattr(prop, "nsm", [0.0]))
        if c["i12"] != 0.0:
            raise InputError(
                f"{where}: I12 = {c['i12']:g}: a section whose principal axes are not the "
                "element's couples flapwise and in-plane bending, which is not modelled"
            )
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
            ends[key] = _constant(where, key.upper(), [a_, a_ if b_ is None else float(b_)])
        sec = Section(
            label,
            prop.pid,
            E,
            G,
            rho,
            c["A"],
            c["i1"],
            c["i2"],
            c["j"],
            wtmass * c["nsm"],
            nsi=wtmass * ends["nsi"],
            m1=ends["m1"],
            m2=ends["m2"],
            gives_inertia=True,
        )
    else:
        raise InputError(f"{where}: property type not supported (PBAR, PBARL, PBEAM)")
    for name in ("A", "I1", "I2", "J"):
        value = getattr(sec, name)
        if not (math.isfinite(value) and value >= 0.0):
            raise InputError(f"{where}: {name} = {value:g}: must be >= 0")
    if sec.J == 0.0:
        raise InputError(f"{where}: J = 0: no torsional stiffness (give J)")
    if sec.nsm < 0.0:
        raise InputError(f"{where}: NSM = {sec.nsm:g}: must be >= 0 [kg/m]")
    return sec
