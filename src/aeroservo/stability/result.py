"""Results of a stability analysis versus airspeed: crossings, tracked branches, summaries."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["Crossing", "FlutterResult"]


@dataclass(frozen=True)
class Crossing:
    """A tracked eigenvalue crossing the imaginary axis.

    Attributes
    ----------
    speed : float
        Airspeed [m/s].
    frequency : float
        Frequency at the crossing [Hz] (0 for divergence).
    mode : int
        Index of the tracked branch.
    kind : str
        ``"onset"`` (becomes unstable as speed increases), ``"recovery"`` (becomes stable
        again: the end of a hump) or ``"divergence"`` (a real eigenvalue through zero).
    """

    speed: float
    frequency: float
    mode: int
    kind: str


@dataclass
class FlutterResult:
    """Stability of a model versus airspeed at one density.

    Attributes
    ----------
    speeds : ndarray (n_speeds,)
        Grid on which the tracked modes are reported [m/s].
    eigenvalues : ndarray (n_speeds, n_modes) complex
        Tracked eigenvalues [1/s].
    mode_labels : list of str
        Name of each tracked branch (from its shape at V = 0).
    crossings : list of Crossing
        Every crossing found, in increasing speed.
    divergence_speed : float or None
        Static divergence speed [m/s] from the steady equations, or None if there is none.
    density : float
        Air density [kg/m^3].
    v_max : float
        Upper end of the speed range searched [m/s].
    n_states : int
        Size of the first-order system.
    searched_up_to : float or None
        Speed up to which the search is complete [m/s]: ``v_max``, or less when it stopped
        early (see ``warnings``); everything found below it stands.
    warnings : list of str
        What the user should know (a search cut short, mesh edges merged, modes added by the
        certificate), one sentence each.
    exact : ndarray (n_speeds, n_modes) of bool or None
        Which branch values are eigenvalues of the full model (the others come from the modal
        model, accurate to about 1e-3 of their modulus); None: all are.
    info : dict
        Method details (modal model, certificate, counts), JSON-ready.
    """

    speeds: np.ndarray
    eigenvalues: np.ndarray
    mode_labels: list[str]
    crossings: list[Crossing]
    divergence_speed: float | None
    density: float
    v_max: float
    n_states: int
    info: dict = field(default_factory=dict)
    searched_up_to: float | None = None
    warnings: list = field(default_factory=list)
    exact: np.ndarray | None = None

    def __post_init__(self) -> None:
        if self.searched_up_to is None:
            self.searched_up_to = self.v_max

    @property
    def complete(self) -> bool:
        """Whether the whole range 0 .. ``v_max`` was searched."""
        return self.searched_up_to >= self.v_max * (1 - 1e-12)

    @property
    def frequencies(self) -> np.ndarray:
        """Frequencies of the tracked branches, Im(lambda)/2pi [Hz]."""
        return np.abs(self.eigenvalues.imag) / (2 * np.pi)

    @property
    def damping_ratio(self) -> np.ndarray:
        """-Re(lambda)/|lambda| [-] (positive: stable)."""
        mag = np.abs(self.eigenvalues)
        out = np.where(np.isnan(mag), np.nan, 0.0)  # NaN where a branch has ended (p-k)
        return np.divide(-self.eigenvalues.real, mag, out=out, where=mag > 0)

    @property
    def flutter(self) -> Crossing | None:
        """The lowest-speed oscillatory onset, or None if no flutter below ``v_max``."""
        onsets = [c for c in self.crossings if c.kind == "onset"]
        return min(onsets, key=lambda c: c.speed) if onsets else None

    @property
    def flutter_speed(self) -> float | None:
        """Flutter speed [m/s] or None."""
        f = self.flutter
        return None if f is None else f.speed

    @property
    def flutter_frequency(self) -> float | None:
        """Flutter frequency [Hz] or None."""
        f = self.flutter
        return None if f is None else f.frequency

    @property
    def flutter_mode(self) -> str | None:
        """Label of the branch that goes unstable first."""
        f = self.flutter
        return None if f is None else self.mode_labels[f.mode]

    def to_dict(self) -> dict:
        """JSON-ready summary (SI units: m/s, Hz, kg/m^3)."""
        return {
            "flutter_speed": self.flutter_speed,
            "flutter_frequency": self.flutter_frequency,
            "flutter_mode": self.flutter_mode,
            "divergence_speed": self.divergence_speed,
            "density": self.density,
            "n_states": self.n_states,
            "v_max": self.v_max,
            "searched_range": [0.0, self.searched_up_to],
            "warnings": list(self.warnings),
            "crossings": [
                {
                    "speed": c.speed,
                    "frequency": c.frequency,
                    "mode": self.mode_labels[c.mode],
                    "kind": c.kind,
                }
                for c in self.crossings
            ],
            "modes": [
                {"label": lab, "frequency_at_rest": float(self.frequencies[0, j])}
                for j, lab in enumerate(self.mode_labels)
            ],
            **self.info,
        }

    def summary(self, warnings: bool = True) -> str:
        """Readable multi-line summary (with the warnings, unless ``warnings=False``)."""
        top = self.searched_up_to
        lines = [f"density {self.density:g} kg/m^3, speeds searched 0 .. {top:.4g} m/s"]
        if not self.complete:
            lines[0] += f" (of {self.v_max:.4g} m/s asked: the search stopped early)"
        if self.flutter is None:
            lines.append(f"flutter: no flutter below {top:.4g} m/s")
        else:
            lines.append(
                f"flutter: {self.flutter_speed:.6g} m/s at {self.flutter_frequency:.5g} Hz "
                f"({self.flutter_mode})"
            )
        if self.divergence_speed is None:
            lines.append("divergence: none")
        else:
            lines.append(f"divergence: {self.divergence_speed:.6g} m/s")
        for c in self.crossings:
            lines.append(
                f"  {c.kind:<10s} {c.speed:10.6g} m/s  {c.frequency:8.5g} Hz  "
                f"{self.mode_labels[c.mode]}"
            )
        lines.append(
            f"{self.n_states} states; tracked: "
            + ", ".join(
                f"{lab} ({self.frequencies[0, j]:.4g} Hz)" for j, lab in enumerate(self.mode_labels)
            )
        )
        if warnings:
            lines += [f"warning: {w}" for w in self.warnings]
        return "\n".join(lines)
