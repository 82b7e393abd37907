"""H-infinity mixed-sensitivity flutter suppression at the actuator, designed for the sampled loop.

The design follows the loop of :mod:`aeroservo.design.sampled_loop` exactly:

1. the design model (controls to sensors, filters included) is sampled by zero-order hold and
   augmented with the held command (the sensors see ``u[k-1]``), then scaled: each control by
   its nominal magnitude ``u0``, each sensor by ``y0`` (controller file ``weights``);
2. the bilinear map ``z = (1 + s dt/2) / (1 - s dt/2)`` takes it to an equivalent continuous
   "w-plane" model (the H-infinity norm and stability are preserved; frequencies are warped,
   ``nu = (2/dt) tan(w dt/2)``, so the weights' corner frequencies are prewarped);
3. it is reduced to ``order`` states by balanced truncation (unstable flutter modes kept);
4. mixed sensitivity **at the plant input** (where margins are required): with the input
   loop ``Li = K G``, ``Si = (I + Li)^-1`` and ``Ti = I - Si``, minimise
   ``|| [W1 Si; W2 K Si; W3 Ti] ||_inf`` (the output-side problem of the transposed plant,
   :func:`control.augw`, solved by slycot's ``sb10ad``); a central controller at
   ``gamma_factor`` times the optimal gamma (the optimal one has poles near infinity, which the
   bilinear map sends to z = -1);
5. the controller is mapped back by the same bilinear map and unscaled: a discrete compensator
   ``c[k] = Cc s[k] + Dc y[k]``, ``s[k+1] = Ac s[k] + Bc y[k]`` (with anti-windup,
   :mod:`aeroservo.design.compensator`).

Weights (frequencies in Hz, prewarped): ``W1 = (s/M_S + wb) / (s + wb A_S)`` bounds ``|Si|`` by
``gamma A_S`` below ``bandwidth`` and ``gamma M_S`` above; ``W2 = c (s/wr + 1) / (s/(20 wr) + 1)``
limits the controller gain from the (scaled) sensors, rising above ``roll_off``;
``W3 = (s/wr + 1/M_T) / (s/(20 wr) + 1)`` bounds ``|Ti|`` by ``gamma M_T`` and rolls the loop
off above ``roll_off``. Bounds on both ``Si`` and ``Ti`` near one give the disk margin.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .._threads import blas_limited
from ..errors import InputError, NumericalError, check_int, check_number, check_quantity
from .compensator import DiscreteCompensator
from .plant import SampledPlant

__all__ = ["HinfWeights", "DiscreteCompensator", "hinf"]


@dataclass(frozen=True)
class HinfWeights:
    """Mixed-sensitivity weights of an H-infinity design (controller file ``[hinf]``).

    Attributes
    ----------
    order : int
        States of the reduced design model.
    sensitivity_peak, sensitivity_floor : float
        ``M_S`` and ``A_S``: bounds on the input sensitivity above and below ``bandwidth``.
    bandwidth : float
        [Hz]
    control_weight : float
        ``c``: weight on the scaled controller gain ``K Si`` below ``roll_off``.
    complementary_peak : float
        ``M_T``: bound on the input complementary sensitivity below ``roll_off``.
    roll_off : float
        [Hz], above which ``W2`` and ``W3`` rise twentyfold.
    gamma_factor : float
        Suboptimal gamma over the optimal one (> 1).
    """

    order: int = 20
    sensitivity_peak: float = 1.5
    sensitivity_floor: float = 0.3
    bandwidth: float = 5.0
    control_weight: float = 1.0
    complementary_peak: float = 1.5
    roll_off: float = 30.0
    gamma_factor: float = 1.2

    def __post_init__(self) -> None:
        check_int("hinf.order", self.order, lo=1, hi=1000)
        for key in ("sensitivity_peak", "sensitivity_floor", "control_weight"):
            check_number(f"hinf.{key}", getattr(self, key), lo=0.0, lo_open=True)
        check_number("hinf.complementary_peak", self.complementary_peak, lo=0.0, lo_open=True)
        check_number("hinf.bandwidth", self.bandwidth, unit="Hz", lo=0.0, lo_open=True)
        check_number("hinf.roll_off", self.roll_off, unit="Hz", lo=0.0, lo_open=True)
        check_number("hinf.gamma_factor", self.gamma_factor, lo=1.0, lo_open=True, hi=100.0)
        if self.sensitivity_floor >= self.sensitivity_peak:
            raise InputError(
                f"hinf.sensitivity_floor = {self.sensitivity_floor:g}: must be below "
                f"hinf.sensitivity_peak = {self.sensitivity_peak:g}"
            )


def _to_w_plane(A, B, C, D, dt: float):
    """Continuous model whose bilinear (Tustin) image is the discrete ``(A, B, C, D)``."""
    n = A.shape[0]
    Ni = np.linalg.inv(A + np.eye(n))
    return (2 / dt) * (np.eye(n) - 2 * Ni), 2 * Ni @ B / dt, 2 * C @ Ni, D - C @ Ni @ B


def _weights(w: HinfWeights, dt: float, n_controls: int, n_sensors: int):
    import control

    def warp(f: float, key: str) -> float:
        if f >= 0.5 / dt:
            raise InputError(
                f"hinf.{key} = {f:g}: above the Nyquist frequency {0.5 / dt:g} Hz of the sample "
                "rate"
            )
        return (2 / dt) * np.tan(np.pi * f * dt)

    wb, wr = warp(w.bandwidth, "bandwidth"), warp(w.roll_off, "roll_off")
    w1 = control.tf([1 / w.sensitivity_peak, wb], [1, wb * w.sensitivity_floor])
    w2 = w.control_weight * control.tf([1 / wr, 1], [1 / (20 * wr), 1])
    w3 = control.tf([1 / wr, 1 / w.complementary_peak], [1 / (20 * wr), 1])
    return (
        control.append(*[control.ss(w1)] * n_controls),
        control.append(*[control.ss(w2)] * n_sensors),
        control.append(*[control.ss(w3)] * n_controls),
    )


def _transpose(sys):
    import control

    return control.ss(
        np.asarray(sys.A).T, np.asarray(sys.C).T, np.asarray(sys.B).T, np.asarray(sys.D).T
    )


@blas_limited
def hinf(
    sys,
    controls: Sequence[str],
    sensors: Sequence[str],
    *,
    input_scale: dict,
    sensor_scale: dict,
    weights: HinfWeights | None = None,
    sample_rate: float = 1000.0,
) -> DiscreteCompensator:
    """H-infinity mixed-sensitivity compensator of the sampled loop (see the module docstring).

    Parameters
    ----------
    sys : control.StateSpace
        Continuous design model (filters included) with the controls and sensors.
    controls, sensors : sequence of str
    input_scale, sensor_scale : dict
        Nominal magnitude of each control [N m] and sensor [its unit].
    weights : HinfWeights, optional
    sample_rate : float
        [Hz]

    Returns
    -------
    DiscreteCompensator
    """
    import control
    from slycot import sb10ad
    from slycot.exceptions import SlycotError

    from ..linear.reduction import balanced_truncation

    w = weights or HinfWeights()
    dt = 1.0 / check_quantity("sample_rate", sample_rate, "sample_rate")
    for what, scale, names in (
        ("inputs", input_scale, controls),
        ("sensors", sensor_scale, sensors),
    ):
        missing = [n for n in names if n not in scale]
        if missing:
            raise InputError(f"hinf: weights.{what}: give a nominal magnitude for {missing}")
    u0 = np.array(
        [
            check_number(f"weights.inputs.{c}", input_scale[c], lo=0.0, lo_open=True)
            for c in controls
        ]
    )
    y0 = np.array(
        [
            check_number(f"weights.sensors.{s}", sensor_scale[s], lo=0.0, lo_open=True)
            for s in sensors
        ]
    )
    sp = SampledPlant.from_statespace(sys, dt, list(controls), (), list(sensors))
    Ad, Bu, _, Ca = sp.augmented()
    Bs, Cs = Bu * u0[None, :], Ca / y0[:, None]
    G = control.ss(*_to_w_plane(Ad, Bs, Cs, np.zeros((len(sensors), len(controls))), dt))
    err = 0.0
    if w.order < G.nstates:
        one_u, one_y = [1.0] * len(controls), [1.0] * len(sensors)
        bt = balanced_truncation(G, w.order, input_scale=one_u, output_scale=one_y)
        G, err = bt.system, bt.max_channel_error
    W1, W2, W3 = _weights(w, dt, len(controls), len(sensors))
    with warnings.catch_warnings():  # augw uses python-control's deprecated connect()
        warnings.simplefilter("ignore", FutureWarning)
        P = control.augw(_transpose(G), W1, W2, W3)
    PA, PB, PC, PD = (np.asarray(m) for m in (P.A, P.B, P.C, P.D))
    dims = (P.nstates, P.ninputs, P.noutputs, len(sensors), len(controls))
    try:
        g_opt = sb10ad(*dims, 1e100, PA, PB, PC, PD, job=3)[0]
        out = sb10ad(*dims, w.gamma_factor * g_opt, PA, PB, PC, PD, job=4)
    except SlycotError as exc:
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise NumericalError(
            f"H-infinity synthesis failed ({first}); try a larger hinf.order, other weights or "
            "a larger hinf.gamma_factor"
        ) from None
    K = _transpose(control.ss(*out[1:5]))
    Kd = control.c2d(K, dt, method="tustin")
    Ac, Bc, Cc, Dc = (np.asarray(m, dtype=float) for m in (Kd.A, Kd.B, Kd.C, Kd.D))
    # physical units, negative feedback: c = -u0 K (y / y0)
    return DiscreteCompensator(
        Ac,
        Bc / y0[None, :],
        -u0[:, None] * Cc,
        -u0[:, None] * Dc / y0[None, :],
        tuple(controls),
        tuple(sensors),
        dt,
        design_speed=float(getattr(sys, "speed", np.nan)),
        source="H-infinity",
        info={
            "gamma": float(out[0]),
            "gamma_optimal": float(g_opt),
            "order": int(Ac.shape[0]),
            "model_order": int(G.nstates),
            "reduction_error": float(err),
        },
    )
