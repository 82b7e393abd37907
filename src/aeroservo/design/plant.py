"""The plant as sampled controllers see it, and actuator limits.

Sampling convention (used by every controller and by :func:`aeroservo.simulate.simulate`): at
sample k the sensors are read **before** the new command is applied, so

``x[k+1] = Phi x[k] + Gu u[k] + Gd d[k]`` (zero-order hold, exact discretization)
``y[k]   = C x[k] + Du u[k-1] + Dd d[k]``

(accelerometers see the command held over the previous interval; no algebraic loop). With a
computational delay of one sample, ``u[k]`` is the command computed at ``k - 1``.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla

from ..errors import RANGES, InputError, check_number
from ..linear.models import check_continuous
from ..linear.signals import check_names, check_signal_map, describe
from ..linear.tags import carry_tags
from .law import LinearLaw, state_gain

MAX_CUTOFF = RANGES["frequency"].hi
"""Largest anti-aliasing filter cutoff [Hz]."""

__all__ = [
    "Limits",
    "OpenLoop",
    "SampledPlant",
    "zoh",
    "select",
    "state_map",
    "with_sensor_filters",
    "filter_arrays",
]


def zoh(A: np.ndarray, B: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Exact zero-order-hold discretization: ``(expm(A dt), int_0^dt expm(A s) ds B)``."""
    n, m = B.shape
    M = np.zeros((n + m, n + m))
    M[:n, :n] = A
    M[:n, n:] = B
    E = sla.expm(M * dt)
    return E[:n, :n], E[:n, n:]


def _index(labels: Sequence[str], names: Sequence[str], what: str) -> list[int]:
    out = []
    for n in check_names(f"{what}s", names, empty=True):
        if n not in labels:
            raise InputError(f"{what} {n!r}: not a signal of the model; it has {list(labels)}")
        out.append(list(labels).index(n))
    return out


def select(sys, inputs: Sequence[str], outputs: Sequence[str]) -> tuple[np.ndarray, ...]:
    """``(A, B, C, D)`` of a python-control model restricted to named inputs and outputs."""
    import control

    if not isinstance(sys, control.StateSpace):
        raise InputError(f"sys = {describe(sys)}: expected a control.StateSpace")
    ii = _index(sys.input_labels, inputs, "input")
    oo = _index(sys.output_labels, outputs, "output")
    A = np.asarray(sys.A)
    return A, np.asarray(sys.B)[:, ii], np.asarray(sys.C)[oo], np.asarray(sys.D)[np.ix_(oo, ii)]


@dataclass(frozen=True)
class Limits:
    """Actuator limits applied to every controller in simulation (and used by MPC).

    Parameters
    ----------
    magnitude : dict
        ``{control input name: max |u|}`` in the input's unit (e.g. N m for a hinge moment).
    rate : dict
        ``{control input name: max |du/dt|}`` (e.g. N m/s).
    """

    magnitude: dict = field(default_factory=dict)
    rate: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        for kind in ("magnitude", "rate"):
            check_signal_map(f"limits.{kind}", getattr(self, kind))

    def arrays(self, controls: Sequence[str]) -> tuple[np.ndarray, np.ndarray]:
        """Magnitude and rate limits per control (inf where none)."""
        for name in list(self.magnitude) + list(self.rate):
            if name not in controls:
                raise InputError(f"limits: {name!r} is not a control input {list(controls)}")
        mag = np.array([self.magnitude.get(c, np.inf) for c in controls], dtype=float)
        rate = np.array([self.rate.get(c, np.inf) for c in controls], dtype=float)
        return mag, rate

    def apply(self, command: np.ndarray, previous: np.ndarray, dt: float, controls) -> np.ndarray:
        """Rate limit (relative to the previous applied value), then saturate."""
        mag, rate = self.arrays(controls)
        u = np.clip(command, previous - rate * dt, previous + rate * dt)
        return np.clip(u, -mag, mag)


