"""Frequency responses to a continuous gust and the quadrature of their moments, open loop and
at the sample instants of a loop closed by a sampled linear controller.

The loop is the one :func:`aeroservo.simulate.simulate` marches (:mod:`aeroservo.design.
sampled_loop`, no active limit): for a gust ``e^{j w t}``, ``z = e^{j w T}``, the plant state at
the samples is ``X = x_ol + (zI - Phi)^-1 Gu U``, ``x_ol = (jwI - A)^-1 Bw`` the continuous
response and ``Phi, Gu`` the zero-order hold of the commands; the controller reads
``M = Cm X + Dmw + Dmu U / z`` (sensors see the command held over the last interval; the plant
state for state feedback) and commands ``U = K(z) M``. Every output is ``H_s(w) = Hy(w) +
T(z) v(w)``: ``[Hy, v]`` smooth (``v = Pi M_ol``, what the controller's state update and
command take in) and ``T(z) = Py (I - Kc Pq)^-1 Kc`` periodic in ``w`` (period ``P = 2pi/T``).

Quadrature of ``|H_s|^2 Phi_t`` (the cross terms and ``w^2 |H_s|^2 Phi_t`` alike):

* ``[0, w_a]``: adaptive Gauss-Legendre on panels ending at the open-loop poles' frequencies
  and at the aliases ``theta_i + k P`` of the closed-loop poles ``log(z_i)/T`` (+- multiples of
  their decay rates); ``w_a`` is the first multiple of P above 20 P, ``rho + 10 P`` and
  ``1.5 rho`` (``rho`` the spectral radius of A), so that beyond it ``[Hy, v]`` and the
  spectrum vary little over a period;
* ``[w_a, inf)``: the integral of the period averages of ``T`` and ``T (x) conj T`` (to
  ``omega_hi`` by quadrature, beyond in closed form: the Markov expansion of ``[Hy, v]`` to
  ``w^-4`` times the spectrum's asymptote ``c w^-p``), plus the Euler-Maclaurin terms of the
  first three Bernoulli moments of the period starting at ``w_a`` (with the smooth factor and
  its first two derivatives there, by central differences). The neglected term is the fourth:
  relative to that part of the integral (a part below 1e-2 of ``N0^2``, far less of
  ``A_bar^2``) of order ``(r+3)! / (2 pi d / P)^4``, ``d`` the distance to the nearest
  singularity of the smooth factor (``d >= 10 P``) and ``r`` its decay order: below 1e-6.
"""

from __future__ import annotations

import math

import numpy as np

_GL_X, _GL_W = np.polynomial.legendre.leggauss(12)
_CHUNK = 4_000_000
"""Floats evaluated at once by the panel quadrature."""


class ModalResponse:
    """``C (j w - A)^-1 b + d`` of selected rows to one input, by the eigendecomposition of A
    (checked against a direct solve; a direct solve per frequency when the check fails)."""

    def __init__(self, a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray) -> None:
        self.a, self.b, self.c, self.d = a, b, c, d
        self.lam, self.vecs = np.linalg.eig(a)
        self.bt = np.linalg.solve(self.vecs, b)
        self.ct = c @ self.vecs
        probe = np.unique(np.abs(self.lam.imag[self.lam.imag > 0]))[:20]
        probe = np.concatenate([probe, [1.0, float(np.max(np.abs(self.lam)))]])
        ref = np.array([self._direct(w) for w in probe])
        self.modal_ok = _close(self._modal(probe), ref)

    def _direct(self, w: float) -> np.ndarray:
        n = self.a.shape[0]
        return self.c @ np.linalg.solve(1j * w * np.eye(n) - self.a, self.b) + self.d

    def _modal(self, w: np.ndarray) -> np.ndarray:
        r = self.bt[None, :] / (1j * w[:, None] - self.lam[None, :])
        return r @ self.ct.T + self.d[None, :]

    def __call__(self, w: np.ndarray) -> np.ndarray:
        if self.modal_ok:
            return self._modal(w)
        return np.array([self._direct(x) for x in w]).reshape(w.size, -1)

    def markov(self, k: int) -> np.ndarray:
        """``[d, C b, C A b, ...]``: the first ``k`` coefficients of ``(j w)^-i``, (k, rows)."""
        out, v = [self.d], self.b.copy()
        for _ in range(k - 1):
            out.append(self.c @ v)
            v = self.a @ v
        return np.array(out, dtype=float)


def _close(got, ref, tol=1e-8) -> bool:
    scale = np.max(np.abs(ref), axis=0) + 1e-300
    return bool(np.all(np.abs(got - ref) <= tol * scale))


