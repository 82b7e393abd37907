"""Near-critical branches: a damping ratio that comes close to zero without crossing it.

A branch whose damping ratio falls to a local minimum just above zero is one modelling
assumption away from flutter: a different aerodynamic approximation (the Wagner fit at that
reduced frequency), a little less structural damping, or a small change of the design can
make it cross. Flutter engineers read such a "hump" on the V-g plot and report it next to the
flutter speed; :func:`near_critical` finds them with the same full-model continuation as the
crossings (:mod:`aeroservo.stability.crossings`).

Definition used here: an interior local minimum of the damping ratio
``zeta = -Re(lambda)/|lambda|`` of an oscillatory branch with ``0 < zeta_min <= threshold``
(default :data:`NEAR_ZETA` = 1e-3). It is reported with the speed range where ``zeta <=
threshold``, the speed, frequency and damping ratio at the minimum.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .branches import is_complex
from .brent import brentq
from .crossings import HUMP_ZETA, VerificationError, Verifier
from .result import FlutterResult

__all__ = ["DISCREPANCY", "NEAR_ZETA", "NearCritical", "method_discrepancy", "near_critical"]

NEAR_ZETA = 1e-3
"""Damping ratio [-] below which a local minimum of a stable branch is near-critical."""


@dataclass(frozen=True)
class NearCritical:
    """A branch whose damping ratio has a local minimum just above zero.

    Attributes
    ----------
    speed : float
        Airspeed of the minimum [m/s].
    frequency : float
        Frequency there [Hz].
    damping_ratio : float
        The minimum damping ratio -Re(lambda)/|lambda| [-] (positive: still stable).
    speed_range : tuple of float
        Speeds between which the damping ratio is below ``threshold`` [m/s].
    mode : int
        Index of the branch.
    threshold : float
        The damping ratio that defines "near" [-].
    """

    speed: float
    frequency: float
    damping_ratio: float
    speed_range: tuple[float, float]
    mode: int
    threshold: float = NEAR_ZETA


def near_critical(
    ver: Verifier,
    rtol: float = 1e-7,
    top: float = np.inf,
    band_top: float = np.inf,
    threshold: float = NEAR_ZETA,
) -> list[NearCritical]:
    """Every near-critical minimum of the verified branches below ``top``.

    Parameters
    ----------
    ver : Verifier
        The full-model view of the branches (as left by the crossing search).
    rtol : float
        Relative tolerance on the speeds [-].
    top : float
        Speed up to which the search is complete [m/s].
    band_top : float
        Top of the modal model's band [rad/s] (branches above it are not decided here).
    threshold : float
        Largest minimum damping ratio reported [-].

    Returns
    -------
    list of NearCritical
        In increasing speed.
    """
    lam = ver.br.eigenvalues
    V = ver.br.speeds
    osc = is_complex(lam) & (np.abs(lam) <= band_top) & (top >= V)[:, None]
    z = -lam.real / np.maximum(np.abs(lam), 1e-300)
    # screened on the modal values (interior minima, V = 0 and its neighbour excluded),
    # decided on the full model
    n = int(np.searchsorted(V, top, side="right"))  # grid points inside the searched range
    cand = np.zeros(lam.shape, dtype=bool)
    cand[2 : n - 1] = (
        osc[1 : n - 2] & osc[2 : n - 1] & osc[3:n]
        & (z[2 : n - 1] <= z[1 : n - 2]) & (z[2 : n - 1] <= z[3:n])
    )  # fmt: skip
    # the last searched point too: a minimum can lie inside the last interval
    cand[n - 1] = osc[n - 2] & osc[n - 1] & (z[n - 1] <= z[n - 2]) if n >= 3 else False
    cand &= np.abs(z) < HUMP_ZETA
    out = []
    for k, j in np.argwhere(cand).tolist():
        last = k == n - 1
        try:
            zk = [_zeta(ver.at(kk, j)) for kk in (k - 1, k) + (() if last else (k + 1,))]
            if zk[1] <= zk[0] and zk[1] <= zk[-1] and 0.0 < zk[1] < HUMP_ZETA:
                out += _refine(ver, j, k, zk[1], rtol, threshold, last, top)
        except VerificationError:
            continue  # not decided here; the search itself reports such a branch
    return sorted(out, key=lambda n: n.speed)


def _refine(
    ver: Verifier, j: int, k: int, z_k: float, rtol: float, thr: float, last: bool, top: float
) -> list:
    """The minimum of zeta around grid point k on the full model, if it is near-critical (at
    the last searched point ``last``: only a minimum inside the last interval, not one at the
    end of the search, where zeta may go on falling)."""
    from scipy.optimize import minimize_scalar

    V = ver.br.speeds

    def zeta(v: float) -> float:
        return _zeta(ver.follow(j, k - 1 if v < V[k] else k, v))

    hi = V[k] if last else V[k + 1]
    sol = minimize_scalar(
        zeta, bounds=(V[k - 1], hi), method="bounded", options={"xatol": rtol * V[k]}
    )
    v0, z0 = float(sol.x), float(sol.fun)
    if last and v0 > V[k] - 10 * rtol * V[k]:
        return []  # still falling at the end of the search: not a minimum
    if not last and z_k < z0:
        v0, z0 = float(V[k]), z_k
    if not 0.0 < z0 <= thr:
        return []  # a crossing (found as one) or not near
    lo, hi = _edge(ver, j, v0, -1, thr, rtol), _edge(ver, j, v0, +1, thr, rtol)
    f0 = abs(ver.follow(j, k - 1 if v0 < V[k] else k, v0).imag) / (2 * np.pi)
    return [NearCritical(v0, f0, z0, (lo, min(hi, top)), j, thr)]


def _edge(ver: Verifier, j: int, v0: float, step: int, thr: float, rtol: float) -> float:
    """Where zeta rises back through ``thr`` going from v0 in direction ``step`` (+1 or -1),
    grid interval by grid interval (the grid's end if it never does)."""
    V = ver.br.speeds
    i = int(np.clip(np.searchsorted(V, v0, side="right") - 1, 0, V.size - 2))
    a = v0
    while 0 <= i <= V.size - 2:
        b = float(V[i + 1] if step > 0 else V[i])

        def f(v: float, i=i) -> float:
            return _zeta(ver.follow(j, i, v)) - thr

        if f(b) >= 0:
            lo, hi = min(a, b), max(a, b)
            return float(brentq(f, lo, hi, xtol=rtol * hi, rtol=1e-15))
        a, i = b, i + step
    return float(V[-1] if step > 0 else V[0])


def _zeta(lam: complex) -> float:
    return float(-lam.real / max(abs(lam), 1e-300))


DISCREPANCY = 0.03
"""Relative difference of the time-domain and p-k flutter speeds [-] above which
:func:`method_discrepancy` warns."""


def method_discrepancy(
    td: FlutterResult, pk: FlutterResult, semichord: float, wagner: str = ""
) -> str | None:
    """One warning line when the time-domain and p-k (exact C(k)) flutter speeds differ by
    more than :data:`DISCREPANCY`, or one finds flutter where the other searched and found none.

    Parameters
    ----------
    td, pk : FlutterResult
        The time-domain boundary (Wagner approximation) and the p-k one (exact C(k)).
    semichord : float
        Reference semichord b of the reduced frequency k = omega b / V [m].
    wagner : str
        Name of the Wagner approximation of ``td``.

    Returns
    -------
    str or None
    """
    vt, vp = td.flutter_speed, pk.flutter_speed
    if vt is None and vp is None:
        return None
    if vt is not None and vp is not None:
        if abs(vt - vp) <= DISCREPANCY * min(vt, vp):
            return None
    elif (vt is None and vp > td.searched_up_to) or (vp is None and vt > pk.searched_up_to):
        return None

    def text(r: FlutterResult) -> str:
        if r.flutter_speed is None:
            return f"no flutter below {r.searched_up_to:.4g} m/s"
        return f"flutter {r.flutter_speed:.4g} m/s ({r.flutter_frequency:.4g} Hz)"

    lines = f"time-domain {text(td)} and p-k (exact C(k)) {text(pk)} differ"
    if vt is not None and vp is not None:
        lines += f" by {100 * abs(vt - vp) / min(vt, vp):.3g} %"
    ks = [
        2 * np.pi * r.flutter_frequency * semichord / r.flutter_speed
        for r in (td, pk)
        if r.flutter_speed is not None and r.flutter_speed > 0
    ]
    why = f"the Wagner approximation{f' ({wagner!r})' if wagner else ''} at the flutter reduced "
    why += f"frequency (k = omega b / V = {', '.join(f'{k:.3g}' for k in ks)})"
    near = list(td.near_critical)
    if near:
        why += ", or a near-critical branch that one method puts just above zero damping and "
        why += (
            "the other just below ("
            + "; ".join(
                f"{n.frequency:.4g} Hz, damping ratio {n.damping_ratio:.1g} at "
                f"{n.speed_range[0]:.4g} .. {n.speed_range[1]:.4g} m/s"
                for n in near
            )
            + ")"
        )
    else:
        why += ", or a branch close to zero damping over a range of speeds"
    return f"{lines}: usually {why}; compare the V-g plots (--pk --plot)"
