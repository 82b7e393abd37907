"""The shipped scenarios as they were before the loop was built as flown (issue 38 item 1): an
ideal actuator, no computational delay and the H-infinity weights chosen for that loop.

Tests of mechanisms that do not depend on the actuator (recoverable sets, black-box margins,
verdict texts) keep the numbers they were written against through these helpers; the loop as
built is checked in ``tests/test_actuator.py`` and by the shipped-scenario tests.
"""

from __future__ import annotations

import dataclasses

from aeroservo.design.hinf import HinfWeights

HM = "aileron_hinge_moment"

IDEAL_HINF = HinfWeights(
    order=24,
    sensitivity_peak=1.83,
    sensitivity_floor=0.77,
    bandwidth=1.8,
    control_weight=0.232,
    complementary_peak=2.36,
    roll_off=41.4,
    gamma_factor=2.08,
)
"""The H-infinity weights searched for the ideal-actuator loop without delay (before 2026-12)."""


def ideal(sc):
    """A scenario with an ideal actuator and no computational delay; an H-infinity spec gets
    :data:`IDEAL_HINF` and its former nominal magnitudes."""
    sc = dataclasses.replace(sc, actuator=None, delay=False)
    spec = sc.controller
    if spec is not None and spec.type == "hinf":
        sensors = {**spec.sensor_scales, "tip_twist": 3.7e-4}
        spec = dataclasses.replace(
            spec, hinf=IDEAL_HINF, bryson_inputs={HM: 192.0}, sensor_scales=sensors
        )
        sc = dataclasses.replace(sc, controller=spec)
    return sc


def ideal_text(text: str) -> str:
    """A shipped scenario file's text without its ``[actuator]`` table and with
    ``delay = false`` (the file counterpart of :func:`ideal`)."""
    if "[actuator]" in text:
        start = text.index("[actuator]")
        end = text.index("\n[", start) + 1
        text = text[:start] + text[end:]
    return text.replace("delay = true ", "delay = false")


IDEAL_HINF_TEXT = {
    "inputs = { aileron_hinge_moment = 100.0 }": "inputs = { aileron_hinge_moment = 192.0 }",
    "tip_twist = 4.3e-4 }": "tip_twist = 3.7e-4 }",
    "bandwidth = 0.3 ": "bandwidth = 1.8 ",
    "control_weight = 0.5 ": "control_weight = 0.232 ",
    "roll_off = 9.0 ": "roll_off = 41.4 ",
}
"""Edits of ``controllers/hinf.toml`` back to :data:`IDEAL_HINF`."""


def ideal_hinf_text(text: str) -> str:
    for old, new in IDEAL_HINF_TEXT.items():
        assert old in text, old
        text = text.replace(old, new)
    return text
