"""The verdict of a closed-loop simulation: from the eigenvalues of the sampled loop at the
scenario's speed and the growth of every recorded signal, controls included.

* The **loop**: the spectral radius ``rho`` of the transition matrix of the sampled loop
  (:func:`aeroservo.design.closed_loop_matrix`, the loop the simulator marches, delay included;
  an MPC as its unconstrained LQG); ``rho >= 1`` is an unstable loop, whatever a short
  simulation shows. A nonlinear controller (a Python law) has no such matrix: its verdict at
  the speed rests on the signals.
* The **signals**: the growth of a signal is the largest ``|y|`` over the last
  :data:`TAIL` of the record divided by its largest value before; above :data:`GROWS` the
  response is still growing at the end (a nonlinear loop, e.g. saturated, can diverge while
  its linear part is stable).

The verdict is ``"unstable"`` if either says so, or if the loop is unstable anywhere in its
engaged range (:mod:`aeroservo.studies.loop_analysis`). A run *passes* when it is stable and
meets its margin requirement over the engaged range; otherwise the command line exits with
status 3 (unless the scenario sets ``simulation.expect_failure = true``).
"""

from __future__ import annotations

import numpy as np

from ..errors import VerdictFailure

__all__ = ["signal_growth", "loop_verdict", "TAIL", "GROWS", "EXIT_UNSTABLE"]

TAIL = 0.2
"""Share of the record at the end whose peak is compared with the peak before it."""

GROWS = 1.05
"""A signal whose last peak exceeds its earlier peak by more than this factor grows."""

EXIT_UNSTABLE = VerdictFailure.exit_code
"""Exit status of ``aeroservo simulate`` when the loop is unstable (and not expected to be):
:class:`~aeroservo.errors.VerdictFailure`'s."""


def signal_growth(y: np.ndarray, tail: float = TAIL) -> float:
    """Peak over the last ``tail`` of a record / peak before it (NaN for a zero signal)."""
    y = np.abs(np.asarray(y, dtype=float))
    n = max(1, int(round(tail * y.size)))
    before = y[:-n].max() if y.size > n else 0.0
    if before == 0.0:
        return float("nan") if y.max() == 0.0 else float("inf")
    return float(y[-n:].max() / before)


_REMEDIES = {
    "open": "no controller acts: the open loop is unstable at this speed",
    "state": "try smaller gains (larger input weights), a higher sample rate or, with a delay, "
    "a design that accounts for it",
    "estimator": "try more design modes (model.design_modes), slower sensor filters "
    "(signals.sensor_filter) or a lower estimator gain (larger estimator.sensor_noise)",
    "compensator": "try more design modes (model.design_modes), a lower bandwidth "
    "(hinf.bandwidth for an H-infinity design) or slower sensor filters "
    "(signals.sensor_filter)",
    "saturation": "the linear loop is stable, the actuator limits lose it: larger limits "
    "(controller limits.magnitude, limits.rate), a smaller disturbance, or anti-windup "
    "(controller anti_windup)",
    "sign": "the same law with the opposite sign is stable: check the controller's sign (a "
    "gain or linear file closes u = sign K y: sign = 1 when its output is the command, -1 for "
    "negative feedback as control.lqr's K; docs/conventions.md)",
}


def _flipped_is_stable(plant, law, delay: bool) -> bool:
    """Whether the law with its command's sign reversed closes a stable sampled loop."""
    from dataclasses import replace

    from ..design.plant import SampledPlant
    from ..design.sampled_loop import loop_matrix

    flipped = replace(law, C=-law.C, D=-law.D)
    sp = SampledPlant.from_statespace(plant, law.dt, list(law.controls), (), list(law.sensors))
    return bool(np.max(np.abs(np.linalg.eigvals(loop_matrix(sp, flipped, delay)))) < 1.0)


def loop_verdict(
    plant, controller, delay: bool, signals: dict, limited: dict | None = None
) -> dict:
    """Verdict, spectral radius and the growing signals of a closed-loop run.

    Parameters
    ----------
    plant : control.StateSpace
        The plant at the scenario's speed (filters included).
    controller
        The sampled controller (a schedule evaluated at the speed).
    delay : bool
        Computational delay of the run.
    signals : dict
        ``{name: {"growth": ...}}`` of the recorded outputs and applied controls.
    limited : dict, optional
        ``{control: share of samples at a magnitude or rate limit}``, quoted in the hint.

    Returns
    -------
    dict
        ``verdict`` ("stable" or "unstable"), ``spectral_radius``, ``growth_rate`` [1/s] and
        ``critical_frequency`` [Hz] of its largest eigenvalue, ``growing_signals``, when
        unstable a one-line ``hint``; ``realisable`` and ``unmeasured_feedback`` (the plant
        states by kind that a state-feedback law feeds back directly, with a ``warnings``
        line: :mod:`aeroservo.design.realisability`).
    """
    from ..design.closed_loop import closed_loop_matrix
    from ..design.interface import has_linear_law
    from ..design.realisability import realisability_text, unmeasured_feedback
    from ..design.sampled_loop import linear_law, plant_states

    unmeasured = unmeasured_feedback(plant, controller)
    realisable = {"realisable": not unmeasured, "unmeasured_feedback": unmeasured}
    if unmeasured:
        realisable["warnings"] = [realisability_text(unmeasured)]

    growing = sorted(n for n, v in signals.items() if np.nan_to_num(v["growth"]) > GROWS)
    if not has_linear_law(controller):
        out = {
            "verdict": "unstable" if growing else "stable",
            "spectral_radius": None,
            "growth_rate": None,
            "critical_frequency": None,
            "growing_signals": growing,
        }
        if growing:
            out["hint"] = (
                f"closed loop unstable: {', '.join(growing)} grow under the nonlinear controller"
            )
        return out | realisable
    A, dt = closed_loop_matrix(plant, controller, delay=delay)
    lam = np.linalg.eigvals(A)
    i = int(np.argmax(np.abs(lam)))
    rho = float(np.abs(lam[i]))
    s = np.log(complex(lam[i])) / dt
    unstable = rho > 1.0 + 1e-12 or bool(growing)
    out = {
        "verdict": "unstable" if unstable else "stable",
        "spectral_radius": rho,
        "growth_rate": float(np.log(rho) / dt),
        "critical_frequency": float(abs(s.imag) / (2 * np.pi)),
        "growing_signals": growing,
    }
    if unstable:
        why = (
            f"spectral radius {rho:.6g} of the sampled loop (growth rate "
            f"{out['growth_rate']:.3g} 1/s at {out['critical_frequency']:.4g} Hz)"
            if rho > 1.0 + 1e-12
            else f"the loop's spectral radius is {rho:.6g}, but {', '.join(growing)} still grow"
        )
        law = linear_law(controller, plant_states(plant))
        kind = "open" if not law.has_feedback else law.kind
        if rho <= 1.0 + 1e-12:
            kind = "saturation"
        elif kind in ("state", "compensator") and _flipped_is_stable(plant, law, delay):
            kind = "sign"
        hint = f"closed loop unstable: {why}; {_REMEDIES[kind]}"
        busy = {k: v for k, v in (limited or {}).items() if v >= 0.5}
        if busy:
            share = ", ".join(f"{k} {100 * v:.0f} %" for k, v in busy.items())
            hint += f" (at its limits: {share} of the samples; the limits bound the response)"
        out["hint"] = hint
    return out | realisable
