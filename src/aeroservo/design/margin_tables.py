"""Loop margins (:class:`~aeroservo.design.margins.LoopMargins`) and margin sweeps
(:class:`~aeroservo.design.margin_sweep.MarginSweep`) as results of the common shape
(:mod:`aeroservo.result_shape`): their tables, summaries and their state as plain data and
arrays for a file (:mod:`aeroservo.files.result_state`)."""

from __future__ import annotations

import dataclasses

import numpy as np

from .margin_channel import ChannelMargins, MarginRequirement

__all__ = [
    "MARGIN_COLUMNS",
    "margins_table",
    "margins_summary",
    "margins_state",
    "margins_from_state",
    "sweep_table",
    "sweep_summary",
]

MARGIN_COLUMNS = (
    "gain_margin_db",
    "gain_reduction_margin_db",
    "phase_margin_deg",
    "delay_margin_s",
    "disk_margin",
    "disk_gain_margin_db",
    "disk_phase_margin_deg",
)
"""The margins of a break point in :func:`margins_table` (dB, dB, deg, s, -, dB, deg)."""

_ATTRIBUTE = {"delay_margin_s": "delay_margin"}


def requirement_text(req: MarginRequirement) -> str:
    """E.g. ``"6 dB, 45 deg at the inputs"``."""
    text = f"{req.gain_db:g} dB, {req.phase_deg:g} deg"
    if req.disk_alpha is not None:
        text = f"disk margin {req.disk_alpha:g}"
    if req.delay_ms is not None:
        text += f", delay {req.delay_ms:g} ms"
    return text + f" at the {', '.join(req.at)}"


def margins_table(lm):
    """One row per break point (each plant input, then each sensor): ``break_point``
    (``"input"``, ``"sensor"``), ``channel``, ``stable``, :data:`MARGIN_COLUMNS` (NaN where the
    closed loop is unstable; inf where a margin is unbounded), their frequencies [Hz] and
    ``meets`` (the requirement's figures)."""
    import pandas as pd

    rows = []
    for where, group in (("input", lm.channels), ("sensor", lm.sensors)):
        for name, ch in group.items():
            row = {"break_point": where, "channel": name, "stable": bool(ch.stable)}
            for q in MARGIN_COLUMNS:
                v = getattr(ch, _ATTRIBUTE.get(q, q))
                row[q] = float(v) if ch.stable else np.nan
            for q, f in (
                ("gain_reduction_frequency_hz", ch.gain_frequencies[0]),
                ("gain_increase_frequency_hz", ch.gain_frequencies[1]),
                ("phase_frequency_hz", ch.phase_frequency),
                ("delay_frequency_hz", ch.delay_frequency),
                ("disk_frequency_hz", ch.disk_frequency),
            ):
                row[q] = np.nan if f is None or not ch.stable else float(f)
            row["meets"] = not ch.violations(lm.requirement)
            rows.append(row)
    return pd.DataFrame(rows)


def _channel_line(ch) -> str:
    if not ch.stable:
        return "closed loop unstable"
    return (
        f"gain {ch.gain_margin_db:+.3g} / {ch.gain_reduction_margin_db:+.3g} dB, phase "
        f"{ch.phase_margin_deg:.3g} deg, delay {1e3 * ch.delay_margin:.3g} ms, disk "
        f"{ch.disk_margin:.3g}"
    )


