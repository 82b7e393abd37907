"""Whether a linear law can be built from what the sensors measure.

A state-feedback law (LQR, a static gain on plant states) commands ``u = -K x`` from the
plant's own states: the structural displacements and velocities, the aerodynamic lag states,
the gust states and the sensor filters' states. No sensor measures them; flown, such a law
needs an observer (an LQG, or an MPC with its estimator) or output feedback on the sensors.
Feeding back the gust states is a perfect measurement of the gust before it acts. A
compensator on the sensors (LQG, H-infinity, a brought compensator or a gain on sensors) is
realisable. :func:`unmeasured_feedback` counts, by kind, the plant states a law feeds back
directly; every report of a loop says it (issue 38).
"""

from __future__ import annotations

import re

import numpy as np

from ..errors import InputError
from .interface import controller_at, has_linear_law
from .sampled_loop import linear_law, plant_states

__all__ = ["unmeasured_feedback", "realisability_text", "refuse_unrealisable", "STATE_KINDS"]

STATE_KINDS = (
    (re.compile(r"^z\d+_"), "aerodynamic lag states"),
    (re.compile(r"^g\d+_"), "gust states"),
    (re.compile(r"_filter\d+$"), "sensor-filter states"),
    (re.compile(r"_actuator(_rate|_lag)?$"), "actuator states"),
    (re.compile(r"_dot$"), "structural velocities"),
)
"""Plant state names (``aeroservo.linear.tags``) by kind; the rest are structural
displacements."""


def _kind(name: str) -> str:
    for pattern, kind in STATE_KINDS:
        if pattern.search(name):
            return kind
    return "structural displacements"


def unmeasured_feedback(plant, controller) -> dict[str, int]:
    """How many plant states of each kind the controller feeds back directly (empty for a law
    on the sensors, or a Python law, whose inputs are the sensors)."""
    if not has_linear_law(controller):
        return {}
    ctrl = controller_at(controller, float(getattr(plant, "speed", np.nan)))
    names = plant_states(plant)
    law = linear_law(ctrl, names)
    if law.kind != "state":
        return {}
    used = np.flatnonzero(np.any(np.asarray(law.D) != 0.0, axis=0))
    out: dict[str, int] = {}
    for i in used:
        kind = _kind(names[i]) if i < len(names) else "structural displacements"
        out[kind] = out.get(kind, 0) + 1
    return out


def realisability_text(counts: dict[str, int]) -> str:
    """One line on a law that feeds back unmeasured states ('' for a realisable one)."""
    if not counts:
        return ""
    parts = ", ".join(f"{n} {kind}" for kind, n in counts.items())
    gust = " (the gust states: a perfect gust measurement)" if "gust states" in counts else ""
    return (
        f"the law feeds back {parts} that no sensor measures{gust}: not realisable as built; "
        "an observer (LQG) or output feedback on the sensors is"
    )


def refuse_unrealisable(source: str, plant, controller) -> None:
    """A scenario with ``controller.realisable = true``: refuse a law that feeds back states
    no sensor measures (one line naming the file and the key)."""
    counts = unmeasured_feedback(plant, controller)
    if counts:
        raise InputError(f"{source}: controller.realisable = true: {realisability_text(counts)}")
