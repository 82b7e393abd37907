"""A p-k solution at a Nastran flutter case's velocities, in the SOL145 flutter-summary terms.

Nastran's PK method prints, for each mode ("POINT") at each velocity of the FLUTTER card, the
reduced frequency ``KFREQ = omega (REFC / 2) / V``, its inverse, the velocity, the damping
``g = 2 gamma`` of the root ``p = omega (gamma +- i)`` (so ``g = 2 Re p / |Im p|``, > 0
unstable), the frequency ``|Im p| / 2 pi`` and the complex eigenvalue (MSC Nastran Aeroelastic
Analysis User's Guide, section 6.4, "Flutter Summary"). :func:`sol145_summary` tabulates
:func:`aeroservo.stability.pk.pk_flutter` evaluated at exactly those velocities the same way;
its roots are aeroservo's p-k (exact Theodorsen, or the doublet lattice's tabulated forces),
frozen at ``omega = Im p`` as Nastran's PK is.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .result import FlutterResult

__all__ = ["Sol145Summary", "sol145_summary"]


@dataclass(frozen=True)
class Sol145Summary:
    """The flutter summary: ``rows[j]`` is mode j's list of (KFREQ, 1/KFREQ, V [m/s], g,
    f [Hz], Re p [1/s], Im p [1/s]) at each velocity."""

    labels: list[str]
    velocities: np.ndarray  # [m/s]
    rows: list[list[tuple[float, ...]]]
    mach: float
    density_ratio: float
    method: str
    reference_chord: float  # [m]
    velocity_unit: str = ""
    velocity_factor: float = 1.0  # [m/s] per velocity unit

    def to_dict(self) -> dict:
        """JSON-ready: one list of points per mode (SI, velocity in m/s)."""
        keys = ("kfreq", "inverse_kfreq", "velocity", "damping_g", "frequency", "real", "imag")
        return {
            "method": self.method,
            "mach": self.mach,
            "density_ratio": self.density_ratio,
            "reference_chord": self.reference_chord,
            "units": {"velocity": "m/s", "frequency": "Hz", "eigenvalue": "1/s"},
            "points": [
                {
                    "point": j + 1,
                    "mode": label,
                    "rows": [dict(zip(keys, r, strict=True)) for r in rs],
                }
                for j, (label, rs) in enumerate(zip(self.labels, self.rows, strict=True))
            ],
        }

    def text(self) -> str:
        """The summary as Nastran prints it (velocity in m/s and in the deck's unit)."""
        unit = self.velocity_unit
        head = (
            f"{'KFREQ':>11} {'1./KFREQ':>11} {'VELOCITY':>11} "
            + (f"{'VELOCITY':>11} " if unit else "")
            + f"{'DAMPING':>11} {'FREQUENCY':>11} {'COMPLEX':>12} {'EIGENVALUE':>12}"
        )
        sub = (
            f"{'':>11} {'':>11} {'[m/s]':>11} "
            + (f"{'[' + unit + ']':>11} " if unit else "")
            + f"{'g':>11} {'[Hz]':>11} {'[1/s]':>12} {'[1/s]':>12}"
        )
        out = []
        for j, (label, rows) in enumerate(zip(self.labels, self.rows, strict=True)):
            out.append(
                f"  POINT = {j + 1:3d}    MACH NUMBER = {self.mach:.4f}    DENSITY RATIO = "
                f"{self.density_ratio:.4E}    METHOD = {self.method}    ({label})"
            )
            out += [head, sub]
            for k, inv, v, g, f, re, im in rows:
                deck = f"{v / self.velocity_factor:11.4E} " if unit else ""
                out.append(
                    f"{k:11.4E} {inv:11.4E} {v:11.4E} {deck}{g:11.4E} {f:11.4E} "
                    f"{re:12.5E} {im:12.5E}"
                )
            out.append("")
        return "\n".join(out)


def sol145_summary(
    pk: FlutterResult,
    velocities,
    reference_chord: float,
    *,
    method: str = "PK",
    density_ratio: float = 1.0,
    velocity_unit: str = "",
    velocity_factor: float = 1.0,
) -> Sol145Summary:
    """Tabulate a p-k result at the velocities [m/s] it passed through (``pk_flutter(...,
    speeds=velocities)``).

    Raises
    ------
    ValueError
        A velocity that is not one of the result's speeds.
    """
    speeds = np.asarray(pk.speeds, dtype=float)
    b = 0.5 * float(reference_chord)
    vel = np.asarray(velocities, dtype=float)
    index = []
    for v in vel:
        i = int(np.argmin(np.abs(speeds - v)))
        if abs(speeds[i] - v) > 1e-9 * max(1.0, v):
            raise ValueError(f"velocity {v:g} m/s is not a speed of the p-k result")
        index.append(i)
    rows = []
    for j in range(pk.eigenvalues.shape[1]):
        mode = []
        for v, i in zip(vel, index, strict=True):
            p = complex(pk.eigenvalues[i, j])
            if not np.isfinite(p):
                continue
            w = abs(p.imag)
            k = w * b / v if v > 0 else float("inf")
            g = 2.0 * p.real / w if w > 0 else float("inf")
            mode.append((k, 1.0 / k if k else float("inf"), v, g, w / (2 * np.pi), p.real, p.imag))
        rows.append(mode)
    return Sol145Summary(
        list(pk.mode_labels), vel, rows, float(pk.mach or 0.0), float(density_ratio), method,
        float(reference_chord), velocity_unit, float(velocity_factor),
    )  # fmt: skip