# -- quadrature --------------------------------------------------------------------------------


def _panels(func, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Gauss-Legendre integrals of the columns of ``func(w)`` on panels, (panels, columns);
    in ``ln w`` on panels with ``lo > 0``."""
    log = lo > 0
    a = np.where(log, np.log(np.where(log, lo, 1.0)), lo)
    b = np.where(log, np.log(np.where(log, hi, 1.0)), hi)
    mid, half = (a + b) / 2, (b - a) / 2
    u = mid[:, None] + half[:, None] * _GL_X[None, :]
    w = np.where(log[:, None], np.exp(u), u)
    jac = half[:, None] * _GL_W[None, :] * np.where(log[:, None], w, 1.0)
    out, i, step = [], 0, 64
    while i < lo.size:
        f = func(w[i : i + step].ravel())
        f = f.reshape(w[i : i + step].shape + (f.shape[1],))
        out.append(np.einsum("pgk,pg->pk", f, jac[i : i + step]))
        i += step
        step = max(1, _CHUNK // (12 * f.shape[-1]))
    return np.concatenate(out)


def adaptive(func, pts: np.ndarray, rtol: float, check, extra) -> np.ndarray:
    """Integrals of the columns of ``func(w)`` (real, ``(n_w, K)``) over ``[pts[0], pts[-1]]``.

    12-point Gauss-Legendre on the panels between ``pts``, a panel split while it and its two
    halves differ by more than ``rtol / 10`` of the total of a ``check`` column (``extra``, per
    column, is added to the total: a tail integrated elsewhere).
    """
    lo, hi = pts[:-1], pts[1:]
    coarse = _panels(func, lo, hi)
    done = np.zeros(coarse.shape[1])
    for _ in range(40):
        log = lo > 0
        mid = np.where(log, np.sqrt(lo * np.where(log, hi, 1.0)), (lo + hi) / 2)
        left, right = _panels(func, lo, mid), _panels(func, mid, hi)
        fine = left + right
        tot = np.abs(done + fine.sum(axis=0) + extra)[check] + 1e-300
        err = np.max(np.abs(fine - coarse)[:, check] / tot, axis=1)
        bad = err > 0.1 * rtol
        done += fine[~bad].sum(axis=0)
        if not bad.any():
            return done
        lo = np.concatenate([lo[bad], mid[bad]])
        hi = np.concatenate([mid[bad], hi[bad]])
        coarse = np.concatenate([left[bad], right[bad]])
    raise RuntimeError("turbulence quadrature did not converge in 40 refinements")


def breakpoints(lam: np.ndarray, speed: float, scale: float, w_hi: float) -> np.ndarray:
    """Panel ends from 0 to ``w_hi``: a log grid (8 per decade) and each pole's damped
    frequency +- (1/2 to 16) x its decay rate."""
    w_lo = 1e-4 * min(speed / (1.339 * scale), np.min(np.abs(lam)))
    decades = math.log10(w_hi / w_lo)
    pts = [np.logspace(math.log10(w_lo), math.log10(w_hi), int(8 * decades) + 1)]
    osc = lam[lam.imag > 0]
    k = np.array([-16, -8, -4, -2, -1, -0.5, 0, 0.5, 1, 2, 4, 8, 16])
    for z in osc:
        pts.append(z.imag + k * abs(z.real))
    p = np.concatenate(pts)
    p = np.unique(np.concatenate([p[(p > w_lo) & (p < w_hi)], [w_lo, w_hi]]))
    return np.concatenate([[0.0], p])


def bilinear(x, y, ny: int, mt=None, mtt=None, const: float = 1.0) -> np.ndarray:
    """``x_y,i conj(y_y,j) + x_y,i conj(MT_j . y_v) + MT_i . x_v conj(y_y,j) + sum MTT_iajb
    x_v,a conj(y_v,b)`` for stacks ``x, y`` (N, ny + q) split as ``[y-part, v-part]``; with
    ``MT, MTT`` the period average of ``T`` and ``T (x) conj(T)`` this is the average of
    ``H_i conj(H_j)``, ``H = x_y + T x_v`` (``const`` weights the first term). (N, ny, ny)."""
    xy, xv, yy, yv = x[:, :ny], x[:, ny:], y[:, :ny], y[:, ny:]
    out = const * xy[:, :, None] * yy.conj()[:, None, :]
    if mt is not None and xv.shape[1]:
        tx = xv @ mt.T  # (N, ny)
        ty = yv @ mt.T
        out = out + xy[:, :, None] * ty.conj()[:, None, :] + tx[:, :, None] * yy.conj()[:, None, :]
        out = out + np.einsum("na,iajb,nb->nij", xv, mtt, yv.conj())
    return out


def markov_tail(coef: np.ndarray, ny: int, k_t: float, p: float, w_hi: float, mt=None, mtt=None):
    """Closed-form ``int_w_hi^inf`` of the covariance and ``w^2 x`` its diagonal, for
    ``w_ol = sum_k coef_k (j w)^-k`` (coef (5, ny + q)) with the period averages ``mt, mtt``
    and the spectrum's asymptote ``k_t w^-p``: the expansion to ``w^-4`` integrated term by
    term. Returns ``(cov (ny, ny), second (ny,))`` (``inf`` where ``w^2 |H|^2 Phi_t`` is not
    integrable)."""
    cov = np.zeros((ny, ny))
    second = np.zeros(ny)
    for order in range(5):
        c = np.zeros((ny, ny))
        for k in range(order + 1):
            b = bilinear(coef[k][None], coef[order - k][None], ny, mt, mtt)[0]
            c += ((-1j) ** k * 1j ** (order - k) * b).real
        e0 = p + order - 1.0  # int_w_hi^inf w^-(p + order) = w_hi^-e0 / e0
        cov += c * k_t * w_hi ** (-e0) / e0
        e2 = p + order - 3.0
        d = np.diag(c)
        if e2 > 0:
            second += d * k_t * w_hi ** (-e2) / e2
        else:
            second = np.where(np.abs(d) > 0, np.inf, second)
    return cov, second


def outer(h: np.ndarray) -> np.ndarray:
    """``Re(h_i conj h_j)`` of responses ``h`` (n_w, ny): (n_w, ny, ny)."""
    return (h[:, :, None] * h[:, None, :].conj()).real


def columns(prod: np.ndarray, w: np.ndarray, psd: np.ndarray) -> np.ndarray:
    """Integrand columns from ``prod`` = ``Re(H_i conj H_j)`` (n_w, ny, ny): ``prod Phi``
    (flattened), then ``w^2 prod_ii Phi``."""
    diag = np.diagonal(prod, axis1=1, axis2=2)
    return np.hstack([prod.reshape(w.size, -1) * psd[:, None], diag * (w**2 * psd)[:, None]])


def pack(cov: np.ndarray, second: np.ndarray) -> np.ndarray:
    """The :func:`columns` layout of a covariance and second moments."""
    return np.concatenate([cov.ravel(), second])


def unpack(col: np.ndarray, ny: int) -> tuple[np.ndarray, np.ndarray]:
    """``(cov (ny, ny), second (ny,))`` from :func:`columns` integrals."""
    cov = col[: ny * ny].reshape(ny, ny)
    return (cov + cov.T) / 2, col[ny * ny :]


def diagonal(ny: int) -> np.ndarray:
    """Column indices of the variances and second moments in :func:`columns`."""
    return np.concatenate([np.arange(ny) * (ny + 1), ny * ny + np.arange(ny)])


# -- the sampled loop --------------------------------------------------------------------------


class SampledResponse:
    """``H_s(w)`` of outputs at the sample instants of the loop a linear law closes (module
    docstring), vectorised over frequencies by the eigendecompositions of A and of the law's A.

    Parameters
    ----------
    a, b, c, d : ndarray
        The continuous plant.
    iu, iw : list of int, int
        Columns of the law's controls and of the gust.
    rows, srows : list of int
        Rows of the outputs and of the law's sensors (``srows`` None: state feedback).
    law : LinearLaw
    phi, gu : ndarray
        Zero-order hold of the controls over ``law.dt``.
    """

    def __init__(self, a, b, c, d, iu: list, iw: int, rows: list, srows, law, phi, gu) -> None:
        n, m = a.shape[0], len(iu)
        self.ny, self.dt = len(rows), law.dt
        if srows is None:
            cm, dmw, dmu = np.eye(n), np.zeros(n), np.zeros((n, m))
        else:
            cm, dmw, dmu = c[srows], d[srows, iw], d[np.ix_(srows, iu)]
        ns, p = law.A.shape[0], law.B.shape[1]
        if p <= ns + m:  # what the controller takes in: its measurement
            pi, bk, dk = np.eye(p), law.B, law.D
        else:  # or its state update and command (state feedback: p = plant states)
            pi = np.vstack([law.B, law.D])
            bk = np.hstack([np.eye(ns), np.zeros((ns, m))])
            dk = np.hstack([np.zeros((m, ns)), np.eye(m)])
        cw = np.vstack([c[rows], pi @ cm])
        self.du = np.vstack([d[np.ix_(rows, iu)], pi @ dmu])
        self.ol = ModalResponse(a, b[:, iw], cw, np.concatenate([d[rows, iw], pi @ dmw]))
        self.mu = np.exp(self.ol.lam * law.dt)
        self.gt = np.linalg.solve(self.ol.vecs, gu)
        self.dk, self.direct, self.direct_law = dk, None, None
        self.lam_s, self.cs, self.bk = np.zeros(0), np.zeros((m, 0)), bk
        if ns:
            self.lam_s, vs = np.linalg.eig(law.A)
            self.cs, self.bk = law.C @ vs, np.linalg.solve(vs, bk)
        # the modal forms against direct solves on the unit circle
        probe = np.exp(1j * np.linspace(0.01, math.pi, 7))
        ref = [(cw @ np.linalg.solve(z * np.eye(n) - phi, gu) + self.du / z) for z in probe]
        if not (self.ol.modal_ok and _close(self._held(probe), np.array(ref))):
            self.direct = (cw, phi, gu)
        if ns:
            ref = [law.C @ np.linalg.solve(z * np.eye(ns) - law.A, bk) + dk for z in probe]
            if not _close(self._law(probe), np.array(ref)):
                self.direct_law = (law.A, law.C, bk)

    def _held(self, z: np.ndarray) -> np.ndarray:
        """``Cw (zI - Phi)^-1 Gu + Du / z``, (n_z, ny + q, m)."""
        if self.direct is not None:
            cw, phi, gu = self.direct
            x = np.linalg.solve(z[:, None, None] * np.eye(phi.shape[0]) - phi, gu)
            return cw @ x + self.du / z[:, None, None]
        r = 1.0 / (z[:, None] - self.mu[None, :])
        cols = [(r * self.gt[:, j]) @ self.ol.ct.T for j in range(self.gt.shape[1])]
        return np.stack(cols, axis=-1) + self.du[None] / z[:, None, None]

    def _law(self, z: np.ndarray) -> np.ndarray:
        """The controller from what it takes in to its command, (n_z, m, q)."""
        if self.direct_law is not None:
            a_s, c_s, bk = self.direct_law
            x = np.linalg.solve(z[:, None, None] * np.eye(a_s.shape[0]) - a_s, bk)
            return c_s @ x + self.dk
        r = 1.0 / (z[:, None] - self.lam_s[None, :])
        return np.einsum("mi,zi,iq->zmq", self.cs, r, self.bk) + self.dk

    def periodic(self, w: np.ndarray) -> np.ndarray:
        """``T(z)``, (n_w, ny, q): ``H_s = Hy + T v``, ``[Hy, v] = self.ol(w)``."""
        z = np.exp(1j * w * self.dt)
        pw, k = self._held(z), self._law(z)
        py, pq = pw[:, : self.ny], pw[:, self.ny :]
        eye = np.eye(k.shape[1])
        return py @ np.linalg.solve(eye - k @ pq, k)

    def __call__(self, w: np.ndarray) -> np.ndarray:
        """``H_s(w)``, (n_w, ny)."""
        wo = self.ol(w)
        t = self.periodic(w)
        return wo[:, : self.ny] + np.einsum("wiq,wq->wi", t, wo[:, self.ny :])


def loop_points(zeta: np.ndarray, dt: float, w_hi: float) -> np.ndarray:
    """Panel ends at the aliases ``+-theta_i + k P`` of the closed-loop poles ``zeta_i``
    (``s_i = log(zeta_i) / T``, ``theta_i = |Im s_i|``) +- 1 and 4 x their decay rate (and 16 x
    for ``k <= 3``), below ``w_hi``: every alias for a peak narrower than P/50, the first
    three aliases for wider ones (up to P/2)."""
    period = 2 * math.pi / dt
    zeta = zeta[np.abs(zeta) > math.exp(-math.pi)]
    s = np.log(zeta.astype(complex)) / dt
    s = np.abs(s.real) + 1j * np.abs(s.imag)
    kept: list = []  # one pole of a cluster closer than a tenth of its decay rate
    for x in s[np.lexsort((s.real, s.imag))]:
        if not kept or abs(x - kept[-1]) >= 0.1 * kept[-1].real:
            kept.append(x)
    theta, sig = np.imag(kept), np.real(kept)
    k = np.arange(0, math.ceil(w_hi / period) + 1)
    pts = []
    for sign in (1.0, -1.0):
        c = k[:, None] * period + sign * theta[None, :]  # (aliases, poles)
        for off in (0, 4, -4):
            pts.append((c + off * sig)[:, sig < period / 50].ravel())
        for off in (0, 1, -1, 4, -4, 16, -16):
            pts.append((c + off * sig)[:4].ravel())
    p = np.concatenate(pts)
    return np.unique(p[(p > 0) & (p < w_hi)])


def alias_start(rho: float, dt: float) -> float:
    """``w_a`` [rad/s], where the period averages start: the first multiple of
    ``P = 2 pi / dt`` above 20 P, 1.5 x the spectral radius ``rho`` of A and ``rho + 10 P``
    (module docstring)."""
    period = 2 * math.pi / dt
    return period * math.ceil(max(1.5 * rho, rho + 10 * period, 20 * period) / period)


# -- the moments ----------------------------------------------------------------------------


def loop_moments(resp: SampledResponse, zeta, spec, v, scale, w_a, w_hi, rtol) -> tuple:
    """Covariance and second-moment columns (:func:`columns`) at the sample instants of a loop
    with closed-loop eigenvalues ``zeta``, and those of the closed-form tail beyond ``w_hi``:
    quadrature to ``w_a``, period averages beyond with their Euler-Maclaurin terms (module
    docstring). ``spec`` a Spectrum, ``v`` [m/s], ``scale`` its L [m], ``w_a, w_hi`` [rad/s];
    returns two arrays."""
    ny, dt = resp.ny, resp.dt
    period = 2 * math.pi / dt
    p = spec.tail_exponent
    at = resp.ol(np.array([w_a]))[0]
    psd_a = spec.time_psd(np.array([w_a]), v)

    def per(w):  # T, T (x) conj T and the actual integrand at w_a, over one period
        t = resp.periodic(w)
        n = w.size
        tt = np.einsum("nia,njb->niajb", t, t.conj()).reshape(n, -1)
        flat = np.hstack([t.reshape(n, -1), tt])
        x = (w - w_a) / period
        probe = np.abs(at[None, :ny] + t @ at[ny:]) ** 2 * psd_a
        bern = (np.ones_like(x), x - 0.5, x * x - x + 1 / 6, x * (x - 0.5) * (x - 1))
        return np.hstack(
            [probe] + [np.ascontiguousarray(flat * b[:, None]).view(float) for b in bern]
        )

    pts = loop_points(zeta, dt, w_a + period)
    pts = np.unique(np.concatenate([[w_a, w_a + period], pts[pts > w_a]]))
    mom = adaptive(per, pts, rtol, np.arange(ny), np.zeros(1))[ny:].view(complex).reshape(4, -1)
    q = resp.ol.ct.shape[0] - ny
    moments = [(m[: ny * q].reshape(ny, q), m[ny * q :].reshape(ny, q, ny, q)) for m in mom]
    mean = (moments[0][0] / period, moments[0][1] / period)

    def smooth(w, mt, mtt, const=1.0):
        wo = resp.ol(w)
        return columns(bilinear(wo, wo, ny, mt, mtt, const).real, w, spec.time_psd(w, v))

    k_t = spec.tail_coefficient * v ** (p - 1)
    tail = pack(*markov_tail(resp.ol.markov(5), ny, k_t, p, w_hi, *mean))
    check = diagonal(ny)
    pts = np.logspace(math.log10(w_a), math.log10(w_hi), int(8 * math.log10(w_hi / w_a)) + 2)
    pts[[0, -1]] = w_a, w_hi
    beyond = adaptive(
        lambda w: smooth(w, *mean), pts, rtol, check, np.where(np.isfinite(tail), tail, 0.0)
    )
    # Euler-Maclaurin: - sum_r P^(r-1)/r! int_0^P f B_r(t/P) dt g^(r-1)(w_a), r = 1, 2, 3
    h = 1e-3 * w_a
    g = [smooth(w_a + np.array([-h, 0.0, h]), *m, 0.0) for m in moments[1:]]
    beyond += tail - g[0][1] - period / 2 * (g[1][2] - g[1][0]) / (2 * h)
    beyond -= period**2 / 6 * (g[2][2] - 2 * g[2][1] + g[2][0]) / h**2

    def f(w):
        return columns(outer(resp(w)), w, spec.time_psd(w, v))

    pts = np.concatenate([breakpoints(resp.ol.lam, v, scale, w_a), loop_points(zeta, dt, w_a)])
    pts = np.unique(np.concatenate([pts, period * np.arange(1, round(w_a / period))]))
    done = adaptive(f, pts, rtol, check, np.where(np.isfinite(beyond), beyond, 0.0))
    return done + beyond, tail
