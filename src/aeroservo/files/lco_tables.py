"""The tables of a limit-cycle scenario (``kind = "lco"``): a typical section (``[section]``) or
a wing, the optional ``[controller]``, ``[lco]`` with its ``[[lco.hinges]]`` (or the wing
file's ``[[hinges]]``), and the checks that need the model (hinge targets, the loop's signals).
Called by :func:`aeroservo.files.scenario_file.scenario_from_dict`; every error names the file,
the key and the value.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import RANGES, InputError
from ..simulate.hinges.march import MAX_HINGE_SAMPLES
from ..studies.lco.study import study_steps
from ..studies.scenario import Scenario
from ..studies.study_options import LCOOptions
from .hinge_tables import check_targets, hinges_from_list
from .scenario_tables import controller
from .toml_tables import Table

__all__ = ["section_table", "lco_tables", "lco_cross_check", "SECTION_KEYS", "MAX_SPEEDS"]

SECTION_KEYS = (
    "semichord",
    "a",
    "mass",
    "x_alpha",
    "inertia",
    "k_plunge",
    "k_pitch",
    "hinge",
    "flap_static_moment",
    "flap_inertia",
    "k_flap",
)
"""Keys of a ``[section]`` table of :class:`~aeroservo.system.section.TypicalSection`
parameters (all required but ``flap_static_moment``, default 0)."""

_SPRING = {"lo": 0.0, "lo_open": True, "hi": 1e12}
SECTION_RANGES = {
    "semichord": {"quantity": "semichord"},
    "a": {"lo": -1.0, "hi": 1.0},
    "mass": {"quantity": "mass_per_length"},
    "x_alpha": {"lo": -2.0, "hi": 2.0},
    "inertia": {"quantity": "inertia_per_length"},
    "k_plunge": {"unit": "N/m per m", **_SPRING},
    "k_pitch": {"unit": "N m/rad per m", **_SPRING},
    "hinge": {"lo": -1.0, "hi": 1.0, "hi_open": True},
    "flap_static_moment": {"quantity": "static_moment"},
    "flap_inertia": {"quantity": "inertia_per_length"},
    "k_flap": {"quantity": "hinge_stiffness"},
}
"""The physical range of each ``[section]`` key (per unit span; the wing file's where it has
one: ``aeroservo.errors.RANGES``): a value beyond it is a unit error. The typical section
checks what depends on other keys (``x_alpha`` within the chord, the hinge aft of the
elastic axis, a positive-definite mass matrix)."""

_UNITS = {
    k: r.get("unit") or RANGES[r["quantity"]].unit
    for k, r in SECTION_RANGES.items()
    if r.get("unit") or "quantity" in r
}
"""The unit of each dimensional ``[section]`` key."""
MAX_SPEEDS = 1000
"""Most speeds of one study."""

MAX_AMPLITUDE = 1.0
"""Largest initial rotation [rad] (57 deg)."""

UNUSED = {
    "model": ("v_max", "pk"),
    "simulation": (
        "duration",
        "seed",
        "sensor_noise",
        "expect_failure",
        "expect_unstable",
        "delay",
    ),
}
"""Keys of the shared tables a limit-cycle scenario has no use for (an error, not ignored):
the march length is ``lco.duration`` and the march has no computational delay."""

_CLOSED_ONLY = (
    ("simulation", "sample_rate", "the controller's rate; the open loop steps at lco.dt"),
    ("model", "design_modes", "the controller's design model"),
    ("model", "gust", "the gust input of the controller's design model"),
)
"""Keys only a closed loop uses: ``(table, key, why)``."""


def section_table(top: Table, kw: dict) -> None:
    """``[section]``: ``builtin = "conner"`` (with ``damped``) or the parameters of a typical
    section (SI, per unit span), with the scenario's ``model.wagner`` and ``[damping]``.
    Sets ``kw["section"]`` (the wing is None)."""
    from dataclasses import replace

    from ..system.section import TypicalSection, conner_section

    if top.has("wing"):
        top.fail("section", top.data["section"], "give [wing] or [section], not both")
    st = top.table("section")
    md = top.table("model")
    for key in md.data:
        if key != "wagner" and (key, md.data[key]) != ("aero", "strip"):
            md.fail(key, md.data[key], "not used with a [section] (only model.wagner)")
    for name in ("signals", "controller", "simulation"):
        if top.has(name):
            top.fail(name, top.data[name], "a typical section has no control loop: give a [wing]")
    wagner = kw.get("wagner", "rt_jones")
    damping = kw.get("damping")
    try:
        if st.has("builtin"):
            st.check_keys(("builtin",), ("damped",))
            st.string("builtin", choices=("conner",))
            damped = st.boolean("damped", False)
            if damped and damping is not None:
                st.fail("damped", damped, "give section.damped or a [damping] table, not both")
            sec = conner_section(damped=damped, wagner=wagner)
            kw["section"] = sec if damping is None else replace(sec, damping=damping)
            kw["wing_source"] = "builtin section conner" + (
                " (damped)" if damped else f" (damping {damping.describe()})" if damping else ""
            )
            return
        st.check_keys(tuple(k for k in SECTION_KEYS if k != "flap_static_moment"), SECTION_KEYS)
        vals = {k: st.number(k, **SECTION_RANGES[k]) for k in SECTION_KEYS if st.has(k)}
        if vals["k_flap"] == 0.0:  # the nonlinear law scales this spring
            st.fail(
                "k_flap", 0.0, "the nonlinear hinge law acts on this spring (its k): give it > 0"
            )
        kw["section"] = TypicalSection(**vals, wagner=wagner, damping=damping)
        kw["wing_source"] = "section"
    except InputError as exc:
        msg = str(exc)
        raise InputError(msg if msg.startswith(f"{top.file}: ") else f"{top.file}: {msg}") from None
    except (ArithmeticError, ValueError, np.linalg.LinAlgError) as exc:  # e.g. huge numbers
        st.fail(None, st.data, f"not a valid section ({' '.join(str(exc).split())[:80]})")


def lco_tables(top: Table, base: Path, kw: dict) -> None:
    """Read ``[controller]`` and ``[lco]`` of a limit-cycle scenario into ``kw`` (the
    :class:`~aeroservo.studies.scenario.Scenario` keywords read so far). Without
    ``controller.spec`` (or with a controller of type ``"none"``) the study is open loop, and
    ``[flight]`` takes the density only."""
    for name, keys in UNUSED.items():
        tbl = top.table(name)
        for key in keys:
            if tbl.has(key):
                tbl.fail(key, tbl.data[key], "not used by a scenario of kind 'lco'")
    fl = top.table("flight")
    ct = top.table("controller").check_keys((), ("spec",))
    if ct.has("spec"):
        kw["controller"] = controller(ct, ct.path("spec", base, required=True))
    closed = ct.has("spec") and kw["controller"].type != "none"
    if closed and kw.get("speed") is None and kw.get("speed_factor") is None:
        raise InputError(
            f"{top.file}: flight.speed: missing; give speed [m/s] or speed_factor (x the "
            "open-loop flutter speed): the controller's design point"
        )
    if not closed:
        only = "only with controller.spec" + (
            " of a type other than 'none'" if ct.has("spec") else ""
        )
        for key in ("speed", "speed_factor"):
            if fl.has(key):
                fl.fail(
                    key,
                    fl.data[key],
                    f"{only} (the controller's design speed); the study's speeds are lco.speeds",
                )
        if top.has("signals"):
            top.fail("signals", top.data["signals"], f"{only} (the loop's)")
        for name, key, why in _CLOSED_ONLY:
            tbl = top.table(name)
            if tbl.has(key):
                tbl.fail(key, tbl.data[key], f"{only} ({why})")
    lt = top.table("lco", required=True)
    kw["options"] = LCOOptions(**lco_table(lt, kw, closed=closed))


def lco_table(lt: Table, kw: dict, closed: bool) -> dict:
    """``[lco]``: speeds, initial rotations, march settings and the hinges."""
    lt.check_keys(
        ("speeds", "amplitudes"),
        (
            "duration",
            "dt",
            "settle",
            "continuation",
            "history",
            "workers",
            "describing",
            "hinges",
        ),
    )
    out: dict = {"speeds": _speeds(lt)}
    amps = lt.numbers("amplitudes", unit="rad", lo=0.0, lo_open=True, hi=MAX_AMPLITUDE)
    if len(set(amps)) != len(amps):
        lt.fail("amplitudes", lt.data["amplitudes"], "values must not repeat")
    out["amplitudes"] = tuple(amps)
    out["duration"] = lt.number("duration", 30.0, quantity="duration")
    if closed and lt.has("dt"):
        lt.fail("dt", lt.data["dt"], "the closed loop steps at 1/simulation.sample_rate")
    out["dt"] = lt.number("dt", 1e-3, unit="s", lo=1e-6, hi=0.1)
    step = 1.0 / kw["sample_rate"] if closed else out["dt"]
    steps = round(out["duration"] / step)  # as the march counts them
    if not 1 <= steps <= MAX_HINGE_SAMPLES:
        lt.fail(
            "duration",
            out["duration"],
            f"{steps} steps of {step:g} s; a march takes 1 to {MAX_HINGE_SAMPLES}",
        )
    out["settle"] = lt.number("settle", 0.5, lo=0.0, hi=0.9)
    out["continuation"] = lt.boolean("continuation", True)
    try:
        n_v, n_a = len(out["speeds"]), len(out["amplitudes"])
        study_steps(n_v, n_a, out["continuation"], out["duration"], step)
    except InputError as exc:
        lt.fail("duration", out["duration"], str(exc))
    out["history"] = lt.number(
        "history", min(2.0, out["duration"]), unit="s", lo=0.0, hi=out["duration"]
    )
    out["workers"] = lt.integer("workers", 0, lo=0, hi=256)
    out["describing"] = lt.boolean("describing", True)
    src = kw.get("wing_source", "")
    in_wing = ()
    if kw.get("wing") is not None and src.endswith(".toml"):
        from .wing_file import load_hinges

        try:  # already checked when the wing was read
            in_wing = load_hinges(src)
        except InputError as exc:  # pragma: no cover - the wing file changed meanwhile
            raise InputError(f"{lt.file}: wing.file -> {exc}") from None
    if lt.has("hinges"):  # the scenario's hinges win over the wing file's
        out["hinges"] = hinges_from_list(lt.data["hinges"], lt.file, lt.key_name("hinges"))
        out["hinges_source"] = "lco.hinges"
        out["wing_hinges_replaced"] = bool(in_wing)
        return out
    if in_wing:
        out["hinges"], out["hinges_source"] = in_wing, f"{src} [[hinges]]"
        out["wing_hinges_replaced"] = False
    if not out.get("hinges"):
        raise InputError(
            f"{lt.file}: lco.hinges: missing; give [[lco.hinges]] tables (target, law, gap or "
            "coefficient)"
            + ("" if kw.get("section") is not None else " or [[hinges]] in the wing file")
        )
    return out


def _speeds(lt: Table) -> tuple:
    """``speeds``: increasing speeds [m/s], or ``{start, stop, num}`` (evenly spaced)."""
    if isinstance(lt.data["speeds"], dict):
        st = lt.table("speeds").check_keys(("start", "stop", "num"))
        start = st.number("start", quantity="flight_speed", required=True)
        stop = st.number("stop", quantity="flight_speed", required=True)
        num = st.integer("num", lo=2, hi=MAX_SPEEDS, required=True)
        if stop <= start:
            st.fail("stop", stop, f"must be above start = {start:g} m/s")
        return tuple(float(v) for v in np.linspace(start, stop, num))
    v = lt.numbers("speeds", quantity="flight_speed", increasing=True)
    if len(v) > MAX_SPEEDS:
        lt.fail("speeds", f"{len(v)} values", f"at most {MAX_SPEEDS} speeds")
    return tuple(v)


def lco_cross_check(s: Scenario, top: Table) -> None:
    """Checks that need the model: each hinge's target on the wing (or ``"flap"``, one hinge,
    on a section with a flap); with a controller, the loop's signals and the controller's."""
    from ..design.loop import check_spec_signals
    from .scenario_checks import check_loop_signals

    lco = s.lco
    where = lco.hinges_source
    key = "lco.hinges" if where == "lco.hinges" else "hinges"
    file = top.file if key == "lco.hinges" else f"{top.file}: wing.file -> {s.wing_source}"
    if s.section is not None:  # a [section] table always has a flap (hinge is required)
        for i, h in enumerate(lco.hinges):
            if h.target != "flap":
                raise InputError(
                    f"{file}: {key}[{i}].target = {h.target!r}: a typical section has one "
                    "nonlinear hinge, target 'flap'"
                )
        if len(lco.hinges) > 1:
            raise InputError(f"{file}: {key}[1]: a typical section has one nonlinear hinge")
        return
    check_targets(lco.hinges, s.wing, file, key)
    if s.controller is None or s.controller.type == "none":
        return
    surfaces = {cs.name: [a.name for a in cs.actuators] for cs in s.wing.control_surfaces}
    actuators = {a for acts in surfaces.values() for a in acts}
    for i, h in enumerate(lco.hinges):  # as check_targets resolves them
        for a in [h.target] if h.target in actuators else surfaces[h.target]:
            if f"{a}_nonlinear_moment" in s.controls:
                top.table("signals").fail(
                    "controls",
                    list(s.controls),
                    f"'{a}_nonlinear_moment' is driven by the hinge law of {key}[{i}], not by "
                    "a controller",
                )
    model = s.model()
    check_loop_signals(s, s.wing, model, top)
    if s.sensor_filter is not None and s.sensor_filter >= 0.5 * s.sample_rate:
        top.table("signals").fail(
            "sensor_filter",
            s.sensor_filter,
            f"must be below the Nyquist frequency {0.5 * s.sample_rate:g} Hz of "
            "simulation.sample_rate",
        )
    try:
        check_spec_signals(s.controller, s.controls, s.sensors, s.outputs)
    except InputError as exc:
        raise InputError(f"{s.source}: controller.spec -> {exc}") from None
