"""Independent reference formulas for the doublet-lattice tests (``tests/test_dlm.py``).

Nothing here imports aeroservo: every function is written from its textbook source so that the
tests compare the code under test with an independent implementation.

* :func:`helmbold` - Helmbold's lift-curve slope as in USAF DATCOM section 4.1.3.2 (with the
  section lift slope 2 pi): ``CLa = 2 pi A / (2 + sqrt(A^2 (1 + tan^2 L_c/2) + 4))``.
* :func:`lifting_line_rectangular` - Prandtl's lifting line for an untwisted rectangular wing
  solved by Glauert's Fourier series (Glauert 1926; Anderson, Fundamentals of Aerodynamics,
  section 5.3.2; Katz and Plotkin, Low-Speed Aerodynamics, 2nd ed., section 8.1).
* :func:`horseshoe_vlm` - the classical vortex-lattice method with horseshoe vortices (bound
  vortex on each box's 1/4-chord line, trailing legs streamwise to infinity, collocation at
  the 3/4-chord point; Katz and Plotkin section 12.3, Bertin and Cummings, Aerodynamics for
  Engineers, section 7.4), Biot-Savart in closed form.
* :func:`theodorsen` and :func:`theodorsen_loads` - Theodorsen's (1935) function with Hankel
  functions and the lift and moment of a harmonically plunging and pitching flat plate
  (Bisplinghoff, Ashley and Halfman 1955, eq. 5-311/5-312; Fung 1955, section 6.9).
* :func:`roger_form` and :func:`minimum_state_form` - Roger's (1977) and Karpel's (1982)
  rational forms evaluated from their matrices.
"""

from __future__ import annotations

import numpy as np
from scipy.special import hankel2

__all__ = [
    "helmbold",
    "lifting_line_rectangular",
    "horseshoe_vlm",
    "theodorsen",
    "theodorsen_loads",
    "roger_form",
    "minimum_state_form",
]


def helmbold(aspect_ratio: float, sweep_half_chord: float = 0.0) -> float:
    """Lift-curve slope [1/rad] of a planform (DATCOM 4.1.3.2 with kappa = 1, M = 0)."""
    a = float(aspect_ratio)
    t2 = np.tan(sweep_half_chord) ** 2
    return 2.0 * np.pi * a / (2.0 + np.sqrt(a * a * (1.0 + t2) + 4.0))


def lifting_line_rectangular(aspect_ratio: float, n: int = 60, a0: float = 2.0 * np.pi) -> float:
    """Lift-curve slope [1/rad] of an untwisted rectangular wing by Prandtl's lifting line.

    Glauert's series ``Gamma(theta) = 2 B V sum A_n sin(n theta)`` (B the span, odd n for a
    symmetric load), collocated at ``n`` stations on a half span: the monoplane equation
    ``sum A_n sin(n theta) (mu n + sin theta) = mu alpha sin theta``, ``mu = a0 c / (4 B)``;
    ``CL = pi A A_1``.
    """
    odd = np.arange(1, 2 * n, 2)
    theta = (np.arange(1, n + 1) - 0.5) * (0.5 * np.pi) / n
    mu = a0 / (4.0 * aspect_ratio)  # c / B = 1 / A
    m = np.sin(np.outer(theta, odd)) * (mu * odd[None, :] + np.sin(theta)[:, None])
    coef = np.linalg.solve(m, mu * np.sin(theta))
    return float(np.pi * aspect_ratio * coef[0])


