"""The plant of a nonlinear march: a linear model with its nonlinear hinge moments as feedback.

``x' = A x + B u + B_n phi(C_n x)``, ``y = C x + D u + D_n phi(C_n x)``: the linear model of
the wing (or a typical section) with every spring closed, named signals for the controller, and
the Lur'e channels of its nonlinear hinges (:mod:`aeroservo.system.hinge_elements`): the
moment ``phi = k s - M(s)`` each element adds at the rotation ``s`` it acts on.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import InputError, check_number
from ..system.hinge_elements import HingeElements, NonlinearHinge, hinge_elements
from .signals import DEFAULT_OUTPUTS, check_names
from .tags import system_name, tag

__all__ = [
    "NonlinearPlant",
    "nonlinear_plant",
    "section_plant",
    "split_plant",
    "hinge_inputs",
    "hinge_rates",
]


@dataclass
class NonlinearPlant:
    """A linear plant and the channels of its nonlinear hinges.

    Attributes
    ----------
    plant : control.StateSpace
        The linear model (springs closed) with the controller's inputs and the recorded outputs
        (``<element>_rotation`` [rad] among them), attributes ``speed``, ``density``.
    b_n : ndarray (n, n_e)
        State derivative per N m of each element's moment ``phi``.
    d_n : ndarray (p, n_e)
        Output feedthrough of ``phi`` (accelerations, loads, actuator moments).
    c_n, c_rate : ndarray (n_e, n)
        Rotation ``s`` [rad] and its rate [rad/s] of each element.
    elements : HingeElements
    x_of_rotation : ndarray (n, n_e)
        Initial state of a static rotation of the elements (the structure deflected by moments
        at the elements alone, at rest): ``x0 = x_of_rotation @ s0``.
    """

    plant: object
    b_n: np.ndarray
    d_n: np.ndarray
    c_n: np.ndarray
    c_rate: np.ndarray
    elements: HingeElements
    x_of_rotation: np.ndarray

    @property
    def speed(self) -> float:
        return float(self.plant.speed)

    def initial_state(self, rotation) -> np.ndarray:
        """State of the structure at rest with the elements rotated by ``rotation`` [rad]
        (one value for all, or one per element)."""
        s0 = np.broadcast_to(np.asarray(rotation, dtype=float), (self.elements.n,))
        return self.x_of_rotation @ s0


def _static_shape(Ks: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """Displacements ``q = X s`` with ``rows @ q = s`` under moments at the elements only."""
    g = np.linalg.solve(Ks, rows.T)
    return g @ np.linalg.inv(rows @ g)


def nonlinear_plant(
    wing,
    hinges: Sequence[NonlinearHinge],
    speed: float,
    density: float,
    inputs: Sequence[str] = (),
    outputs: Sequence[str] | None = None,
    **statespace_options,
) -> NonlinearPlant:
    """The nonlinear plant of a wing at one flight condition.

    Parameters
    ----------
    wing : Wing or AeroelasticModel
    hinges : sequence of NonlinearHinge
        Laws on actuators (or on every actuator of a surface).
    speed, density : float
        [m/s], [kg/m^3].
    inputs : sequence of str
        The controller's inputs (default none: the open loop).
    outputs : sequence of str, optional
        Recorded outputs and the controller's sensors (default the tip accelerometers and
        twist); ``<actuator>_rotation`` of every element is added.
    **statespace_options
        ``n_elements``, ``wagner``, ``servo``, ``n_modes``, ``mach``, ``balanced`` of
        :func:`aeroservo.linear.models.statespace`.
    """
    from .models import _model_for, statespace

    model = _model_for(
        wing,
        statespace_options.pop("n_elements", 10),
        statespace_options.pop("wagner", "rt_jones"),
    )
    elements = hinge_elements(model, hinges)
    inputs = check_names("inputs", list(inputs), empty=True)
    outputs = list(DEFAULT_OUTPUTS) if outputs is None else check_names("outputs", outputs)
    rot = [f"{n}_rotation" for n in elements.names]
    outs = outputs + [r for r in rot if r not in outputs]
    full = statespace(
        model, speed, density, inputs + hinge_inputs(elements), outs + hinge_rates(elements),
        **statespace_options,
    )  # fmt: skip
    if statespace_options.get("n_modes") is not None:
        _check_truncation(full, model, speed, density, elements, rot, statespace_options)
    return split_plant(full, inputs, outs, elements, full.builder)


TRUNCATION_TOLERANCE = 0.02
"""Largest relative error of the hinge compliance (rotation per nonlinear moment) a modal
model may have before :func:`nonlinear_plant` warns (a march's rotations follow it: on the
Goland aileron at 6 modes, 23 % off statically and 6.5 % off in a freeplay march)."""


def _check_truncation(reduced, model, speed, density, elements, rot, options) -> None:
    """Warn when a modal model's hinge compliance (each element's rotation per its own
    nonlinear moment, statically and at half its four lowest modal frequencies) is more than
    :data:`TRUNCATION_TOLERANCE` off the full model's: the rotations a nonlinear march finds
    follow that compliance (6-23 % off at ``n_modes = 6`` on the Goland aileron, issue 40)."""
    import warnings

    from .models import statespace

    full_opts = {k: v for k, v in options.items() if k != "n_modes"}
    ins = hinge_inputs(elements)
    full = statespace(model, speed, density, ins, rot, **full_opts)
    poles = np.linalg.eigvals(np.asarray(reduced.A))
    # statically and between the lowest modes (not at a resonance, where a small shift of a
    # frequency is a large error of the compliance and says nothing of the truncation)
    freqs = np.unique(np.round(np.abs(poles.imag[poles.imag > 1e-6]), 6))[:4]
    worst = (0.0, 0.0, "")
    for w in (0.0, *(0.5 * freqs)):
        g_full = _gain(full, ins, rot, w)
        g_red = _gain(reduced, ins, rot, w)
        for i, name in enumerate(elements.names):
            ref = abs(g_full[i, i])
            if ref > 0:
                err = abs(g_red[i, i] - g_full[i, i]) / ref
                if err > worst[0]:
                    worst = (err, w / (2 * np.pi), name)
    if worst[0] > TRUNCATION_TOLERANCE:
        where = "statically" if worst[1] == 0 else f"at {worst[1]:.3g} Hz"
        warnings.warn(
            f"nonlinear_plant: n_modes = {options['n_modes']} gives the hinge compliance of "
            f"{worst[2]} {worst[0]:.1%} off the full model {where} (a march's rotations may be "
            "off by up to as much): raise n_modes or leave it out",
            UserWarning,
            stacklevel=3,
        )


def _gain(sys, inputs: list, outputs: list, w: float) -> np.ndarray:
    """The frequency response of ``sys`` from ``inputs`` to ``outputs`` at ``w`` [rad/s]."""
    i = [list(sys.input_labels).index(n) for n in inputs]
    o = [list(sys.output_labels).index(n) for n in outputs]
    A, B, C, D = (np.asarray(m) for m in (sys.A, sys.B, sys.C, sys.D))
    x = np.linalg.solve(1j * w * np.eye(A.shape[0]) - A, B[:, i])
    return C[o] @ x + D[np.ix_(o, i)]


def hinge_inputs(elements: HingeElements) -> list[str]:
    """The moment inputs of the elements (``<actuator>_nonlinear_moment``)."""
    return [f"{n}_nonlinear_moment" for n in elements.names]


def hinge_rates(elements: HingeElements) -> list[str]:
    """The rotation-rate outputs of the elements (``<actuator>_rotation_rate``)."""
    return [f"{n}_rotation_rate" for n in elements.names]


def split_plant(full, inputs: list, outs: list, elements: HingeElements, builder) -> NonlinearPlant:
    """The plant and the element channels from a model ``full`` whose inputs are ``inputs``
    then the element moments, and outputs ``outs`` (element rotations among them) then the
    element rates, built by ``builder`` (states: its states first, any filter states after)."""
    import control

    m, p, e = len(inputs), len(outs), elements.n
    plant = control.StateSpace(
        full.A,
        full.B[:, :m],
        full.C[:p],
        full.D[:p, :m],
        states=list(full.state_labels),
        inputs=inputs,
        outputs=outs,
        name=full.name,
    )
    tag(plant, full.speed, full.density, full.signal_units)
    plant.builder = builder
    scaling = np.ones(full.nstates)
    scaling[: builder.n_states] = getattr(full, "state_scaling", builder.state_scaling)[
        : builder.n_states
    ]
    plant.state_scaling = scaling
    rows = elements.rows if builder.basis is None else elements.rows @ builder.basis
    ks = builder.system.Ks.toarray()
    n_q = ks.shape[0]
    x_rot = np.zeros((full.nstates, e))
    x_rot[:n_q] = _static_shape(ks, rows) / scaling[:n_q, None]
    rot = [outs.index(f"{n}_rotation") for n in elements.names]
    return NonlinearPlant(
        plant, full.B[:, m:], full.D[:p, m:], full.C[rot], full.C[p:], elements, x_rot
    )


def section_plant(section, hinges: Sequence[NonlinearHinge], speed: float, density: float):
    """The nonlinear plant of a typical section with a flap.

    Inputs ``flap_hinge_moment`` [N m per m]; outputs ``plunge`` [m], ``pitch`` [rad],
    ``flap_rotation`` [rad] and their rates (``plunge_rate``, ...). States: the section's
    first-order states (physical units).
    """
    import control

    v = check_number("speed", speed, unit="m/s", lo=0.0, lo_open=True, hi=1e3)
    elements = hinge_elements(section, hinges)
    if section.hinge is None:
        raise InputError("section: no flap")
    system = section.system(density)
    A = system.state_matrix(v)
    b_n, c_n, c_rate = elements.lure(system)
    n, n_q = A.shape[0], system.n_q
    C = np.zeros((6, n))
    C[:3, :3] = np.eye(3)
    C[3:, 3:6] = np.eye(3)
    names = ["plunge", "pitch", "flap_rotation"]
    outs = names + [f"{s}_rate" for s in names]
    plant = control.StateSpace(
        A,
        b_n,
        C,
        np.zeros((6, 1)),
        states=list(system.state_labels),
        inputs=["flap_hinge_moment"],
        outputs=outs,
        name=system_name("section", v),
    )
    units = dict(zip(outs, ["m", "rad", "rad", "m/s", "rad/s", "rad/s"], strict=True))
    tag(plant, v, float(density), units | {"flap_hinge_moment": "N m"})
    plant.state_scaling = np.ones(n)
    x_rot = np.zeros((n, 1))
    x_rot[:n_q] = _static_shape(system.Ks.toarray(), elements.rows)
    return NonlinearPlant(plant, b_n, np.zeros((6, 1)), c_n, c_rate, elements, x_rot)
