"""The closed-loop stability of a controller versus airspeed, as data: crossings, stable and
unstable speed intervals with the kind of each loss (oscillatory flutter at f Hz, or static
divergence through a real pole), and the figure (:func:`closed_loop_boundary` computes it)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..result_shape import Result

__all__ = ["ClosedLoopBoundary", "loss_name"]


def loss_name(static: bool, frequency: float | None) -> str:
    """How an engineer names a loss of stability: ``"oscillatory flutter at 11.2 Hz"`` or
    ``"static divergence (real pole)"``."""
    if static:
        return "static divergence (real pole)"
    return f"oscillatory flutter at {frequency:.3g} Hz"


@dataclass
class ClosedLoopBoundary(Result):
    """Closed-loop stability of a linear controller versus airspeed.

    A result of the common shape (:mod:`aeroservo.result_shape`): :meth:`summary`,
    :attr:`table` (the grid), :meth:`plot` (``"boundary"``), :meth:`to_json` and :meth:`save`
    (a ``.npz``).

    Attributes
    ----------
    speeds : ndarray
        Grid speeds [m/s].
    abscissa : ndarray
        Stability measure on the grid [1/s]: growth rate of the least stable closed-loop pole
        (negative: stable).
    frequencies : ndarray
        Frequency of that pole on the grid [Hz].
    crossings : list of dict
        ``{"speed" [m/s], "frequency" [Hz], "kind": "onset" | "recovery", "static": bool}``
        in increasing speed; ``static`` marks a real pole through zero (divergence-like, 0 Hz).
    sampled : bool
        Whether the measure is that of the sampled loop.
    reference_speed : float
        Speed [m/s] whose stable interval defines :attr:`flutter_speed`.
    info : dict
        ``n_evaluations``; ``law``: what the loop's controller is (e.g. an MPC's law without
        active constraints).
    delay : bool
        Whether the loop has a one-sample computational delay.
    reference_abscissa : float or None
        The measure at the reference speed [1/s] (computed there).
    """

    speeds: np.ndarray
    abscissa: np.ndarray
    frequencies: np.ndarray
    crossings: list
    sampled: bool
    reference_speed: float
    info: dict = field(default_factory=dict)
    delay: bool = False
    reference_abscissa: float | None = None

    FIGURES = {"boundary": "plot_boundary"}

    @property
    def v_range(self) -> tuple[float, float]:
        """Searched speed range [m/s]."""
        return float(self.speeds[0]), float(self.speeds[-1])

    @property
    def stable_at_reference(self) -> bool:
        """Whether the loop is stable at the reference (e.g. design) speed (from its own
        eigenvalues when computed, else interpolated on the grid)."""
        g = self.reference_abscissa
        return bool(
            (np.interp(self.reference_speed, self.speeds, self.abscissa) if g is None else g) < 0
        )

    @property
    def flutter(self) -> dict | None:
        """First onset above the reference speed (None: stable to the end of the range)."""
        above = [
            c for c in self.crossings if c["kind"] == "onset" and c["speed"] >= self.reference_speed
        ]
        return above[0] if above else None

    @property
    def flutter_speed(self) -> float | None:
        """Closed-loop flutter speed [m/s]: where the loop first loses stability above the
        reference speed, through a complex pair (flutter) or a real pole (``static`` in
        :attr:`flutter`); None if it stays stable up to the end of the range."""
        f = self.flutter
        return None if f is None else float(f["speed"])

    @property
    def flutter_frequency(self) -> float | None:
        """Frequency [Hz] of the closed-loop flutter onset."""
        f = self.flutter
        return None if f is None else float(f["frequency"])

    @property
    def lower_speed(self) -> float | None:
        """Lower end [m/s] of the stable interval that holds the reference speed (None if the
        loop is unstable there); the start of the searched range if stable down to it."""
        for a, b in self.stable_intervals:
            if a <= self.reference_speed <= b:
                return a
        return None

    @property
    def lower_speed_kind(self) -> str | None:
        """What :attr:`lower_speed` is: ``"search limit"`` (stable down to the lowest speed
        searched) or ``"stability boundary (...)"`` naming the loss below it; None with it."""
        v = self.lower_speed
        if v is None:
            return None
        if v <= float(self.speeds[0]):
            return "search limit (stable down to the lowest speed searched)"
        c = next((c for c in self.crossings if c["speed"] == v), None)
        loss = "" if c is None else f" ({loss_name(c['static'], c['frequency'])} below it)"
        return "stability boundary" + loss

    @property
    def stable_intervals(self) -> list[tuple[float, float]]:
        """Speed intervals [m/s] inside the searched range where the loop is stable.

        Between two crossings the loop is stable after a recovery and unstable after an onset
        (the crossing kinds come from the refined roots, not from the coarse grid, which can
        step over a short unstable interval); before the first crossing it is the opposite of
        that crossing.
        """
        out = []
        for a, b, ok, _ in self._pieces():
            if b > a and ok:
                out.append((float(a), float(b)))
        return out

    def _pieces(self) -> list[tuple[float, float, bool, dict | None]]:
        """``(start, end, stable, crossing that bounds it)`` over the searched range."""
        edges = [self.speeds[0]] + [c["speed"] for c in self.crossings] + [self.speeds[-1]]
        if self.crossings:
            first = self.crossings[0]["kind"] == "onset"
            stable = [first] + [c["kind"] == "recovery" for c in self.crossings]
        else:
            stable = [bool(np.all(self.abscissa < 0))]
        out = []
        for i, (a, b, ok) in enumerate(zip(edges[:-1], edges[1:], stable, strict=True)):
            # the crossing that starts the piece, else the one that ends it
            near = (
                self.crossings[i - 1] if i > 0 else (self.crossings[0] if self.crossings else None)
            )
            out.append((float(a), float(b), ok, near))
        return out

    def unstable_intervals(self, lo: float | None = None, hi: float | None = None) -> list[dict]:
        """Speed intervals [m/s] within ``[lo, hi]`` (default the searched range) where the loop
        is unstable: ``{"from", "to", "static", "frequency" [Hz], "kind"}``, the kind named as
        :func:`loss_name` names it (from the crossing that bounds the interval, or from the
        least stable pole on the grid inside it)."""
        lo = self.speeds[0] if lo is None else lo
        hi = self.speeds[-1] if hi is None else hi
        out = []
        for a, b, ok, near in self._pieces():
            a2, b2 = max(a, lo), min(b, hi)
            if ok or b2 < a2 or (b2 == a2 and b > a):
                continue
            if near is not None:
                static, freq = bool(near["static"]), float(near["frequency"])
            else:
                inside = (self.speeds >= a) & (self.speeds <= b)
                i = int(np.argmax(np.where(inside, self.abscissa, -np.inf)))
                freq = float(self.frequencies[i])
                static = freq < 1e-6
            out.append(
                {
                    "from": float(a2),
                    "to": float(b2),
                    "static": static,
                    "frequency": 0.0 if static else freq,
                    "kind": loss_name(static, freq),
                }
            )
        return out

    def to_dict(self) -> dict:
        """JSON-ready summary (m/s, Hz)."""
        f = self.flutter
        return {
            "closed_loop_flutter_speed": self.flutter_speed,
            "closed_loop_flutter_frequency": self.flutter_frequency,
            "closed_loop_instability": None
            if f is None
            else loss_name(f["static"], f["frequency"]),
            "lower_speed": self.lower_speed,
            "lower_speed_kind": self.lower_speed_kind,
            "reference_speed": self.reference_speed,
            "stable_at_reference": self.stable_at_reference,
            "sampled": self.sampled,
            "delay": self.delay,
            "law": self.info.get("law", ""),
            "crossings": self.crossings,
            "stable_intervals": self.stable_intervals,
            "unstable_intervals": self.unstable_intervals(),
            "v_range": list(self.v_range),
        }

    @property
    def table(self):
        """The speed grid (pandas DataFrame): ``speed_m_s``, ``growth_rate_1_s`` (of the least
        stable closed-loop pole), ``frequency_hz`` (of that pole) and ``stable``."""
        import pandas as pd

        return pd.DataFrame(
            {
                "speed_m_s": np.asarray(self.speeds, dtype=float),
                "growth_rate_1_s": np.asarray(self.abscissa, dtype=float),
                "frequency_hz": np.asarray(self.frequencies, dtype=float),
                "stable": np.asarray(self.abscissa) < 0,
            }
        )

    def summary(self) -> str:
        """Where the loop is stable, and how it loses stability, a line each."""
        lo, hi = self.v_range
        law = self.info.get("law", "")
        loop = "sampled loop" if self.sampled else "continuous loop"
        loop += " with a one-sample delay" if self.delay else ""
        ref = self.reference_speed
        lines = [
            f"closed loop ({loop}{'; ' + law if law else ''}) over {lo:.5g} .. {hi:.5g} m/s: "
            f"{'stable' if self.stable_at_reference else 'UNSTABLE'} at the reference speed "
            f"{ref:.5g} m/s"
        ]
        f = self.flutter
        if f is None:
            lines.append(f"  no loss of stability above it up to {hi:.5g} m/s")
        else:
            lines.append(f"  closed-loop flutter: {loss_name(f['static'], f['frequency'])} at "
                         f"{f['speed']:.6g} m/s")  # fmt: skip
        if self.lower_speed is not None:
            lines.append(f"  stable from {self.lower_speed:.6g} m/s ({self.lower_speed_kind})")
        for u in self.unstable_intervals():
            lines.append(f"  unstable {u['from']:.5g} .. {u['to']:.5g} m/s: {u['kind']}")
        return "\n".join(lines)

    def to_state(self) -> dict:
        """Every field as plain data and arrays (for a file; :meth:`from_state`)."""
        return {f: getattr(self, f) for f in self.__dataclass_fields__}

    @classmethod
    def from_state(cls, state: dict) -> ClosedLoopBoundary:
        """The boundary of :meth:`to_state`."""
        return cls(**state)

    def plot_boundary(
        self,
        ax=None,
        open_loop=None,
        engaged: tuple[float, float] | None = None,
        stable_to: float | None = None,
    ):
        """Growth rate of the least stable pole versus speed; each loss of stability named by
        its kind, the lower end of the stable interval and the engaged range marked.

        Parameters
        ----------
        ax : matplotlib Axes, optional
        open_loop : FlutterResult, optional
            Adds the open-loop tracked modes' real parts for comparison.
        engaged : (float, float), optional
            Speed range [m/s] where the loop is engaged (shaded).
        stable_to : float, optional
            Speed [m/s] up to which stability is required (the flutter margin), marked.

        Returns
        -------
        matplotlib.figure.Figure
            ``ax``'s figure, or a new one: the current pyplot figure when pyplot is in use
            (:mod:`aeroservo._figures`), so ``plt.savefig`` and ``plt.show()`` act on it.
        """
        from .._figures import new_figure

        if ax is None:
            fig = new_figure(figsize=(7.5, 4.0))
            ax = fig.subplots()
        else:
            fig = ax.figure
        if engaged is not None:
            ax.axvspan(*engaged, color="g", alpha=0.08, label="engaged range")
        if stable_to is not None:
            ax.axvline(stable_to, color="g", ls=":", lw=1, label="stability required to")
        if open_loop is not None:
            ol = np.max(open_loop.eigenvalues.real, axis=1)
            ax.plot(open_loop.speeds, ol, color="0.6", lw=1, label="open loop (tracked modes)")
            if open_loop.flutter_speed is not None:
                ax.axvline(open_loop.flutter_speed, color="0.6", ls=":", lw=1)
        ax.plot(self.speeds, self.abscissa, label="closed loop")
        ax.axhline(0, color="k", lw=0.8)
        ax.axvline(self.reference_speed, color="g", ls="--", lw=1, label="design speed")
        for j, c in enumerate(self.crossings):
            onset = c["kind"] == "onset"
            ax.plot(c["speed"], 0, "ro" if onset else "bs", ms=5)
            text = loss_name(c["static"], c["frequency"]) if onset else "stable again"
            if not onset and c["speed"] == self.lower_speed:
                text = f"lower end {c['speed']:.4g} m/s"
            elif onset:
                text = f"{text}\nat {c['speed']:.4g} m/s"
            ax.annotate(
                text,
                (c["speed"], 0),
                xytext=(6, 18 + 14 * (j % 3)),
                textcoords="offset points",
                fontsize=7,
                arrowprops={"arrowstyle": "->", "lw": 0.6},
            )
        lo, hi = np.percentile(self.abscissa, [2, 98])
        pad = 0.2 * (hi - lo + 1e-9)
        ax.set_ylim(min(lo, -pad) - pad, max(hi, pad) + 2 * pad)
        ax.set_xlabel("airspeed V [m/s]")
        ax.set_ylabel("growth rate of least stable pole [1/s]")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7, loc="upper left")
        return fig