def _segment(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Velocity at points p (m, 3) of unit vortex segments a -> b (n, 3): (m, n, 3)."""
    r1 = p[:, None, :] - a[None, :, :]
    r2 = p[:, None, :] - b[None, :, :]
    r0 = (b - a)[None, :, :]
    cross = np.cross(r1, r2)
    c2 = np.einsum("mni,mni->mn", cross, cross)
    n1 = np.linalg.norm(r1, axis=2)
    n2 = np.linalg.norm(r2, axis=2)
    dot = np.einsum("mni,mni->mn", r0, r1 / n1[..., None] - r2 / n2[..., None])
    with np.errstate(divide="ignore", invalid="ignore"):
        f = np.where(c2 > 1e-24, dot / (4.0 * np.pi * c2), 0.0)
    return f[..., None] * cross


def _semi_infinite(p: np.ndarray, a: np.ndarray, e: np.ndarray) -> np.ndarray:
    """Velocity at p (m, 3) of unit vortices from a (n, 3) to infinity along unit e (3,)."""
    r = p[:, None, :] - a[None, :, :]
    cross = np.cross(np.broadcast_to(e, r.shape), r)
    c2 = np.einsum("mni,mni->mn", cross, cross)
    cos1 = (r @ e) / np.linalg.norm(r, axis=2)
    with np.errstate(divide="ignore", invalid="ignore"):
        f = np.where(c2 > 1e-24, (1.0 + cos1) / (4.0 * np.pi * c2), 0.0)
    return f[..., None] * cross


def horseshoe_vlm(corners: np.ndarray, symmetric: bool) -> np.ndarray:
    """Pressure-jump coefficients ``dcp`` of boxes at a unit angle of attack (1 rad), flat wing.

    Parameters
    ----------
    corners : ndarray (n, 4, 2)
        Box corners ``(x spanwise, y aft)`` in the order inboard LE, inboard TE, outboard TE,
        outboard LE; side edges streamwise.
    symmetric : bool
        Add the mirror image in the plane x = 0 (same circulation).

    Returns
    -------
    ndarray (n,)
        ``dcp = L / (q A)`` per box, with the Kutta-Joukowski lift ``rho V Gamma dx`` of its bound
        vortex (dx its spanwise extent).
    """
    c = np.asarray(corners, dtype=float)
    n = len(c)

    # axes: X aft (the stream), Y spanwise, Z up (right-handed); flow V = 1 along +X
    def pt(xy):
        return np.column_stack([xy[:, 1], xy[:, 0], np.zeros(len(xy))])

    a = pt(c[:, 0] + 0.25 * (c[:, 1] - c[:, 0]))  # inboard end of the bound vortex
    b = pt(c[:, 3] + 0.25 * (c[:, 2] - c[:, 3]))  # outboard end
    inner = c[:, 0] + 0.75 * (c[:, 1] - c[:, 0])
    outer = c[:, 3] + 0.75 * (c[:, 2] - c[:, 3])
    p = pt(0.5 * (inner + outer))  # collocation points
    e = np.array([1.0, 0.0, 0.0])

    def horseshoes(a, b):
        return _segment(p, a, b) + _semi_infinite(p, b, e) - _semi_infinite(p, a, e)

    vel = horseshoes(a, b)
    if symmetric:
        mirror = np.array([1.0, -1.0, 1.0])
        # the image runs from the image of b (now leftmost) to the image of a
        vel = vel + horseshoes(b * mirror, a * mirror)
    k = vel[..., 2]  # normal velocity per unit circulation
    gamma = np.linalg.solve(k, -np.ones(n))  # w_induced + V alpha = 0
    dx = b[:, 1] - a[:, 1]
    chord = 0.5 * ((c[:, 1, 1] - c[:, 0, 1]) + (c[:, 2, 1] - c[:, 3, 1]))
    area = chord * (c[:, 3, 0] - c[:, 0, 0])
    return 2.0 * gamma * dx / area  # rho V Gamma dx / (rho V^2 / 2 A)


def theodorsen(k: np.ndarray) -> np.ndarray:
    """Theodorsen's function ``C(k) = H1(k) / (H1(k) + i H0(k))`` (Hankel functions of the second
    kind), k > 0."""
    k = np.asarray(k, dtype=float)
    h1, h0 = hankel2(1, k), hankel2(0, k)
    return h1 / (h1 + 1j * h0)


def theodorsen_loads(k: float, a: float = 0.0) -> dict:
    """Complex lift (up) and pitching moment (nose up, about the axis at ``a``) per unit span and
    unit dynamic pressure, for a flat plate of semichord 1 in a stream of speed 1, harmonic in
    time with reduced frequency k (``omega = k``).

    Theodorsen's loads with plunge h positive down and pitch alpha nose up about ``x = a b``:

    ``L = pi rho b^2 (h'' + V alpha' - b a alpha'') + 2 pi rho V b C (h' + V alpha + b (1/2 - a)
    alpha')``,
    ``M = pi rho b^2 (b a h'' - V b (1/2 - a) alpha' - b^2 (1/8 + a^2) alpha'')
    + 2 pi rho V b^2 (a + 1/2) C (h' + V alpha + b (1/2 - a) alpha')``.

    Returns ``{"L_h", "M_h", "L_alpha", "M_alpha"}``: loads of a unit ``h / b`` and a unit
    ``alpha`` [rad], divided by ``q = rho V^2 / 2`` (rho = V = b = 1).
    """
    rho = v = b = 1.0
    q = 0.5 * rho * v * v
    w = k * v / b
    ck = complex(theodorsen(np.array([k]))[0])
    iw, w2 = 1j * w, -(w * w)
    # unit plunge h = b (down)
    hd, hdd = iw * b, w2 * b
    lh = np.pi * rho * b**2 * hdd + 2 * np.pi * rho * v * b * ck * hd
    mh = np.pi * rho * b**2 * (b * a * hdd) + 2 * np.pi * rho * v * b**2 * (a + 0.5) * ck * hd
    # unit pitch
    ad, add = iw, w2
    q3 = v * 1.0 + b * (0.5 - a) * ad  # 3/4-chord normalwash (without the plunge)
    la = np.pi * rho * b**2 * (v * ad - b * a * add) + 2 * np.pi * rho * v * b * ck * q3
    ma = (
        np.pi * rho * b**2 * (-v * b * (0.5 - a) * ad - b**2 * (0.125 + a * a) * add)
        + 2 * np.pi * rho * v * b**2 * (a + 0.5) * ck * q3
    )
    return {"L_h": lh / q, "M_h": mh / q, "L_alpha": la / q, "M_alpha": ma / q}


def roger_form(k, a0, a1, a2, roots, lags) -> np.ndarray:
    """``A0 + p A1 + p^2 A2 + sum_j p / (p + g_j) B_j`` at ``p = i k``, (n_k, rows, cols)."""
    out = []
    for kk in np.atleast_1d(k):
        p = 1j * kk
        q = a0 + p * a1 + p * p * a2
        for g, bj in zip(roots, lags, strict=True):
            q = q + p / (p + g) * bj
        out.append(q)
    return np.array(out)


def minimum_state_form(k, a0, a1, a2, roots, d, e) -> np.ndarray:
    """``A0 + p A1 + p^2 A2 + D (p I - R)^-1 E p`` with ``R = -diag(roots)``, at ``p = i k``."""
    out = []
    r = -np.diag(roots)
    n = len(roots)
    for kk in np.atleast_1d(k):
        p = 1j * kk
        out.append(a0 + p * a1 + p * p * a2 + d @ np.linalg.solve(p * np.eye(n) - r, e) * p)
    return np.array(out)
