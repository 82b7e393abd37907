"""State-space models of a wing at a flight condition, over a speed grid, sampled (ZOH), and
initial states; builders are cached per model so repeated calls are cheap.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..aero.atmosphere import isa_at_density
from ..errors import RANGES, InputError, check_number
from ..system.first_order import mach_note
from .signals import Sensor, describe
from .state_space import DENSITIES, MAX_SPEED, Servo, StateSpaceBuilder
from .tags import tag

__all__ = ["statespace", "statespace_family", "discretize", "tip_deflection_state"]


_MODELS: dict = {}


SAMPLE_RATES = (RANGES["sample_rate"].lo, RANGES["sample_rate"].hi)
"""Allowed sample rates [Hz] of sampled models (as in scenario files)."""

_BUILDER_KW = ("servo", "gust", "kussner", "n_modes", "mach")


def _model_for(wing_or_model, n_elements: int, wagner: object, aero: object = "strip"):
    from ..aero.dlm_settings import as_aero
    from ..structure.wing import Wing
    from ..system.aeroelastic import AeroelasticModel

    if isinstance(wing_or_model, AeroelasticModel):
        return wing_or_model
    if not isinstance(wing_or_model, Wing):
        raise InputError(
            f"wing = {describe(wing_or_model)}: expected an aeroservo.Wing or an AeroelasticModel"
        )
    aero = as_aero(aero)
    key = (wing_or_model, n_elements, wagner if isinstance(wagner, str) else None, aero)
    if key[2] is not None and key in _MODELS:
        return _MODELS[key]
    model = AeroelasticModel(
        wing_or_model, n_elements, wagner, aero="strip" if aero is None else aero
    )
    if key[2] is not None:
        if len(_MODELS) > 16:
            _MODELS.clear()
        _MODELS[key] = model
    return model


def _builder_for(model, density, inputs, outputs, **kw) -> StateSpaceBuilder:
    check_number("density", density, unit="kg/m^3", lo=DENSITIES[0], hi=DENSITIES[1])
    cache = model.__dict__.setdefault("_ss_builders", {})
    try:
        key = (float(density), _freeze(inputs), _freeze(outputs), _freeze(kw))
        hash(key)
    except TypeError:
        return StateSpaceBuilder(model, density, inputs, outputs, **kw)
    if key not in cache:
        cache[key] = StateSpaceBuilder(model, density, inputs, outputs, **kw)
    return cache[key]


def _freeze(x):
    if isinstance(x, dict):
        return tuple(sorted((k, _freeze(v)) for k, v in x.items()))
    if isinstance(x, (list, tuple)):
        return tuple(_freeze(v) for v in x)
    return x


def statespace(
    wing,
    speed: float,
    density: float,
    inputs: Sequence[str] | None = None,
    outputs: Sequence[str | Sensor] | None = None,
    *,
    n_elements: int = 10,
    wagner: object = "rt_jones",
    servo: Servo | dict | None = None,
    gust: str = "kussner",
    kussner: object = "sears_sparks",
    n_modes: int | None = None,
    balanced: bool = True,
    mach: float = 0.0,
    aero: object = "strip",
):
    """Linear state-space model of a wing at one flight condition.

    Parameters
    ----------
    wing : Wing or AeroelasticModel
        A wing (meshed with ``n_elements`` and ``wagner``) or an existing model.
    speed : float
        Airspeed [m/s].
    density : float
        Air density [kg/m^3].
    inputs, outputs :
        Signal names, see :mod:`aeroservo.linear.signals` (defaults: hinge moments and gust in; tip
        leading/trailing-edge accelerations and tip twist out).
    servo, gust, kussner, n_modes :
        See :class:`StateSpaceBuilder`.
    balanced : bool
        True (default): diagonally scaled states (same transfer function and state names,
        ``x_physical = sys.state_scaling * x``); False: the physical states, see
        :meth:`StateSpaceBuilder.at`.
    mach : float
        Mach number of the Prandtl-Glauert correction (0: incompressible; below 0.9); of the
        doublet lattice (below 1).
    aero : {"strip", "dlm"}, dict or DoubletLattice
        Aerodynamic model of a wing given as a Wing (see :class:`aeroservo.AeroelasticModel`;
        an existing model keeps its own).

    Returns
    -------
    control.StateSpace
        With named states, inputs and outputs, and attributes ``speed``, ``density`` and
        ``signal_units``. Builders are cached per model, so repeated calls are cheap.
    """
    check_number("speed", speed, unit="m/s", lo=0.0, hi=MAX_SPEED)
    _check_bool("balanced", balanced)
    model = _model_for(wing, n_elements, wagner, aero)
    kw = {"mach": mach} if mach else {}  # the cached incompressible builder otherwise
    b = _builder_for(
        model,
        density,
        inputs,
        outputs,
        servo=servo,
        gust=gust,
        kussner=kussner,
        n_modes=n_modes,
        **kw,
    )
    a = isa_at_density(density).speed_of_sound
    note = None if mach else mach_note("the model", speed, a, assumed=True)
    if note:
        import warnings

        warnings.warn(note, UserWarning, stacklevel=2)
    sys = b.at(speed, balanced=balanced)
    sys.builder = b  # the plant's layout, for tip_deflection_state and state maps
    return sys


def statespace_family(
    wing, speeds: Sequence[float], density: float, inputs=None, outputs=None, **kw
):
    """Models over a speed grid [m/s], e.g. for gain scheduling (no re-assembly).

    Same parameters as :func:`statespace`; returns a list of ``control.StateSpace``.
    """
    n_el = kw.pop("n_elements", 10)
    wag = kw.pop("wagner", "rt_jones")
    aero = kw.pop("aero", "strip")
    balanced = _check_bool("balanced", kw.pop("balanced", True))
    for k in kw:
        if k not in _BUILDER_KW:
            allowed = ["n_elements", "wagner", "aero", "balanced", *_BUILDER_KW]
            raise InputError(f"statespace_family: unknown argument {k!r}; allowed: {allowed}")
    if not (isinstance(speeds, (list, tuple, range)) or getattr(speeds, "ndim", 0) == 1):
        raise InputError(f"speeds = {describe(speeds)}: expected a sequence of speeds [m/s]")
    model = _model_for(wing, n_el, wag, aero)
    return _builder_for(model, density, inputs, outputs, **kw).family(speeds, balanced=balanced)


def discretize(sys, sample_rate: float):
    """Zero-order-hold discretization at ``sample_rate`` [Hz] (1 Hz to 100 kHz); names and tags
    are kept."""
    check_continuous("sys", sys)
    lo, hi = SAMPLE_RATES
    rate = check_number("sample_rate", sample_rate, unit="Hz", lo=lo, hi=hi)
    d = sys.sample(1.0 / rate, method="zoh")
    if hasattr(sys, "speed"):
        tag(d, sys.speed, sys.density, sys.signal_units)
    if hasattr(sys, "state_scaling"):
        d.state_scaling = sys.state_scaling
    return d


def tip_deflection_state(plant, tip: float, *, balanced: bool | None = None) -> np.ndarray:
    """Initial state: the static shape under a tip load, scaled to a tip deflection ``tip`` [m].

    Rates, lag, gust and servo states are zero.

    Parameters
    ----------
    plant : control.StateSpace or StateSpaceBuilder
        The plant from :func:`statespace` (its states, balanced or physical, are used as they
        are) or its :class:`~aeroservo.linear.state_space.StateSpaceBuilder` (full model).
    tip : float
        Tip deflection [m] (+ up).
    balanced : bool, optional
        With a builder: the scaled states of ``builder.at`` (default True) or the physical
        ones (False). With a state space it must agree with the model's states if given.

    Returns
    -------
    ndarray (n_states,)
    """
    builder = getattr(plant, "builder", plant)
    if not isinstance(builder, StateSpaceBuilder):
        raise InputError(
            f"plant = {describe(plant)}: expected the control.StateSpace of "
            "aeroservo.statespace(...) or a StateSpaceBuilder"
        )
    check_number("tip", tip, unit="m")
    if balanced is not None:
        _check_bool("balanced", balanced)
    if builder.n_modes is not None:
        raise InputError("tip_deflection_state: use the full-model plant (no n_modes)")
    model = builder.model
    f = np.zeros(model.n_dofs)
    tip_w = model.mesh.dof_w[-1]
    f[tip_w] = 1.0
    ks = model.matrices.Ks.toarray()
    x = np.zeros(builder.n_states)
    if builder.basis is None:
        q = np.linalg.solve(ks, f)
        x[: model.n_dofs] = q * (tip / q[tip_w])
    else:  # a doublet-lattice model: the static shape on its modal basis
        phi = builder.basis
        eta = np.linalg.solve(phi.T @ ks @ phi, phi.T @ f)
        x[: eta.size] = eta * (tip / (phi @ eta)[tip_w])
    if builder is plant:
        return x / builder.state_scaling if balanced in (None, True) else x
    scaling = np.asarray(plant.state_scaling)
    is_balanced = not np.all(scaling == 1.0)
    if (
        balanced is not None
        and bool(balanced) != is_balanced
        and not np.all(builder.state_scaling == 1.0)
    ):
        raise InputError(
            f"balanced = {balanced}: the plant's states are "
            f"{'balanced' if is_balanced else 'physical'}; leave balanced out"
        )
    return x / scaling


def _check_bool(field: str, value: object) -> bool:
    if not isinstance(value, (bool, np.bool_)):
        raise InputError(f"{field} = {describe(value)}: expected True or False")
    return bool(value)


def check_continuous(field: str, sys: object) -> None:
    """Refuse anything but a continuous-time ``control.StateSpace``."""
    import control

    if not isinstance(sys, control.StateSpace):
        raise InputError(f"{field} = {describe(sys)}: expected a control.StateSpace")
    if sys.isdtime(strict=True):
        raise InputError(
            f"{field}: a discrete-time model (dt = {sys.dt}); expected a continuous one"
        )
