"""State-space models of a wing at a flight condition, over a speed grid, sampled (ZOH), and
initial states; builders are cached per model so repeated calls are cheap.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..errors import InputError, check_number
from .signals import Sensor
from .state_space import Servo, StateSpaceBuilder, _tag

__all__ = ["statespace", "statespace_family", "discretize", "tip_deflection_state"]


_MODELS: dict = {}


def _model_for(wing_or_model, n_elements: int, wagner: object):
    from ..system.aeroelastic import AeroelasticModel

    if isinstance(wing_or_model, AeroelasticModel):
        return wing_or_model
    key = (wing_or_model, n_elements, wagner if isinstance(wagner, str) else None)
    if key[2] is not None and key in _MODELS:
        return _MODELS[key]
    model = AeroelasticModel(wing_or_model, n_elements, wagner)
    if key[2] is not None:
        if len(_MODELS) > 16:
            _MODELS.clear()
        _MODELS[key] = model
    return model


def _builder_for(model, density, inputs, outputs, **kw) -> StateSpaceBuilder:
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

    Returns
    -------
    control.StateSpace
        With named states, inputs and outputs, and attributes ``speed``, ``density`` and
        ``signal_units``. Builders are cached per model, so repeated calls are cheap.
    """
    model = _model_for(wing, n_elements, wagner)
    b = _builder_for(
        model, density, inputs, outputs, servo=servo, gust=gust, kussner=kussner, n_modes=n_modes
    )
    return b.at(speed, balanced=balanced)


def statespace_family(
    wing, speeds: Sequence[float], density: float, inputs=None, outputs=None, **kw
):
    """Models over a speed grid [m/s], e.g. for gain scheduling (no re-assembly).

    Same parameters as :func:`statespace`; returns a list of ``control.StateSpace``.
    """
    n_el = kw.pop("n_elements", 10)
    wag = kw.pop("wagner", "rt_jones")
    balanced = kw.pop("balanced", True)
    model = _model_for(wing, n_el, wag)
    return _builder_for(model, density, inputs, outputs, **kw).family(speeds, balanced=balanced)


def discretize(sys, sample_rate: float):
    """Zero-order-hold discretization at ``sample_rate`` [Hz]; names and tags are kept."""
    rate = check_number("sample_rate", sample_rate, unit="Hz", lo=0.0, lo_open=True)
    d = sys.sample(1.0 / rate, method="zoh")
    if hasattr(sys, "speed"):
        _tag(d, sys.speed, sys.density, sys.signal_units)
    if hasattr(sys, "state_scaling"):
        d.state_scaling = sys.state_scaling
    return d


def tip_deflection_state(builder, tip: float, *, balanced: bool = True) -> np.ndarray:
    """Initial state: the static shape under a tip load, scaled to a tip deflection ``tip`` [m].

    Rates, lag, gust and servo states are zero. ``builder`` is the plant's
    :class:`~aeroservo.linear.state_space.StateSpaceBuilder` (full model); ``balanced``
    (default, as its models): in the scaled states of ``builder.at``; False: physical states.
    """
    check_number("tip", tip, unit="m")
    if builder.n_modes is not None:
        raise InputError("tip_deflection_state: use the full-model builder of the plant")
    model = builder.model
    f = np.zeros(model.n_dofs)
    f[model.mesh.dof_w[-1]] = 1.0
    q = np.linalg.solve(model.matrices.Ks.toarray(), f)
    x = np.zeros(builder.n_states)
    x[: model.n_dofs] = q * (tip / q[model.mesh.dof_w[-1]])
    return x / builder.state_scaling if balanced else x
