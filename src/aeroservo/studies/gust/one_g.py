"""The 1 g flight loads of a wing: its static aeroelastic trim at a flight point.

In level 1 g flight the wing carries its share of the airplane's weight, ``L = share M g``
(``share`` 0.5 for one of two wings, the tail's load neglected), against its own weight. The
clamped strip model is trimmed by the angle of attack ``alpha`` of its root section (a rigid
rotation of the whole wing, the same as a uniform steady upwash ``alpha V``): with the model's
steady (zero-frequency) response ``G`` to the ``gust`` input and to the ``load_factor`` input
(every mass loaded by g downward),

    root shear(alpha, n = 1) = alpha V G_shear,gust + G_shear,n = L - W

where ``W`` is the wing's weight (the aerodynamic lift is the root shear plus the weight),
and every load follows as ``alpha V G_load,gust + G_load,n``: the elastic twist under lift and
weight (and its extra lift) included. The control surfaces are held at zero: a loop is
assumed to command nothing in steady 1 g flight (flutter-suppression and load-alleviation laws
wash out the steady part of their sensors).

Limit loads are then ``1 g +- the incremental gust loads`` (CS-25.341: the gust loads are
increments on the 1 g level-flight loads; CS-25.321).
"""

from __future__ import annotations

import numpy as np

from ...errors import InputError
from ...linear.state_space import STANDARD_GRAVITY

__all__ = ["one_g_loads", "wing_weight"]


def wing_weight(model) -> float:
    """The wing's weight [N]: g times the vertical load of a unit acceleration, summed over
    the nodes (the consistent loads of every element and concentrated mass)."""
    am = model.matrices
    w = model.mesh.dof_w
    return float(STANDARD_GRAVITY * (am.weight[w[w >= 0]].sum() + am.root.weight[0]))


def one_g_loads(model, density: float, speed: float, loads, lift: float) -> tuple[dict, dict]:
    """The 1 g loads of a wing trimmed to carry ``lift`` (see the module docstring).

    Parameters
    ----------
    model : AeroelasticModel
        Strip model (the doublet lattice has no weight input).
    density : float
        [kg/m^3]
    speed : float
        True airspeed [m/s].
    loads : sequence of str
        Outputs of the model; inputs of the model among them (commands) are 0 in the trim.
    lift : float
        The lift the wing carries in 1 g flight [N].

    Returns
    -------
    (dict, dict)
        Load name -> 1 g value (SI), and the trim: ``alpha_rad``, ``lift_N``, ``weight_N``,
        ``lift_per_rad_N`` (the elastic wing's lift effectiveness).

    Raises
    ------
    InputError
        The wing has no positive lift effectiveness at this point (at or beyond divergence).
    """
    from ...linear.models import statespace
    from ...linear.signals import input_names

    inputs = set(input_names(model.wing))
    outs = list(dict.fromkeys(["root_shear"] + [n for n in loads if n not in inputs]))
    sys = statespace(model, speed, density, inputs=["gust", "load_factor"], outputs=outs)
    a, b = np.asarray(sys.A), np.asarray(sys.B)
    try:
        g = np.asarray(sys.D) - np.asarray(sys.C) @ np.linalg.solve(a, b)
    except np.linalg.LinAlgError:
        raise InputError(
            f"1 g trim at {speed:.4g} m/s: the static aeroelastic problem is singular (divergence)"
        ) from None
    weight = wing_weight(model)
    per_rad = speed * g[0, 0]  # lift (root shear) per radian of root angle of attack
    if not per_rad > 0:
        raise InputError(
            f"1 g trim at {speed:.4g} m/s: the wing's lift effectiveness is {per_rad:.4g} N/rad "
            "(not positive: at or beyond divergence); no 1 g loads"
        )
    alpha = (lift - weight - g[0, 1]) / per_rad
    values = alpha * speed * g[:, 0] + g[:, 1]
    units = getattr(sys, "signal_units", {}) or {}
    steady_zero = [i for i, n in enumerate(outs) if units.get(n) in ("m/s", "m/s^2", "rad/s")]
    values[steady_zero] = 0.0  # rates and accelerations: zero in steady flight, not rounding
    out = {n: float(values[outs.index(n)]) if n in outs else 0.0 for n in loads}
    trim = {
        "alpha_rad": float(alpha),
        "lift_N": float(lift),
        "weight_N": weight,
        "lift_per_rad_N": float(per_rad),
    }
    return out, trim
