"""The recoverable set of a saturated loop, with and without anti-windup.

A flutter-suppression loop above the open-loop flutter speed recovers from a disturbance only
while its actuator can hold the wing: released from a tip deflection ``d`` with the command
limited to ``+- M``, the loop either brings the wing back or loses it. Over a grid of initial
deflections and magnitude limits, :func:`recoverable_set` marches the loop (the plant exact
between samples, zero-order hold, the limits active: :func:`aeroservo.simulate.simulate`) with
the controller's use of the applied input on and off (:mod:`aeroservo.design.anti_windup`) and
records which cells recover: the measure of what anti-windup buys, per controller.

A run **recovers** when the plant state, over the last :data:`SETTLE` of the run, stays below
:data:`THRESHOLD` of its initial size (the 2-norm of the balanced plant state: every mode and
aerodynamic state counted) and every signal is finite.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError, check_number
from ..result_shape import Result

__all__ = ["RecoverableSet", "recoverable_set", "SETTLE", "THRESHOLD"]

SETTLE = 0.2
"""Share of the run, at its end, over which recovery is judged."""

THRESHOLD = 0.05
"""Largest plant-state size over that window, relative to the initial one, of a recovery."""


@dataclass
class RecoverableSet(Result):
    """Which initial deflections and limits a loop recovers from (SI units).

    A result of the common shape (:mod:`aeroservo.result_shape`): :meth:`summary`,
    :attr:`table` (one row per cell), :meth:`plot` (``"recovery"``), :meth:`to_json` and
    :meth:`save` (a ``.npz``).

    Attributes
    ----------
    deflections : ndarray
        Initial tip deflections [m] (rows).
    magnitudes : ndarray
        Magnitude limits of ``control`` [its unit] (columns).
    control : str
    speed : float
        True airspeed [m/s].
    controller : str
    recovered : dict
        ``True`` / ``False`` (anti-windup on / off) -> (n_deflections, n_magnitudes) bool.
    final : dict
        The same keys -> the largest plant-state size over the last window, relative to the
        initial one (inf where a signal is not finite).
    """

    deflections: np.ndarray
    magnitudes: np.ndarray
    control: str
    speed: float
    controller: str
    recovered: dict = field(default_factory=dict)
    final: dict = field(default_factory=dict)

    FIGURES = {"recovery": "plot_recovery"}

    def count(self, anti_windup: bool) -> int:
        """Cells recovered with anti-windup on (True) or off (False)."""
        return int(np.count_nonzero(self.recovered[anti_windup]))

    @property
    def anti_windup_helps(self) -> bool | None:
        """True when anti-windup recovers a strict superset of the cells, False when it
        recovers a strict subset or loses a cell the plain law recovers, None when equal."""
        on, off = self.recovered[True], self.recovered[False]
        if np.array_equal(on, off):
            return None
        return bool(np.all(on >= off))

    def summary(self) -> str:
        """One paragraph: the counts and the cells that differ."""
        n = self.recovered[True].size
        lines = [
            f"recoverable set of {self.controller} at {self.speed:.4g} m/s ({self.control} "
            f"limited): anti-windup on {self.count(True)} of {n} cells, off {self.count(False)}"
        ]
        diff = np.argwhere(self.recovered[True] != self.recovered[False])
        for i, j in diff:
            who = "on" if self.recovered[True][i, j] else "off"
            lines.append(
                f"  tip {self.deflections[i]:.4g} m, limit {self.magnitudes[j]:.4g}: recovered "
                f"only with anti-windup {who}"
            )
        return "\n".join(lines)

    @property
    def table(self):
        """One row per initial deflection and limit (pandas DataFrame): ``deflection_m``,
        ``magnitude`` (the limit, in the control's unit), ``recovered_anti_windup``,
        ``recovered_plain`` and the final state sizes ``final_anti_windup``,
        ``final_plain`` (relative to the initial one; inf: a signal not finite)."""
        import pandas as pd

        i, j = np.divmod(np.arange(self.deflections.size * self.magnitudes.size),
                         self.magnitudes.size)  # fmt: skip
        out = {"deflection_m": self.deflections[i], "magnitude": self.magnitudes[j]}
        for on, name in ((True, "anti_windup"), (False, "plain")):
            if on in self.recovered:
                out[f"recovered_{name}"] = self.recovered[on][i, j]
                out[f"final_{name}"] = self.final[on][i, j]
        return pd.DataFrame(out)

    def to_dict(self) -> dict:
        """The grid and, anti-windup on and off, the recovered cells and final sizes."""
        out = {k: getattr(self, k) for k in ("control", "speed", "controller")}
        out |= {"deflections": self.deflections, "magnitudes": self.magnitudes}
        for on, name in ((True, "anti_windup"), (False, "plain")):
            if on in self.recovered:
                out[f"recovered_{name}"], out[f"final_{name}"] = self.recovered[on], self.final[on]
        return out

    def to_state(self) -> dict:
        """Every field as plain data and arrays (for a file; :meth:`from_state`)."""
        return self.to_dict()

    @classmethod
    def from_state(cls, state: dict) -> RecoverableSet:
        """The set of :meth:`to_state`."""
        out = cls(*(state[k] for k in ("deflections", "magnitudes", "control", "speed")),
                  state["controller"])  # fmt: skip
        for on, name in ((True, "anti_windup"), (False, "plain")):
            if f"recovered_{name}" in state:
                out.recovered[on] = np.asarray(state[f"recovered_{name}"], dtype=bool)
                out.final[on] = np.asarray(state[f"final_{name}"], dtype=float)
        return out

    def plot_recovery(self):
        """The two grids side by side (recovered cells filled)."""
        from .._figures import new_figure

        fig = new_figure(figsize=(9.0, 3.8))
        axs = fig.subplots(1, 2, sharey=True)
        for ax, on in zip(axs, (True, False), strict=True):
            grid = self.recovered[on].astype(float)
            ax.imshow(grid, origin="lower", cmap="Greens", vmin=0, vmax=1.4, aspect="auto")
            ax.set_xticks(range(self.magnitudes.size), [f"{m:.3g}" for m in self.magnitudes])
            ax.set_yticks(range(self.deflections.size), [f"{d:.3g}" for d in self.deflections])
            ax.set_xlabel(f"magnitude limit of {self.control}")
            ax.set_title(f"anti-windup {'on' if on else 'off'}: {self.count(on)} recovered")
            for i, j in np.argwhere(self.recovered[True] != self.recovered[False]):
                ax.plot(j, i, "x", color="tab:red", ms=10, mew=2)
        axs[0].set_ylabel("initial tip deflection [m]")
        fig.suptitle(
            f"{self.controller} at {self.speed:.4g} m/s: recovered (green) within "
            f"{THRESHOLD:g} of the initial state; red x: the two differ",
            fontsize=10,
        )
        return fig


def _judge(states: np.ndarray) -> float:
    """Largest state size over the last window relative to the first sample's."""
    if not np.all(np.isfinite(states)):
        return float("inf")
    size = np.linalg.norm(states, axis=1)
    start = max(int((1.0 - SETTLE) * size.size), 1)
    return float(size[start:].max() / size[0])


def recoverable_set(
    loop,
    controller,
    speed: float,
    deflections,
    magnitudes,
    *,
    control: str | None = None,
    rate: float | None = None,
    duration: float = 3.0,
    delay: bool = False,
) -> RecoverableSet:
    """March the loop from each initial tip deflection with each magnitude limit, anti-windup
    on and off (see the module docstring).

    Parameters
    ----------
    loop : aeroservo.design.loop.ControlLoop
    controller : LQG or compensator
        Designed (e.g. ``loop.design_controller(spec, ...)``); its switch is set both ways.
    speed : float
        True airspeed [m/s].
    deflections : sequence of float
        Initial tip deflections [m] (the static tip-load shape, as ``initial_tip``).
    magnitudes : sequence of float
        Magnitude limits of ``control`` [its unit].
    control : str, optional
        The limited control (default the loop's first).
    rate : float, optional
        Its rate limit [unit/s] (default none).
    duration : float
        Length of each run [s].
    delay : bool
        One-sample computational delay.
    """
    from ..design.anti_windup import with_anti_windup
    from ..design.plant import Limits
    from ..simulate.march import simulate

    d = np.array([check_number("deflection", x, unit="m", lo=0.0, lo_open=True)
                  for x in np.atleast_1d(deflections)])  # fmt: skip
    m = np.array([check_number("magnitude limit", x, lo=0.0, lo_open=True)
                  for x in np.atleast_1d(magnitudes)])  # fmt: skip
    check_number("duration", duration, unit="s", lo=0.0, lo_open=True, hi=600.0)
    control = control or loop.controls[0]
    if control not in loop.controls:
        raise InputError(f"control = {control!r}: not a control of the loop {list(loop.controls)}")
    plant = loop.plant(speed)
    out = RecoverableSet(d, m, control, float(speed), getattr(controller, "name", "") or
                         type(controller).__name__)  # fmt: skip
    for on in (True, False):
        ctrl = with_anti_windup(controller, on)
        rec = np.zeros((d.size, m.size), dtype=bool)
        fin = np.zeros((d.size, m.size))
        for i, tip in enumerate(d):
            x0 = loop.initial_state(tip)
            for j, mag in enumerate(m):
                lim = Limits({control: mag}, {control: rate} if rate else {})
                with warnings.catch_warnings():  # a lost run winds up: that is the finding
                    warnings.simplefilter("ignore", RuntimeWarning)
                    res = simulate(plant, ctrl, duration=duration, x0=x0, limits=lim,
                                   delay=delay, record_states=True)  # fmt: skip
                fin[i, j] = _judge(np.asarray(res.states))
                rec[i, j] = fin[i, j] <= THRESHOLD
        out.recovered[on], out.final[on] = rec, fin
    return out
