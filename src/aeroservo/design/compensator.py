"""Linear discrete compensators from sensors to commands, with anti-windup.

A :class:`DiscreteCompensator` is ``c_k = Cc s_k + Dc y_k``, ``s_{k+1} = Ac s_k + Bc y_k`` in
physical units (sensors in their units, commands in theirs). H-infinity designs return one;
:func:`compensator_from_lti` makes one from a python-control ``StateSpace`` or
``TransferFunction`` designed elsewhere (discrete at the loop's period, or continuous and
discretised by a stated method).

**Anti-windup.** When the actuator limits cut the command, the compensator's state is updated
with the input actually applied (known in software), in observer form (Astrom & Rundqwist,
"Integrator windup and how to avoid it", ACC 1989; Astrom & Wittenmark, *Computer-Controlled
Systems*, 3rd ed., sec. 9.4)::

    s_{k+1} = Ac s_k + Bc y_k + Law (u_k - c_k)

with ``Ac - Law Cc`` stable, so that a saturated loop leaves the compensator's state bounded.
While no limit is active ``u_k = c_k``: the linear loop, its eigenvalues and its margins do not
depend on ``Law``. The default ``Law`` solves the filter Riccati equation of the pair
``(Ac, Cc)`` with unit weights (commands scaled to unit norm rows): unstable compensator poles
are moved inside the unit circle, stable ones move little.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError, check_number
from ..linear.signals import check_names, describe
from .law import LinearLaw, anti_windup_gain

__all__ = [
    "DiscreteCompensator",
    "compensator_from_lti",
    "DISCRETIZATIONS",
]

DISCRETIZATIONS = ("tustin", "zoh", "matched")
"""Methods that discretise a continuous compensator at the loop's sample rate."""


def _real_matrix(name: str, value, shape: tuple[int, int]) -> np.ndarray:
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{name} = {describe(value)}: expected a real matrix") from None
    if a.size == 0:
        a = a.reshape(shape)
    a = np.atleast_2d(a) if a.ndim < 2 and a.size else a
    if a.shape != shape:
        raise InputError(f"{name} has shape {a.shape}; expected {shape}")
    if not np.all(np.isfinite(a)):
        raise InputError(f"{name} has NaN or infinite entries")
    return a