def margins_summary(lm) -> str:
    """The requirement met or missed, then each break point's margins, a line each."""
    bad = lm.violations()
    head = f"loop margins at {lm.speed:.6g} m/s (sample period {lm.dt:.4g} s"
    head += ", one-sample delay" if lm.delay else ""
    head += f"{'; ' + lm.law if lm.law else ''}): "
    head += f"requirement ({requirement_text(lm.requirement)}) "
    head += "met" if not bad else "MISSED: " + "; ".join(bad)
    lines = [head, f"  break points: {lm.break_point}"]
    lines += [f"  input {c}: {_channel_line(ch)}" for c, ch in lm.channels.items()]
    lines += [f"  sensor {s}: {_channel_line(ch)}" for s, ch in lm.sensors.items()]
    for where, multi in (("inputs", lm.multiloop), ("sensors", lm.multiloop_outputs)):
        if multi.get("disk_margin") is not None:
            lines.append(
                f"  all {where} at once: disk {multi['disk_margin']:.3g} (+-"
                f"{multi['disk_gain_margin_db']:.3g} dB, +-{multi['disk_phase_margin_deg']:.3g} "
                f"deg; {multi.get('method', '')})"
            )
    sens = lm.sensitivity
    if "peak_S" in sens:
        lines.append(
            f"  peak |S| {sens['peak_S']:.3g} at {sens['peak_S_frequency']:.4g} Hz, peak |T| "
            f"{sens['peak_T']:.3g} at {sens['peak_T_frequency']:.4g} Hz"
        )
    return "\n".join(lines)


def _fields(obj) -> dict:
    return {f.name: getattr(obj, f.name) for f in dataclasses.fields(obj)}


def margins_state(lm) -> dict:
    """Every field of loop margins as plain data and arrays."""
    state = _fields(lm)
    state["channels"] = {k: _fields(v) for k, v in lm.channels.items()}
    state["sensors"] = {k: _fields(v) for k, v in lm.sensors.items()}
    state["requirement"] = requirement_state(lm.requirement)
    return state


def requirement_state(req: MarginRequirement) -> dict:
    """A requirement as plain data."""
    return _fields(req)


def _channel(d: dict) -> ChannelMargins:
    return ChannelMargins(**{**d, "gain_frequencies": tuple(d["gain_frequencies"])})


def requirement_from_state(d: dict) -> MarginRequirement:
    """The requirement of :func:`margins_state`."""
    return MarginRequirement(**{**d, "at": tuple(d["at"])})


def margins_from_state(cls, state: dict):
    """The ``cls`` (LoopMargins) of :func:`margins_state`."""
    return cls(
        **{
            **state,
            "channels": {k: _channel(v) for k, v in state["channels"].items()},
            "sensors": {k: _channel(v) for k, v in state["sensors"].items()},
            "requirement": requirement_from_state(state["requirement"]),
        }
    )


def sweep_table(sweep):
    """One row per control and speed: ``control``, ``speed_m_s``, the margins of
    :data:`aeroservo.design.margin_sweep.QUANTITIES` (NaN where unstable), ``stable``,
    ``meets``."""
    import pandas as pd

    frames = []
    for c in sweep.controls:
        t = sweep.table_for(c)
        frames.append(pd.DataFrame({"control": c, "speed_m_s": sweep.speeds, **t}))
    if not frames:
        return pd.DataFrame(columns=["control", "speed_m_s"])
    return pd.concat(frames, ignore_index=True)


def sweep_summary(sweep) -> str:
    """Per control: the speeds that meet the requirement and the least margins, a line each."""
    v = sweep.speeds
    lines = [
        f"loop margins at {v.size} speeds from {v[0]:.5g} to {v[-1]:.5g} m/s; requirement "
        f"{requirement_text(sweep.requirement)}"
        + ("" if sweep.reference_speed is None else f"; reference {sweep.reference_speed:.5g} m/s")
    ]
    for c in sweep.controls:
        t = sweep.table_for(c)
        rng = sweep.meeting_range(c)
        met = "not met at the reference" if rng is None else f"met {rng[0]:.5g}-{rng[1]:.5g} m/s"
        unstable = int(np.count_nonzero(~t["stable"]))
        lines.append(f"  {c}: requirement {met}; unstable at {unstable} of {v.size} speeds")
        if t["stable"].any():
            ok = t["stable"]
            lines.append(
                f"    least over the stable speeds: gain {np.min(t['gain_margin_db'][ok]):.3g} "
                f"dB, gain reduction {np.max(t['gain_reduction_margin_db'][ok]):.3g} dB, phase "
                f"{np.min(t['phase_margin_deg'][ok]):.3g} deg, disk "
                f"{np.min(t['disk_margin'][ok]):.3g}"
            )
    return "\n".join(lines)
