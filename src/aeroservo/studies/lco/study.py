"""Limit-cycle studies: what is swept, one march judged, and the sweeps over speed.

A :class:`LCOSetup` is a model with nonlinear hinges at one air density, in open loop or with
a controller designed once and held fixed at every speed. A study marches it

* from rest with each initial rotation at each speed (independent points), and
* along the speeds, up and down, each march starting from the last state of the one before
  (continuation: the branches a slow acceleration or deceleration follows, hysteresis),

and judges each march by :func:`aeroservo.simulate.lco_detect.classify` on the rotation of the
first nonlinear element. Everything here is picklable, so :mod:`aeroservo.studies.lco.run`
can send it to Dask workers.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from ...design.plant import Limits
from ...design.user_code import LawError
from ...errors import InputError, check_number
from ...simulate.hinges.march import march_hinges
from ...simulate.hinges.smooth_laws import DivergedMarch
from ...simulate.lco_detect import SUSTAINED, classify
from ...system.hinge_elements import NonlinearHinge, hinge_elements

__all__ = [
    "LCOSetup", "LCOSweep", "march_task", "study_steps", "HISTORY_SAMPLES", "MAX_STUDY_STEPS",
]  # fmt: skip

DIVERGED = 10.0
"""A growing march is called divergent once its reference rotation exceeds this many gaps
(below: "growing", not settled within the march)."""

ABSURD = 1e3
"""A march whose reference rotation reaches this many gaps (or a non-finite value) diverges,
whatever its verdict (a freeplay march above the gap-closed flutter speed grows without bound:
1e303 gaps in 30 s at 50 m/s on the Conner section)."""

HISTORY_SAMPLES = 4000
"""Samples kept of each march's last ``history`` seconds (for the example time histories)."""


@dataclass
class LCOSetup:
    """A model with nonlinear hinges, open or closed loop.

    Parameters
    ----------
    model : TypicalSection or AeroelasticModel
    hinges : sequence of NonlinearHinge
    density : float
        [kg/m^3].
    loop : ControlLoop, optional
        The loop of a wing whose plant the controller reads (needed with a controller on a
        wing; its model is used).
    controller : optional
        A designed controller (any of the controller interface), the same at every speed.
    limits : Limits, optional
        Actuator limits of the controller.
    outputs : sequence of str, optional
        Recorded outputs of a wing in open loop (default the tip sensors).
    name : str
    """

    model: object
    hinges: Sequence[NonlinearHinge]
    density: float = 1.225
    loop: object = None
    controller: object = None
    limits: Limits | None = None
    outputs: Sequence[str] | None = None
    name: str = "lco"

    def __post_init__(self) -> None:
        self.hinges = tuple(
            [self.hinges] if isinstance(self.hinges, NonlinearHinge) else self.hinges
        )
        check_number("density", self.density, unit="kg/m^3", lo=0.0, lo_open=True)
        if self.controller is not None and hasattr(self.model, "wing") and self.loop is None:
            raise InputError("LCOSetup: a controller on a wing needs its ControlLoop (loop=)")
        model = self.loop.model if self.loop is not None else self.model
        self.elements = hinge_elements(model, self.hinges)

    @property
    def reference(self) -> str:
        """The element judged (the first)."""
        return self.elements.names[0]

    @property
    def gap(self) -> float | None:
        """Total gap [rad] of the reference element's law (None for a cubic)."""
        return getattr(self.elements.laws[0], "gap", None)

    def plant(self, speed: float):
        """The :class:`~aeroservo.linear.hinge_plant.NonlinearPlant` at ``speed`` [m/s]."""
        from ...linear.hinge_plant import nonlinear_plant, section_plant

        if self.loop is not None:
            from ...design.hinge_loop import loop_hinge_plant

            return loop_hinge_plant(self.loop, self.hinges, speed)
        if hasattr(self.model, "wing"):
            return nonlinear_plant(
                self.model, self.hinges, speed, self.density, outputs=self.outputs
            )
        return section_plant(self.model, self.hinges, speed, self.density)


MAX_STUDY_STEPS = 1_000_000_000
"""Most time steps of one limit-cycle study, all its marches together (the Conner section's
shipped study takes 3.5e6, about 30 s on one core)."""


def study_steps(
    n_speeds: int, n_amplitudes: int, continuation: bool, duration: float, step: float
) -> int:
    """Total time steps of a study of ``n_speeds`` x ``n_amplitudes`` marches (and the two
    sweeps of ``continuation``) of ``duration`` [s] at ``step`` [s].

    Raises
    ------
    InputError
        Beyond :data:`MAX_STUDY_STEPS`, saying the total and the limit.
    """
    marches = n_speeds * n_amplitudes + (2 * n_speeds if continuation else 0)
    total = marches * max(round(duration / step), 1)
    if total > MAX_STUDY_STEPS:
        raise InputError(
            f"{n_speeds} speeds x {n_amplitudes} amplitudes"
            + (f" + 2 sweeps of {n_speeds} speeds" if continuation else "")
            + f" = {marches} marches of {duration:g} s at {step:g} s: {total:.4g} steps in "
            f"all, above the limit of {MAX_STUDY_STEPS:.0e} for one study (about 3 hours of a "
            "typical section's marches on one core): fewer speeds or amplitudes, or shorter "
            "marches"
        )
    return total


