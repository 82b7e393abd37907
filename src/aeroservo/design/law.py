"""The linear law of a sampled controller: one form for every linear controller.

Every linear controller of :mod:`aeroservo.design` (LQR, LQG, an MPC without active constraints,
H-infinity, a static gain, a compensator brought from python-control or MATLAB) is, at sample k,

``c_k = C s_k + D m_k``
``s_{k+1} = A s_k + B m_k + L (u_k - c_k)``

with ``m_k`` what it measures (the sensors, or the plant state for state feedback), ``c_k`` the
command it emits and ``u_k`` the input applied to the plant for it, after the actuator limits.
The last term is the controller's use of the applied input, which software knows: an
estimator predicts with it (LQG: ``L = Bu``, ``applied_input = "prediction"``), and a
compensator uses it against windup (observer form, Astrom & Rundqwist 1989;
``applied_input = "anti-windup"``). While no limit is active ``u_k = c_k`` and the term
vanishes: the controller seen from outside (a black box from sensors to commands) is
``(A, B, C, D)`` alone. Only hardware that *measures* the applied input and feeds it back (not a
known command) makes ``L`` part of the loop a margin analysis breaks.

A one-sample computational delay is part of the controller: :func:`delayed` appends the pending
command to its state, so the same form covers both. The two uses of the applied input part
there: an estimator keeps predicting with the input the plant receives (the pending command,
limited), while anti-windup compares the pending command with its limited value (a new gain
for the delayed realization), so that it vanishes whenever no limit is active.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from ..errors import InputError
from .riccati import solve_dare

__all__ = ["LinearLaw", "delayed", "state_gain", "pad_state_map", "anti_windup_gain"]


@dataclass(frozen=True)
class LinearLaw:
    """A linear sampled controller as matrices (see the module docstring).

    Attributes
    ----------
    A, B, C, D, L : ndarray
        ``(n_s, n_s)``, ``(n_s, p)``, ``(m, n_s)``, ``(m, p)``, ``(n_s, m)``.
    controls : tuple of str
        The commands, in order (m).
    sensors : tuple of str
        The measured sensors, in order (p), or ``()`` for state feedback (then ``m_k`` is the
        whole plant state, filters included, and p is its size).
    dt : float
        Sample period [s].
    kind : str
        ``"state"`` (state feedback), ``"estimator"`` (LQG, MPC without active constraints),
        ``"compensator"`` (H-infinity, a brought compensator or gain) or ``"open"`` (no feedback).
    source : str
        What the law is, for reports (e.g. ``"MPC without active constraints (its LQG)"``).
    applied_input : str
        What ``L`` does with the applied input: ``"prediction"`` (an estimator's model of the
        plant input) or ``"anti-windup"``.
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    L: np.ndarray
    controls: tuple
    sensors: tuple
    dt: float
    kind: str = "compensator"
    source: str = ""
    applied_input: str = "anti-windup"

    @property
    def n_states(self) -> int:
        """Controller states."""
        return self.A.shape[0]

    @property
    def state_feedback(self) -> bool:
        """Whether the law measures the plant state (no sensors)."""
        return not self.sensors

    @property
    def has_feedback(self) -> bool:
        """Whether any measurement reaches a command (an open loop has none)."""
        if np.any(self.D):
            return True
        return bool(np.any(self.C) and np.any(self.B))


def delayed(law: LinearLaw) -> LinearLaw:
    """The law with a one-sample computational delay: the command computed at sample k is
    applied at k + 1. The pending command ``p`` joins the state and is the output, ``o_k = p_k``,
    ``p_{k+1} = C s_k + D m_k``. An estimator keeps predicting with the input applied
    (``s_{k+1} = (A - L C) s_k + (B - L D) m_k + L u_k``); an anti-windup gain is designed anew
    for the delayed realization (``L (u_k - p_k)``, zero while no limit is active)."""
    ns, m = law.n_states, len(law.controls)
    p = law.B.shape[1]
    A = np.zeros((ns + m, ns + m))
    A[ns:, :ns] = law.C
    C = np.hstack([np.zeros((m, ns)), np.eye(m)])
    if law.applied_input == "prediction":
        A[:ns, :ns] = law.A - law.L @ law.C
        A[:ns, ns:] = law.L
        B = np.vstack([law.B - law.L @ law.D, law.D])
        L = np.vstack([law.L, np.zeros((m, m))])
    else:
        A[:ns, :ns] = law.A
        B = np.vstack([law.B, law.D])
        L = anti_windup_gain(A, C) if np.any(law.L) else np.zeros((ns + m, m))
    return replace(law, A=A, B=B, C=C, D=np.zeros((m, p)), L=L)


def pad_state_map(T: np.ndarray, n_plant: int) -> np.ndarray:
    """A state map padded with zero columns for plant states appended after the model's own
    (e.g. sensor filters of :func:`~aeroservo.design.plant.with_sensor_filters`)."""
    if T.shape[1] > n_plant:
        raise InputError(
            f"state feedback: the gain needs {T.shape[1]} plant states, the plant has {n_plant}"
        )
    return np.hstack([T, np.zeros((T.shape[0], n_plant - T.shape[1]))])


def state_gain(
    G: np.ndarray, controls: Sequence[str], dt: float, *, kind: str = "state", source: str = ""
) -> LinearLaw:
    """The law ``c = -G x`` of a state feedback on the whole plant state (no controller state)."""
    G = np.asarray(G, dtype=float)
    m, n = G.shape
    z = np.zeros
    return LinearLaw(
        z((0, 0)), z((0, n)), z((m, 0)), -G, z((0, m)), tuple(controls), (), float(dt), kind, source
    )


def anti_windup_gain(A: np.ndarray, C: np.ndarray) -> np.ndarray:
    """Observer gain ``L`` with ``A - L C`` stable (Schur), for anti-windup (module docstring).

    Returns zeros if the compensator has no state, no output, or no detectable pair (then the
    state update cannot use the applied input).
    """
    n, m = A.shape[0], C.shape[0]
    zero = np.zeros((n, m))
    if n == 0 or not np.any(C):
        return zero
    c = np.linalg.norm(C, axis=1)
    c[c == 0] = 1.0
    Cs = C / c[:, None]
    try:
        P = solve_dare(A.T, Cs.T, np.eye(n), np.eye(m))
        Ls = np.linalg.solve(Cs @ P @ Cs.T + np.eye(m), Cs @ P @ A.T).T
    except (ArithmeticError, np.linalg.LinAlgError):
        return zero
    L = Ls / c[None, :]
    if not np.all(np.isfinite(L)) or np.max(np.abs(np.linalg.eigvals(A - L @ C))) >= 1.0:
        return zero
    return L