@dataclass
class SampledPlant:
    """A continuous plant sampled at ``dt`` with the convention of this module.

    Attributes
    ----------
    Phi, Gu, Gd, C, Du, Dd : ndarray
    dt : float
    controls, disturbances, outputs : tuple of str
    """

    Phi: np.ndarray
    Gu: np.ndarray
    Gd: np.ndarray
    C: np.ndarray
    Du: np.ndarray
    Dd: np.ndarray
    dt: float
    controls: tuple
    disturbances: tuple
    outputs: tuple

    @classmethod
    def from_statespace(
        cls,
        sys,
        dt: float,
        controls: Sequence[str],
        disturbances: Sequence[str] = (),
        outputs: Sequence[str] | None = None,
    ) -> SampledPlant:
        dt = check_number("sample period", dt, unit="s", lo=0.0, lo_open=True)
        check_continuous("sys", sys)
        controls = check_names("controls", controls, empty=True)
        disturbances = check_names("disturbances", disturbances, empty=True)
        if outputs is None:
            outputs = list(sys.output_labels)
        outputs = check_names("outputs", outputs, empty=True)
        arrays = tuple(np.asarray(x) for x in (sys.A, sys.B, sys.C, sys.D))
        labels = (sys.input_labels, sys.output_labels)
        return cls.from_arrays(arrays, labels, dt, controls, disturbances, outputs)

    @classmethod
    def from_arrays(
        cls, arrays: tuple, labels: tuple, dt: float, controls, disturbances, outputs
    ) -> SampledPlant:
        """As :meth:`from_statespace`, from ``(A, B, C, D)`` and ``(input_labels,
        output_labels)`` (checked names, no python-control model)."""
        dt = check_number("sample period", dt, unit="s", lo=0.0, lo_open=True)
        ii, jj = (_index(labels[0], names, "input") for names in (controls, disturbances))
        oo = _index(labels[1], outputs, "output")
        A, B, C, D = arrays
        Bu, Bd, C = B[:, ii], B[:, jj], C[oo]
        Du, Dd = D[np.ix_(oo, ii)], D[np.ix_(oo, jj)]
        Phi, G = zoh(A, np.hstack([Bu, Bd]), dt)
        m = len(controls)
        return cls(
            Phi,
            G[:, :m],
            G[:, m:],
            C,
            Du,
            Dd,
            dt,
            tuple(controls),
            tuple(disturbances),
            tuple(outputs),
        )

    @property
    def n_states(self) -> int:
        return self.Phi.shape[0]

    def augmented(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(Ad, Bu_a, Bd_a, Ca)`` of the model with the held command h as extra states.

        ``xi = [x, h]``: ``xi[k+1] = Ad xi[k] + Bu_a u[k] + Bd_a d[k]`` and
        ``y[k] = Ca xi[k] + Dd d[k]``.
        """
        n, m = self.Gu.shape
        Ad = np.zeros((n + m, n + m))
        Ad[:n, :n] = self.Phi
        Bu = np.vstack([self.Gu, np.eye(m)])
        Bd = np.vstack([self.Gd, np.zeros((m, self.Gd.shape[1]))])
        Ca = np.hstack([self.C, self.Du])
        return Ad, Bu, Bd, Ca

    def as_statespace(self, delay: bool = False):
        """Discrete ``control.StateSpace`` of the sampled plant (inputs: controls then
        disturbances; outputs: measured outputs), with a one-sample command delay if asked."""
        import control

        Ad, Bu, Bd, Ca = self.augmented()
        n, m = Bu.shape
        if delay:  # pending command p: u[k] = p[k], p[k+1] = c[k]
            A2 = np.zeros((n + m, n + m))
            A2[:n, :n] = Ad
            A2[:n, n:] = Bu
            Bu2 = np.vstack([np.zeros((n, m)), np.eye(m)])
            Bd2 = np.vstack([Bd, np.zeros((m, Bd.shape[1]))])
            Ad, Bu, Bd, Ca = A2, Bu2, Bd2, np.hstack([Ca, np.zeros((Ca.shape[0], m))])
        return control.ss(
            Ad,
            np.hstack([Bu, Bd]),
            Ca,
            np.hstack([np.zeros((Ca.shape[0], m)), self.Dd]),
            self.dt,
            inputs=list(self.controls) + list(self.disturbances),
            outputs=list(self.outputs),
        )


def state_map(plant_builder, design_builder, *, balanced: bool = True) -> np.ndarray:
    """Matrix T with ``x_design = T x_plant`` between two builders of the same wing model.

    The design builder may be a modal truncation of the plant builder (``n_modes``): modal
    coordinates are ``eta = Phi^T Ms q`` (mass-normalized modes), their rates likewise; lag, gust
    and servo states are shared. ``balanced`` (default, as the builders' models): between the
    scaled states of :meth:`StateSpaceBuilder.at`; False: between the physical ones.
    """
    from ..linear.state_space import StateSpaceBuilder

    for name, b in (("plant_builder", plant_builder), ("design_builder", design_builder)):
        if not isinstance(b, StateSpaceBuilder):
            raise InputError(f"{name} = {describe(b)}: expected a StateSpaceBuilder")
    if plant_builder.model is not design_builder.model:
        raise InputError("state_map: the builders must use the same AeroelasticModel")
    if plant_builder.n_modes is not None:
        raise InputError("state_map: the plant builder must be the full model (n_modes=None)")
    if plant_builder.input_labels != design_builder.input_labels:
        raise InputError("state_map: plant and design models must have the same inputs")
    n_p, n_d = plant_builder.n_states, design_builder.n_states
    n_q = plant_builder.model.n_dofs
    if design_builder.n_modes is None:
        return np.eye(n_p)  # the same builder kind: the same scaling
    r = design_builder.n_modes
    if getattr(plant_builder.model, "dlm", None) is not None:
        T = _dlm_state_map(plant_builder.model, r, n_p, n_d)
    else:
        phi = design_builder.basis
        proj = phi.T @ plant_builder.model.matrices.Ms.toarray()
        T = np.zeros((n_d, n_p))
        T[:r, :n_q] = proj
        T[r : 2 * r, n_q : 2 * n_q] = proj
        rest = n_p - 2 * n_q
        if rest != n_d - 2 * r:
            raise InputError("state_map: the non-structural states of the two models differ")
        T[2 * r :, 2 * n_q :] = np.eye(rest)
    if balanced:
        T = T * (1.0 / design_builder.state_scaling)[:, None] * plant_builder.state_scaling[None, :]
    return T


def _dlm_state_map(model, r: int, n_p: int, n_d: int) -> np.ndarray:
    """:func:`state_map` of a doublet-lattice model: both are written on its aerodynamic basis
    (modal coordinates ``eta``), the design model on its first ``r`` modes. Roger's lag states
    (root-major, one per mode) of the kept modes are kept; minimum-state lag states, gust and
    servo states are shared (as strip theory's nodal lag states are)."""
    n_a = model.dlm.n_a
    lags = model.aero.lags
    roger = model.aero.rfa == "roger"
    n_lp, n_ld = (lags * n_a, lags * r) if roger else (lags, lags)
    rest = n_p - 2 * n_a - n_lp
    if rest != n_d - 2 * r - n_ld:
        raise InputError("state_map: the non-structural states of the two models differ")
    T = np.zeros((n_d, n_p))
    T[:r, :r] = np.eye(r)
    T[r : 2 * r, n_a : n_a + r] = np.eye(r)
    kept = [j * n_a + i for j in range(lags) for i in range(r)] if roger else list(range(lags))
    T[2 * r + np.arange(n_ld), 2 * n_a + np.asarray(kept)] = 1.0
    T[n_d - rest :, n_p - rest :] = np.eye(rest)
    return T


@dataclass
class OpenLoop:
    """A controller that commands zero (open-loop runs through the same simulator)."""

    controls: tuple
    dt: float
    sensors: tuple = ()
    needs_state: bool = False

    def law(self, states) -> LinearLaw:
        """No feedback: ``c = 0``."""
        zero = np.zeros((len(self.controls), len(states)))
        return state_gain(zero, self.controls, self.dt, kind="open", source="open loop")

    def reset(self) -> None:
        pass

    def command(self, y: np.ndarray, x: np.ndarray | None = None) -> np.ndarray:
        return np.zeros(len(self.controls))

    def update(self, y: np.ndarray, u: np.ndarray) -> None:
        pass


@functools.lru_cache(maxsize=16)
def _butterworth(order: int, cutoff: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(A, B, C)`` of an analogue Butterworth low-pass of ``cutoff`` [Hz] (no feedthrough);
    speed-independent, so built once per filter (read-only arrays)."""
    import control
    from scipy.signal import butter

    num, den = butter(order, 2 * np.pi * cutoff, analog=True)
    mats = tuple(
        np.atleast_2d(np.asarray(x, dtype=float)) for x in control.ssdata(control.tf2ss(num, den))
    )
    for x in mats:
        x.setflags(write=False)
    return mats[:3]


def with_sensor_filters(sys, sensors: Sequence[str], cutoff: float, order: int = 2):
    """The continuous plant with analogue anti-aliasing filters on some outputs.

    Each named output is replaced by its Butterworth low-pass-filtered value (same name), as
    on a real test rig where sensors are filtered before sampling. The filters are strictly
    proper, so filtered accelerometers have no direct feedthrough: a design model with the
    same filters stays consistent with the full plant after modal truncation (the feedthrough
    of the truncated modes is not seen).

    Parameters
    ----------
    sys : control.StateSpace
    sensors : sequence of str
        Outputs to filter.
    cutoff : float
        Cutoff frequency [Hz], in (0, 1e5].
    order : int
        Butterworth order (1 to 4).

    Returns
    -------
    control.StateSpace
        States ``<sensor>_filter<i>`` appended; metadata (speed, density, units) kept.
    """
    import control

    check_continuous("sys", sys)
    rows = _index(sys.output_labels, sensors, "sensor")
    arrays = (np.asarray(x) for x in (sys.A, sys.B, sys.C, sys.D))
    Aa, Ba, Ca, Da = filter_arrays(*arrays, rows, cutoff, order)
    k = int(order)  # filter states per sensor (validated by filter_arrays)
    states = list(sys.state_labels)
    for r in rows:
        states += [f"{sys.output_labels[r]}_filter{i + 1}" for i in range(k)]
    out = control.ss(
        Aa,
        Ba,
        Ca,
        Da,
        inputs=list(sys.input_labels),
        outputs=list(sys.output_labels),
        states=states,
    )
    return carry_tags(sys, out)


def filter_arrays(A, B, C, D, rows: Sequence[int], cutoff: float, order: int = 2) -> tuple:
    """The matrices of :func:`with_sensor_filters` (outputs ``rows`` filtered), without the
    python-control model around them."""
    fc = check_number("cutoff", cutoff, unit="Hz", lo=0.0, lo_open=True, hi=MAX_CUTOFF)
    is_int = isinstance(order, (int, np.integer)) and not isinstance(order, bool)
    if not is_int or order not in (1, 2, 3, 4):
        raise InputError(f"order = {describe(order)}: allowed values are 1, 2, 3, 4")
    fa, fb, fc_ = _butterworth(int(order), fc)
    n, m = B.shape
    k = fa.shape[0]
    nf = k * len(rows)
    Aa = np.zeros((n + nf, n + nf))
    Ba = np.zeros((n + nf, m))
    Ca = np.hstack([C, np.zeros((C.shape[0], nf))])
    Da = D.copy()
    Aa[:n, :n] = A
    Ba[:n] = B
    for j, r in enumerate(rows):
        s = slice(n + j * k, n + (j + 1) * k)
        Aa[s, s] = fa
        Aa[s, :n] = fb @ C[r : r + 1]
        Ba[s] = fb @ D[r : r + 1]
        Ca[r] = 0.0
        Ca[r, s] = fc_[0]
        Da[r] = 0.0
    return Aa, Ba, Ca, Da