@dataclass(frozen=True)
class LCOSweep:
    """The marches of a study.

    Parameters
    ----------
    speeds : sequence of float
        Airspeeds [m/s], ascending.
    amplitudes : sequence of float
        Initial rotations [rad] of the elements (the structure at rest), one march each per
        speed.
    duration : float
        Length of each march [s].
    dt : float
        Record step of the open loop [s] (a controller's own period otherwise).
    settle : float
        Fraction of each march excluded as transient (the verdict is on the rest).
    continuation : bool
        Also sweep the speeds up and down, each march starting from the last state of the
        one before (the up sweep starts from the smallest amplitude, the down sweep from the
        largest).
    history : float
        Seconds kept of the end of each march for example time histories.
    extra : dict
        Settings carried into the result (a scenario's name, source, ...). With
        ``"open_loop_flutter_speed"`` [m/s] (the flutter speed with every spring closed; a
        scenario sets it), a march of the open loop with piecewise-linear laws that still grows
        at or above it is a divergence, not "growing": beyond the gaps the springs are linear
        and unstable there.
    """

    speeds: Sequence[float]
    amplitudes: Sequence[float]
    duration: float = 30.0
    dt: float = 1e-3
    settle: float = 0.5
    continuation: bool = True
    history: float = 2.0
    extra: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        v = np.asarray(self.speeds, dtype=float)
        if v.ndim != 1 or v.size == 0 or not np.all(np.isfinite(v)) or np.any(v <= 0):
            raise InputError(f"speeds = {self.speeds!r}: expected positive speeds [m/s]")
        if np.any(np.diff(v) <= 0):
            raise InputError("speeds: expected ascending speeds [m/s]")
        a = np.asarray(self.amplitudes, dtype=float)
        if a.ndim != 1 or a.size == 0 or not np.all(np.isfinite(a)) or np.any(a <= 0):
            raise InputError(
                f"amplitudes = {self.amplitudes!r}: expected positive initial rotations [rad]"
            )
        check_number("duration", self.duration, unit="s", lo=0.0, lo_open=True, hi=1e4)
        check_number("dt", self.dt, unit="s", lo=1e-6, hi=0.1)
        check_number("settle", self.settle, lo=0.0, hi=0.9)
        check_number("history", self.history, unit="s", lo=0.0, hi=self.duration)

    def steps(self, step: float) -> int:
        """Total time steps of the study at a march step of ``step`` [s] (the open loop's
        ``dt`` or the controller's period): :func:`study_steps`."""
        n_v, n_a = len(self.speeds), len(self.amplitudes)
        return study_steps(n_v, n_a, self.continuation, self.duration, step)

    def tasks(self) -> list[tuple]:
        """``(kind, speeds, amplitude)``: ``"point"`` marches and the two sweeps."""
        out = [("point", (v,), a) for v in self.speeds for a in self.amplitudes]
        if self.continuation:
            out.append(("up", tuple(self.speeds), min(self.amplitudes)))
            out.append(("down", tuple(self.speeds[::-1]), max(self.amplitudes)))
        return out


def march_task(shared: tuple, task: tuple) -> list[dict]:
    """The rows of one task (a point or a sweep) of ``shared = (setup, sweep)``."""
    setup, sweep = shared
    kind, speeds, amp = task
    rows, x = [], None
    for v in speeds:
        plant = setup.plant(v)
        kw = {"rotation0": amp} if x is None else {"x0": x}
        try:
            res = march_hinges(
                plant, setup.controller, duration=sweep.duration, dt=sweep.dt,
                limits=setup.limits, **kw,
            )  # fmt: skip
        except DivergedMarch as exc:  # the integrator of a smooth law gave up: diverged
            rows.append(_failed(kind, v, amp if x is None else np.nan, str(exc), "divergence"))
            x = None
            continue
        except LawError:  # a Python law that fails fails everywhere: the study stops
            raise
        except InputError as exc:
            rows.append(_failed(kind, v, amp if x is None else np.nan, str(exc)))
            x = None
            continue
        rows.append(_row(setup, sweep, kind, v, amp if x is None else np.nan, res))
        x = res.states[-1] if np.all(np.isfinite(res.states[-1])) else None
        if x is not None and rows[-1]["kind"] == "divergence":
            x = None  # do not carry a diverged state on: restart the sweep from rest
    return rows