@dataclass
class DiscreteCompensator:
    """A linear discrete compensator from the sensors to the commands (module docstring).

    Attributes
    ----------
    Ac, Bc, Cc, Dc : ndarray
        ``(n, n)``, ``(n, p)``, ``(m, n)``, ``(m, p)``; ``c = Cc s + Dc y``, ``s+ = Ac s + Bc y``.
    controls, sensors : tuple of str
        Command (m) and sensor (p) names.
    dt : float
        Sample period [s].
    design_speed : float
        [m/s] (NaN if unknown).
    info : dict
        What built it (H-infinity: ``gamma``, ``gamma_optimal``, ``order``, ``model_order``,
        ``reduction_error``; a brought compensator: its ``source`` and discretisation).
    anti_windup : ndarray or None
        ``Law`` ``(n, m)``; None computes the default (module docstring); zeros disable it.
    source : str
        Name in reports.
    """

    Ac: np.ndarray
    Bc: np.ndarray
    Cc: np.ndarray
    Dc: np.ndarray
    controls: tuple
    sensors: tuple
    dt: float
    design_speed: float = float("nan")
    info: dict = field(default_factory=dict)
    anti_windup: np.ndarray | None = None
    source: str = "discrete compensator"
    needs_state: bool = False

    def __post_init__(self) -> None:
        self.controls = tuple(check_names("controls", self.controls))
        self.sensors = tuple(check_names("sensors", self.sensors))
        self.dt = check_number("dt", self.dt, unit="s", lo=0.0, lo_open=True)
        Dc = np.asarray(self.Dc, dtype=float)
        m, p = len(self.controls), len(self.sensors)
        n = np.asarray(self.Ac).shape[0] if np.asarray(self.Ac).size else 0
        self.Ac = _real_matrix("Ac", self.Ac, (n, n))
        self.Bc = _real_matrix("Bc", self.Bc, (n, p))
        self.Cc = _real_matrix("Cc", self.Cc, (m, n))
        self.Dc = _real_matrix("Dc", Dc, (m, p))
        if self.anti_windup is None:
            self.anti_windup = anti_windup_gain(self.Ac, self.Cc)
        else:
            self.anti_windup = _real_matrix("anti_windup", self.anti_windup, (n, m))
        self.reset()

    def compensator_matrices(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        return self.Ac, self.Bc, self.Cc, self.Dc

    @property
    def n_states(self) -> int:
        return self.Ac.shape[0]

    def law(self, states: Sequence[str] = ()) -> LinearLaw:
        """Its :class:`~aeroservo.design.law.LinearLaw` (``states`` unused: it reads sensors)."""
        return LinearLaw(
            self.Ac,
            self.Bc,
            self.Cc,
            self.Dc,
            self.anti_windup,
            self.controls,
            self.sensors,
            self.dt,
            "compensator",
            self.source,
        )

    @property
    def compensator(self):
        """The compensator as a discrete ``control.StateSpace`` (sensors in, commands out)."""
        import control

        return control.ss(
            self.Ac,
            self.Bc,
            self.Cc,
            self.Dc,
            self.dt,
            inputs=list(self.sensors),
            outputs=list(self.controls),
        )

    # sampled-controller protocol (the simulator marches the law itself)
    def reset(self) -> None:
        self.s = np.zeros(self.Ac.shape[0])
        self._c = np.zeros(len(self.controls))

    def command(self, y: np.ndarray, x: np.ndarray | None = None) -> np.ndarray:
        self._c = self.Cc @ self.s + self.Dc @ y
        return self._c

    def update(self, y: np.ndarray, u: np.ndarray) -> None:
        self.s = self.Ac @ self.s + self.Bc @ y + self.anti_windup @ (u - self._c)


def sample_period(sample_rate: float | None) -> float | None:
    """The loop's sample period [s] from its sample rate [Hz] (None stays None)."""
    if sample_rate is None:
        return None
    return 1.0 / check_number("sample_rate", sample_rate, unit="Hz", lo=1.0, hi=1e5)


def check_period(dt: float, dt_loop: float | None, what: str) -> None:
    """A discrete controller's period ``dt`` [s] must be the loop's (if the loop's is given)."""
    if dt_loop is not None and abs(dt - dt_loop) > 1e-9 * dt_loop:
        raise InputError(
            f"{what} is discrete with period {dt:g} s ({1 / dt:g} Hz); the loop samples at "
            f"{1 / dt_loop:g} Hz: discretise it again at that rate"
        )


def _names(sys, kind: str, given) -> list[str]:
    """The input (``kind="inputs"``) or output names of an LTI system, or the given ones."""
    labels = list(sys.input_labels if kind == "inputs" else sys.output_labels)
    if given is not None:
        given = check_names("sensors" if kind == "inputs" else "controls", given)
        if len(given) != len(labels):
            raise InputError(
                f"{'sensors' if kind == 'inputs' else 'controls'} = {given}: the compensator has "
                f"{len(labels)} {kind}"
            )
        return list(given)
    default = "u[" if kind == "inputs" else "y["
    if any(n.startswith(default) for n in labels):
        what = "sensors" if kind == "inputs" else "controls"
        raise InputError(
            f"the compensator's {kind} are not named ({labels}): name them after the loop's "
            f"{what} (control.ss(A, B, C, D, dt, inputs=[sensors], outputs=[controls])) or give "
            f"{what}=[...]"
        )
    return labels


def compensator_from_lti(
    sys,
    *,
    sample_rate: float | None = None,
    method: str = "tustin",
    prewarp: float | None = None,
    sign: int = 1,
    controls: Sequence[str] | None = None,
    sensors: Sequence[str] | None = None,
    anti_windup: np.ndarray | None = None,
    source: str = "",
) -> DiscreteCompensator:
    """A :class:`DiscreteCompensator` from a python-control ``StateSpace`` or
    ``TransferFunction`` whose inputs are sensors and outputs commands.

    Parameters
    ----------
    sys : control.StateSpace or control.TransferFunction
        Discrete (its period must be the loop's) or continuous (discretised at ``sample_rate``).
    sample_rate : float, optional
        The loop's sample rate [Hz]; required for a continuous system.
    method : {"tustin", "zoh", "matched"}
        Discretisation of a continuous system (``"matched"``: matched pole-zero, SISO only).
    prewarp : float, optional
        Frequency [Hz] matched exactly by ``"tustin"``.
    sign : {1, -1}
        1: the system's output is the command (MATLAB's ``lqg``, ``hinfsyn``; positive feedback
        ``feedback(P, K, +1)``); -1: the command is minus its output (python-control's
        ``feedback(P, K)``, negative feedback).
    controls, sensors : sequence of str, optional
        Names replacing the system's output and input names.

    Raises
    ------
    InputError
        Unnamed signals, a period other than the loop's, an unknown method, a bad sign.
    """
    import control

    if not isinstance(sys, (control.StateSpace, control.TransferFunction)):
        raise InputError(
            f"sys = {describe(sys)}: expected a control.StateSpace or TransferFunction"
        )
    if sign not in (1, -1):
        raise InputError(f"sign = {describe(sign)}: expected 1 (output = command) or -1")
    if method not in DISCRETIZATIONS:
        raise InputError(f"method = {describe(method)}: choose one of {list(DISCRETIZATIONS)}")
    sensor_names, control_names = _names(sys, "inputs", sensors), _names(sys, "outputs", controls)
    dt_loop = sample_period(sample_rate)
    info = {"source": source or type(sys).__name__}
    if sys.dt in (0, None):  # continuous
        if dt_loop is None:
            raise InputError(
                "the compensator is continuous: give the loop's sample_rate [Hz] to discretise it "
                f"(method {method!r})"
            )
        kw = {}
        if prewarp is not None:
            if method != "tustin":
                raise InputError(f"prewarp: only the 'tustin' method takes it, not {method!r}")
            f = check_number("prewarp", prewarp, unit="Hz", lo=0.0, lo_open=True)
            if f >= 0.5 / dt_loop:
                raise InputError(f"prewarp = {f:g} Hz: above the Nyquist frequency")
            kw["prewarp_frequency"] = 2 * np.pi * f
        if method == "matched":
            if sys.ninputs != 1 or sys.noutputs != 1:
                raise InputError(
                    "method = 'matched': matched pole-zero is defined for SISO compensators; "
                    "use 'tustin' or 'zoh'"
                )
            d = control.ss(control.c2d(control.tf(sys), dt_loop, method="matched"))
        else:
            d = control.ss(control.c2d(control.ss(sys), dt_loop, method=method, **kw))
        info.update(discretisation=method, continuous=True)
        dt = dt_loop
    else:
        d = control.ss(sys)
        if sys.dt is True:
            if dt_loop is None:
                raise InputError("the compensator is discrete with no period: give sample_rate")
            dt = dt_loop
        else:
            dt = float(sys.dt)
            check_period(dt, dt_loop, "the compensator")
        info.update(continuous=False)
    A, B, C, D = (np.asarray(x, dtype=float) for x in (d.A, d.B, d.C, d.D))
    return DiscreteCompensator(
        A,
        B,
        sign * C,
        sign * D,
        tuple(control_names),
        tuple(sensor_names),
        dt,
        info=info,
        anti_windup=anti_windup,
        source=source or "brought compensator",
    )
