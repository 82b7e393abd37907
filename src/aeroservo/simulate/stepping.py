"""The sampled loop marched sample by sample (the engine of :func:`~aeroservo.simulate.simulate`):
one matrix-vector product per sample for a linear law, the controller's protocol for a
nonlinear one, the actuator limits in between."""

from __future__ import annotations

import numpy as np

__all__ = ["march_loop"]


_BLOCK = 1024
"""Samples marched per block: the working array stays in cache whatever the duration."""


def _rows_times(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """``A @ B.T`` for a long ``A``, by ``np.einsum`` (no BLAS threads started: waking a
    multithreaded BLAS pool costs more than these products, and its spinning workers then slow
    the single-threaded loop that follows)."""
    return np.einsum("ij,kj->ik", A, B)


def _law_matrix(sp, law, s_idx):
    """One product per sample for a linear law (see :func:`_march`).

    Row k of the working array is ``[x, s, rB, q, u, d, aB, aD]``: plant state ``x``,
    controller state ``s``, ``rB = B m`` and ``q = C s + D m`` with ``m`` the measurement
    without disturbance feedthrough and noise, the input applied ``u``, the disturbance ``d``,
    and the controller's share of the feedthrough and noise ``aB = B a``, ``aD = D a``. The
    command is ``c = q + aD``; the law's state update ``s+ = A s + B (m + a) + L (u - c)`` and
    the next ``rB``, ``q`` are linear in the row.
    """
    Phi, Gu, Gd = sp.Phi, sp.Gu, sp.Gd
    n, m = Gu.shape
    nd = Gd.shape[1]
    A, B, C, D, L = law.A, law.B, law.C, law.D, law.L
    ns = A.shape[0]
    if law.state_feedback:
        Cm, Dm = np.eye(n), np.zeros((n, m))
    else:
        Cm, Dm = sp.C[s_idx], sp.Du[s_idx]
    widths = (n, ns, ns, m, m, nd, ns, m)
    starts = np.cumsum((0,) + widths)
    ix, i_s, irb, iq, iu, idd, iab, iad = (
        slice(int(a), int(b)) for a, b in zip(starts[:-1], starts[1:], strict=True)
    )
    M = np.zeros((starts[4], starts[-1]))
    # x+ = Phi x + Gu u + Gd d
    M[ix, ix], M[ix, iu], M[ix, idd] = Phi, Gu, Gd
    # s+ = (A) s + rB + aB + L u - L (q + aD)
    M[i_s, i_s], M[i_s, irb], M[i_s, iab] = A, np.eye(ns), np.eye(ns)
    M[i_s, iu], M[i_s, iq], M[i_s, iad] = L, -L, -L
    # m+ = Cm x+ + Dm u: rB+ = B m+, q+ = C s+ + D m+
    Mx = Cm @ M[ix]
    Mx[:, iu] += Dm
    M[irb] = B @ Mx
    M[iq] = C @ M[i_s] + D @ Mx
    return M, (ix, i_s, irb, iq, iu, idd, iab, iad), (Cm, B, C, D)


def _checked(c, m: int, controller) -> np.ndarray:
    """A protocol controller's command as ``m`` floats, or an InputError naming it."""
    try:
        out = np.asarray(c, dtype=float)
    except (TypeError, ValueError):
        out = None
    if out is None or out.shape not in ((m,), (m, 1), (1, m)):
        from ..errors import InputError, show_value

        raise InputError(
            f"controller {type(controller).__name__}: command returned {show_value(c)}; "
            f"expected {m} number(s), one per control"
        )
    return out.reshape(m)


def march_loop(
    sp, controller, law, x0, d, noise, s_idx, rec_idx, mag, rate_dt, delay, n_steps, rec,
    act=None,
):  # fmt: skip
    """The sampled loop: ``(outputs, states or None, applied, commands, status)`` per sample.

    A linear law (:class:`~aeroservo.design.law.LinearLaw`, delay included) is marched by one
    matrix-vector product per sample (:func:`_law_matrix`); the Python work per sample is the
    command ``c = q + aD`` and the limits. A nonlinear controller (MPC, a Python law) is
    called through its protocol, ``command(y, x)`` then ``update(y, u)`` with the input
    applied. With one control the limits are applied on Python floats (the same comparisons as
    ``np.maximum``/``np.minimum``, without the overhead of ufunc calls on one-element arrays).
    The recorded outputs are computed per block of samples from the states,
    ``y[k] = C x[k] + Du u[k-1] + Dd d[k]``. ``act``
    (:class:`~aeroservo.simulate.actuator_limits.ActuatorLimits`) corrects the state at the
    end of a sample in which an actuator output reaches its limits, and the measurements that
    follow from it.
    """
    Phi, Gu, Gd = sp.Phi, sp.Gu, sp.Gd
    n, m = Gu.shape
    S, Su = sp.C[s_idx], sp.Du[s_idx]
    a = _rows_times(d, sp.Dd[s_idx])  # disturbance feedthrough (and noise) the sensors see
    if noise is not None:
        a += noise
    if law is not None:
        M, sl, (Cm, B, C, D) = _law_matrix(sp, law, s_idx)
        ix, i_s, irb, iq, iu, idd, iab, iad = sl
        if law.state_feedback:  # it reads the state: no feedthrough, no sensor noise
            extra = np.hstack([d, np.zeros((n_steps + 1, B.shape[0] + m))])
        else:
            extra = np.hstack([d, _rows_times(a, B), _rows_times(a, D)])
        width, ihead = M.shape[1], iu.start
        row0 = np.zeros(width)
        row0[ix] = x0
        m0 = Cm @ x0
        row0[irb], row0[iq] = B @ m0, D @ m0
    else:
        p = S.shape[0]
        ix, irb = slice(0, n), slice(n, n + p)
        iu, idd = slice(n + p, n + p + m), slice(n + p + m, n + p + m + Gd.shape[1])
        M = np.zeros((n + p, idd.stop))
        M[:n, :n], M[:n, iu], M[:n, idd] = Phi, Gu, Gd
        M[n:, :n], M[n:, iu], M[n:, idd] = S @ Phi, S @ Gu + Su, S @ Gd
        extra, width, ihead = d, idd.stop, iu.start
        row0 = np.zeros(width)
        row0[ix], row0[irb] = x0, S @ x0
    C_rec = sp.C[rec_idx]
    W = None
    if act is not None:  # the head of a row as a function of its state: for the corrections
        W = np.zeros((ihead, n))
        W[ix] = np.eye(n)
        if law is not None:
            W[irb], W[iq] = B @ Cm, D @ Cm
        else:
            W[irb] = S
        clamp = act.clamp

    Y = np.empty((n_steps + 1, len(rec_idx)))
    X = np.empty((n_steps + 1, n)) if rec else None
    U = np.empty((n_steps + 1, m))
    Cmd = np.empty((n_steps + 1, m))
    status: list = []
    Z = np.empty((_BLOCK + 1, width))
    Z[0] = row0
    head = Z[:, :ihead]  # the part of each row the product writes
    i0 = iu.start
    dot, minimum, maximum = np.dot, np.minimum, np.maximum
    scalar = m == 1
    h, neg_mag = np.zeros(m), -mag
    hs, mg, r = 0.0, float(mag[0]), float(rate_dt[0])
    pending = np.zeros(m)
    if law is None:
        command, update, append = controller.command, controller.update, status.append
        last = hasattr(controller, "last_status")
    for k0 in range(0, n_steps + 1, _BLOCK):
        nb = min(_BLOCK, n_steps + 1 - k0)
        Z[:nb, idd.start :] = extra[k0 : k0 + nb]
        cmd = Cmd[k0 : k0 + nb]
        if law is not None and scalar:
            q0, a0 = iq.start, iad.start
            for j, (zk, zk1) in enumerate(zip(Z[:nb], head[1 : nb + 1], strict=True)):
                c = zk.item(q0) + zk.item(a0)
                lo, hi = hs - r, hs + r
                u = lo if c < lo else c
                u = hi if u > hi else u
                u = -mg if u < -mg else u
                u = mg if u > mg else u
                cmd[j, 0] = c
                zk[i0] = u
                dot(M, zk, zk1)
                hs = u
                if W is not None:
                    dx = clamp(zk[ix], (u,), zk1)
                    if dx is not None:
                        zk1 += W @ dx
        elif law is not None:
            for zk, zk1, ck in zip(Z[:nb], head[1 : nb + 1], cmd, strict=True):
                c = zk[iq] + zk[iad]
                u = minimum(maximum(c, h - rate_dt), h + rate_dt)
                u = minimum(maximum(u, neg_mag), mag)
                ck[:] = c
                zk[iu] = u
                dot(M, zk, zk1)
                h = u
                if W is not None:
                    dx = clamp(zk[ix], u, zk1)
                    if dx is not None:
                        zk1 += W @ dx
        else:
            for zk, zk1, ak, ck in zip(Z[:nb], head[1 : nb + 1], a[k0 : k0 + nb], cmd, strict=True):
                ys = zk[irb] + ak
                c = _checked(command(ys, zk[ix].copy()), m, controller)
                if delay:
                    c, pending = pending, np.asarray(c, dtype=float)
                u = minimum(maximum(c, h - rate_dt), h + rate_dt)
                u = minimum(maximum(u, neg_mag), mag)
                update(ys, u)
                if last:
                    st = getattr(controller, "last_status", None)
                    if st is not None:
                        append(st)
                ck[:] = c
                zk[iu] = u
                dot(M, zk, zk1)
                h = u
                if W is not None:
                    dx = clamp(zk[ix], u, zk1)
                    if dx is not None:
                        zk1 += W @ dx
        Y[k0 : k0 + nb] = _rows_times(Z[:nb, :n], C_rec)
        if X is not None:
            X[k0 : k0 + nb] = Z[:nb, :n]
        U[k0 : k0 + nb] = Z[:nb, iu]
        Z[0, :ihead] = Z[nb, :ihead]
    Y[1:] += _rows_times(U[:-1], sp.Du[rec_idx])
    Y += _rows_times(d, sp.Dd[rec_idx])
    return Y, X, U, Cmd, status