def _row(setup, sweep, kind, speed, amp, res) -> dict:
    names = list(res.rotations)
    signals = {f"{n}_rotation": res.rotations[n] for n in names}
    for n in names:
        signals[f"{n}_hinge_moment"] = res.hinge_moments[n]
    for o, y in res.outputs.items():
        signals.setdefault(o, y)
    for c, y in res.applied.items():  # the moments the controller applied
        signals[f"{c}_applied"] = y
    ref = f"{setup.reference}_rotation"
    verdict = classify(res.t, signals, reference=ref, settle=sweep.settle)
    keep = res.t >= res.t[-1] - sweep.history
    step = max(1, int(np.ceil(keep.sum() / HISTORY_SAMPLES)))
    hist = {"t": res.t[keep][::step] - res.t[keep][0]}
    hist |= {k: v[keep][::step] for k, v in signals.items()}
    gap = setup.gap
    kind_, reason = verdict.kind, verdict.reason
    with np.errstate(over="ignore", invalid="ignore"):
        reach = float(np.max(np.abs(res.rotations[setup.reference] - _centre(setup))))
    if gap and not reach <= ABSURD * gap and kind_ != "divergence":  # nan fails the test too
        kind_ = "divergence"
        why = f"divergence: the rotation reaches {reach / gap:.3g} x gap (> {ABSURD:g})"
        reason = f"{why}; {reason}"
    vf = sweep.extra.get("open_loop_flutter_speed")
    unbounded = (  # open loop, piecewise-linear laws: beyond the gaps the springs are linear
        vf is not None and setup.controller is None and setup.elements.piecewise_linear
        and speed >= vf
    )  # fmt: skip
    moderate = kind_ == "divergence" and gap and np.isfinite(reach) and reach < DIVERGED * gap
    if moderate and unbounded:
        reason = (
            f"divergence at or above the flutter speed with every spring closed ({vf:.4g} m/s), "
            f"which no gap bounds (largest rotation {reach / gap:.3g} x gap); {reason}"
        )
    elif moderate:
        kind_ = "growing"  # not settled at the end of the march, and still moderate
        if reach < 0.5 * gap:
            what = f"unstable inside the gap: grows, largest rotation {reach / gap:.3g} x gap"
        else:
            what = f"grows, largest rotation {reach / gap:.3g} x gap: march longer to see where"
            what += " it settles"
        reason = what + "; " + reason
    confidence = verdict.confidence
    if unbounded and kind_ in SUSTAINED:  # a bounded motion where large ones grow: maybe slow
        confidence = "low"
        reason = (
            f"at or above the flutter speed with every spring closed ({vf:.4g} m/s), where a "
            "large enough motion grows without bound: this one may still grow beyond the "
            f"march (march longer); {reason}"
        )
    rest = float(verdict.mean[ref]) - _centre(setup)
    if kind_ == "decay" and gap and abs(rest) >= EDGE * 0.5 * gap:
        side = "upper" if rest > 0 else "lower"
        reason = (
            f"rest at the {side} edge of the gap: offset {rest:.4g} rad ({rest / gap:+.3g} x "
            f"gap) from its centre; {reason}"
        )
    row = {
        "start": kind,
        "speed": float(speed),
        "initial": float(amp),
        "kind": kind_,
        "confidence": confidence,
        "reason": reason,
        "frequency": float(verdict.frequency),
        "modulation": float(verdict.modulation),
        "amplitude": float(verdict.peak[ref]),
        "rms": float(verdict.rms[ref]),
        "mean": float(verdict.mean[ref]),
        "amplitude_per_gap": float(verdict.peak[ref] / gap) if gap else float("nan"),
        "rms_per_gap": float(verdict.rms[ref] / gap) if gap else float("nan"),
        "growth": float(verdict.growth),
        "peaks": {k: float(v) for k, v in verdict.peak.items()},
        "rmss": {k: float(v) for k, v in verdict.rms.items()},
        "switches_per_second": float(len(res.switches) / max(res.t[-1], 1e-12)),
        "saturated": {c: float(f) for c, f in res.saturated_fraction.items()},
        "history": hist,
    }
    return row


EDGE = 0.98
"""A march that decays to a mean rotation beyond this share of the half gap rests against the
gap's edge (the spring engaged or just touched), not at its centre."""


def _centre(setup) -> float:
    return float(getattr(setup.elements.laws[0], "offset", 0.0))


def _failed(kind, speed, amp, reason, verdict: str = "failed") -> dict:
    return {
        "start": kind,
        "speed": float(speed),
        "initial": float(amp),
        "kind": verdict,
        "confidence": "high",
        "reason": reason,
        "frequency": float("nan"),
        "modulation": float("nan"),
        "amplitude": float("nan"),
        "rms": float("nan"),
        "mean": float("nan"),
        "amplitude_per_gap": float("nan"),
        "rms_per_gap": float("nan"),
        "growth": float("nan"),
        "peaks": {},
        "rmss": {},
        "switches_per_second": float("nan"),
        "saturated": {},
        "history": {},
    }
