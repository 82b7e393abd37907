"""The wing parameters a sensitivity differentiates, by their wing-file names, and a wing with
some of them changed (:mod:`.sensitivity`, :mod:`.sensitivity_fd`, the optimiser)."""

from __future__ import annotations

from dataclasses import replace

from ..system.derivatives import PARAMETERS
from .result import FlutterResult

__all__ = ["parameter_values", "with_parameters", "TIE", "TOUCH"]

TIE = 1e-3
"""Two onsets closer than this relative speed: a mode switch, not differentiable."""

TOUCH = 1e-5
"""``Re(dlambda/dV) V / |lambda|`` below this: the branch only touches the axis."""


def parameter_values(wing) -> dict[str, tuple[str, tuple[int, ...], str, float]]:
    """Every wing parameter offered, by its wing-file name, with ``(owner, index, key, value)``."""
    out: dict = {}
    for i, seg in enumerate(wing.segments):
        for key in PARAMETERS["segment"]:
            out[f"segments[{i}].{key}"] = ("segment", (i,), key, float(getattr(seg, key)))
    for k, cs in enumerate(wing.control_surfaces):
        for key in PARAMETERS["surface"]:
            out[f"control_surfaces[{k}].{key}"] = ("surface", (k,), key, float(getattr(cs, key)))
        for j, act in enumerate(cs.actuators):
            for key in PARAMETERS["actuator"]:
                name = f"control_surfaces[{k}].actuators[{j}].{key}"
                out[name] = ("actuator", (k, j), key, float(getattr(act, key)))
    for i, pm in enumerate(wing.masses):
        for key in PARAMETERS["mass"]:
            out[f"masses[{i}].{key}"] = ("mass", (i,), key, float(getattr(pm, key)))
    return out


def with_parameters(wing, values: dict):
    """The wing with parameters (wing-file names of :func:`parameter_values`) set to
    ``values`` (the wing's checks run again)."""
    table = parameter_values(wing)
    segs, surfaces, masses = list(wing.segments), list(wing.control_surfaces), list(wing.masses)
    for name, v in values.items():
        owner, idx, key, _ = table[name]
        if owner == "mass":
            masses[idx[0]] = replace(masses[idx[0]], **{key: v})
        elif owner == "segment":
            segs[idx[0]] = replace(segs[idx[0]], **{key: v})
        elif owner == "surface":
            surfaces[idx[0]] = replace(surfaces[idx[0]], **{key: v})
        else:
            cs = surfaces[idx[0]]
            acts = list(cs.actuators)
            acts[idx[1]] = replace(acts[idx[1]], **{key: v})
            surfaces[idx[0]] = replace(cs, actuators=tuple(acts))
    return replace(
        wing, segments=tuple(segs), control_surfaces=tuple(surfaces), masses=tuple(masses)
    )


def _tie(r: FlutterResult) -> str | None:
    """A reason the flutter speed is not differentiable, or None."""
    vf = r.flutter_speed
    onsets = [c for c in r.crossings if c.kind == "onset"]
    near = [c for c in onsets if c.mode != r.flutter.mode and abs(c.speed - vf) <= TIE * vf]
    if near:
        c = near[0]
        return (
            f"mode switch: branches {r.flutter.mode} and {c.mode} go unstable at {vf:.6g} and "
            f"{c.speed:.6g} m/s (within {TIE:g}); V_f is the smaller of two smooth functions"
        )
    return None
