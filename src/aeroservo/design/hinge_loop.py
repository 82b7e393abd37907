"""The plant of a flutter-suppression loop with nonlinear hinges (freeplay on its actuators).

The same states, scaling and sensor filters as :meth:`ControlLoop.plant`, so that any
controller designed on the loop reads and drives it unchanged, plus the channels of the
nonlinear hinges (:class:`aeroservo.linear.hinge_plant.NonlinearPlant`).
"""

from __future__ import annotations

from collections.abc import Sequence

from ..errors import InputError
from ..linear.hinge_plant import NonlinearPlant, hinge_inputs, hinge_rates, split_plant
from ..linear.state_space import StateSpaceBuilder
from ..system.hinge_elements import NonlinearHinge, hinge_elements

__all__ = ["loop_hinge_plant"]


def loop_hinge_plant(loop, hinges: Sequence[NonlinearHinge], speed: float) -> NonlinearPlant:
    """The nonlinear plant of ``loop`` (a :class:`~aeroservo.design.loop.ControlLoop`) at
    ``speed`` [m/s] with the nonlinear ``hinges``.

    Its outputs are the loop's outputs and each element's ``<actuator>_rotation`` [rad]. A loop
    with actuator dynamics is refused (the hinge march does not model them yet).
    """
    if getattr(loop, "actuators", None):
        raise InputError(
            f"loop_hinge_plant: the loop has actuator dynamics on {list(loop.actuators)}; the "
            "march with nonlinear hinges does not model them yet: build the loop without "
            "actuator= (an ideal actuator)"
        )
    elements = hinge_elements(loop.model, hinges)
    base = loop.plant_builder
    inputs = list(base.input_labels)
    outs = list(base.output_labels)
    outs += [f"{n}_rotation" for n in elements.names if f"{n}_rotation" not in outs]
    builder = StateSpaceBuilder(
        loop.model,
        loop.density,
        inputs + hinge_inputs(elements),
        outs + hinge_rates(elements),
        gust=base.gust,
        kussner=base.kussner,
    )
    builder._scaling = base.state_scaling  # the loop's state basis, exactly
    full = loop._filter(builder.at(speed))
    return split_plant(full, inputs, outs, elements, builder)
