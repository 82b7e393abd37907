"""The name of an exported model and the attributes aeroservo puts on it (speed, density, units)."""

from __future__ import annotations

import re

__all__ = ["system_name", "tag", "carry_tags"]

TAGS = ("speed", "density", "signal_units")
"""The attributes aeroservo puts on an exported model."""


def system_name(wing_name: str, speed: float) -> str:
    """python-control system name (no dots allowed): e.g. ``goland_wing_V137p4``."""
    slug = re.sub(r"\W+", "_", wing_name).strip("_").lower() or "wing"
    return f"{slug}_V{speed:.6g}".replace(".", "p").replace("-", "m")


def tag(sys, speed: float, density: float, units: dict) -> None:
    sys.speed = speed
    sys.density = density
    sys.signal_units = dict(units)


def carry_tags(src, dst):
    """``dst`` with the tags ``src`` has (a model rebuilt from another's matrices); returns it."""
    for attr in TAGS:
        if hasattr(src, attr):
            setattr(dst, attr, getattr(src, attr))
    return dst
