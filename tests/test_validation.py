"""Bad input gets one clear error naming the field, the value and the allowed range."""

import dataclasses

import pytest

import aeroservo as aes
from aeroservo.structure import Actuator, ControlSurface, Segment, Wing

SEG = dict(
    start=0.0,
    end=6.0,
    semichord=0.9,
    a=-0.34,
    mass=35.0,
    x_alpha=0.2,
    inertia=8.6,
    EI=9.7e6,
    GJ=9.9e5,
)
CS = dict(
    name="aileron",
    start=3.6,
    end=6.0,
    hinge=0.6,
    static_moment=0.3,
    inertia=0.09,
    hinge_stiffness=500.0,
)


@pytest.mark.parametrize(
    "field,value,match",
    [
        ("EI", -1.0, r"EI = -1: allowed range is \[1e-06, 1e\+13\] \[N m\^2\]"),
        ("EI", 1e308, r"EI = 1e\+308: allowed range"),
        ("GJ", 1e-300, r"GJ = 1e-300: allowed range"),
        ("mass", 1e7, r"mass = 1e\+07: allowed range"),
        ("GJ", 0.0, "GJ = 0"),
        ("mass", float("nan"), "mass = nan: must be a finite number"),
        ("semichord", "wide", "semichord = 'wide': expected a real number"),
        ("a", 1.5, r"a = 1.5: allowed range is \[-1, 1\]"),
        ("x_alpha", 1.5, "x_alpha = 1.5"),
        ("inertia", 0.5, "inertia = 0.5"),
        ("end", -1.0, "end = -1"),
        ("EI", True, "expected a real number"),
    ],
)
def test_segment_errors(field, value, match):
    with pytest.raises(aes.InputError, match=match):
        Segment(**(SEG | {field: value}))


@pytest.mark.parametrize(
    "changes,match",
    [
        ({"hinge": 1.0}, "hinge = 1"),
        ({"hinge": -0.5}, "must not lie ahead of the elastic axis"),
        ({"inertia": -0.1}, "inertia = -0.1"),
        ({"hinge_stiffness": 0.0}, "would float freely"),
        ({"name": "my aileron"}, "must be an identifier"),
        ({"static_moment": 5.0}, "not positive definite"),
        ({"start": 5.0, "end": 7.0}, "outside the wing"),
        ({"actuators": (Actuator(2.0, 1e3),)}, r"actuators\[0\].station = 2"),
    ],
)
def test_control_surface_errors(changes, match):
    with pytest.raises(aes.InputError, match=match):
        Wing(6.0, [Segment(**SEG)], [ControlSurface(**(CS | changes))])


def test_overlapping_surfaces():
    a = ControlSurface(**CS)
    b = ControlSurface(**(CS | {"name": "spoiler", "start": 5.0}))
    with pytest.raises(aes.InputError, match="overlaps 'aileron'"):
        Wing(6.0, [Segment(**SEG)], [a, b])


def test_duplicate_surface_names():
    a = ControlSurface(**(CS | {"end": 4.5}))
    b = ControlSurface(**(CS | {"start": 4.5}))
    with pytest.raises(aes.InputError, match="duplicate"):
        Wing(6.0, [Segment(**SEG)], [a, b])


@pytest.mark.parametrize(
    "segments,match",
    [
        ([], "at least one segment"),
        (
            [Segment(**(SEG | {"end": 3.0})), Segment(**(SEG | {"start": 3.5}))],
            "must equal the end of the previous",
        ),
        ([Segment(**(SEG | {"end": 5.0}))], "must equal wing.span"),
    ],
)
def test_segment_tiling(segments, match):
    with pytest.raises(aes.InputError, match=match):
        Wing(6.0, segments)


def test_negative_actuator_stiffness():
    with pytest.raises(aes.InputError, match="stiffness = -5"):
        Actuator(4.0, -5.0)


@pytest.mark.parametrize(
    "kw,match",
    [
        ({"n_elements": 1}, "at least 2 are needed"),
        ({"n_elements": 0}, "n_elements = 0"),
        ({"wagner": "x"}, "unknown set"),
    ],
)
def test_model_errors(kw, match):
    wing = Wing(6.0, [Segment(**SEG)], [ControlSurface(**CS)])
    with pytest.raises(aes.InputError, match=match):
        aes.AeroelasticModel(wing, **kw)


def test_unknown_surface_name():
    wing = Wing(6.0, [Segment(**SEG)], [ControlSurface(**CS)])
    with pytest.raises(aes.InputError, match="'rudder': unknown; this wing has \\['aileron'\\]"):
        wing.surface("rudder")


def test_frozen_models_validate_on_replace():
    seg = Segment(**SEG)
    with pytest.raises(aes.InputError, match="GJ"):
        dataclasses.replace(seg, GJ=-3.0)
