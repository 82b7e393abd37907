"""Results of a stability analysis versus airspeed: crossings, tracked branches, summaries.

Speeds are true airspeeds (TAS) [m/s]; every flutter and divergence speed is also given as an
equivalent airspeed (EAS), a Mach number when the speed of sound is known (an altitude was
given), and in knots (KTAS, KEAS) (:mod:`aeroservo.aero.atmosphere`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..aero.atmosphere import KNOT, RHO0
from ..result_shape import Result, shell

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
class FlutterResult(Result):
    """Stability of a model versus airspeed at one density.

    A result of the common shape (:mod:`aeroservo.result_shape`): :meth:`summary`,
    :attr:`table`, :meth:`plot` (``"vg"``, ``"vf"``, ``"root-locus"``), :meth:`to_json` and
    ``save(path, model=..., pk=..., title=...)`` (a ``.npz`` that ``load_result`` reads back as
    a :class:`~aeroservo.files.flutter_file.SavedFlutter`; the wing is needed: ``model`` or
    ``wing_text``).

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
    altitude : float or None
        Geopotential altitude [m] of the flight condition (None: only the density is known).
    speed_of_sound : float or None
        [m/s]; None when only the density is known (no Mach numbers then).
    mach : float
        Mach number of the aerodynamics (Prandtl-Glauert correction or the doublet lattice's;
        0: incompressible).
    compressibility : str or None
        ``"prandtl-glauert"`` (strip theory), ``"dlm"`` (the doublet lattice at ``mach``) or
        None (incompressible strip theory).
    damping : str
        Structural damping of the model (e.g. ``"g = 0.03"``, ``"none"``).
    near_critical : list of NearCritical
        Branches whose damping ratio has a local minimum just above zero (below
        :data:`aeroservo.stability.near_critical.NEAR_ZETA`): not flutter by this model, but
        close to it (:mod:`aeroservo.stability.near_critical`).
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
    altitude: float | None = None
    speed_of_sound: float | None = None
    mach: float = 0.0
    compressibility: str | None = None
    damping: str = "none"
    near_critical: list = field(default_factory=list)

    FIGURES = {"vg": "plot_vg", "vf": "plot_vf", "root-locus": "plot_root_locus"}

    def __post_init__(self) -> None:
        if self.searched_up_to is None:
            self.searched_up_to = self.v_max

    def plot_vg(self, **kw):
        """V-f and V-g diagrams (:func:`aeroservo.plots.plot_vg`, its options)."""
        return shell("plot_vg")(self, **kw)

    def plot_vf(self, **kw):
        """The V-f panel of :meth:`plot_vg` alone (the same options)."""
        fig = self.plot_vg(**kw)
        ax_f, ax_g = fig.axes[:2]
        fig.delaxes(ax_g)
        ax_f.set_xlabel(ax_g.get_xlabel())
        ax_f.tick_params(labelbottom=True)
        return fig

    def plot_root_locus(self, **kw):
        """Root locus (:func:`aeroservo.plots.plot_root_locus`, its options)."""
        return shell("plot_root_locus")(self, **kw)

    @property
    def table(self):
        """The tracked branches, one row per branch and speed (pandas DataFrame), the columns
        of the f06-like CSV (:mod:`aeroservo.files.flutter_table`) as numbers: ``mode``
        (from 1), ``mode_label``, ``point`` (from 1), ``velocity_m_s``, ``eas_m_s``,
        ``velocity_kt``, ``eas_kt``, ``mach`` (NaN without a speed of sound), ``damping_g``,
        ``damping_zeta``, ``frequency_hz``, ``eigenvalue_real_1_s``, ``eigenvalue_imag_1_s``,
        ``exact``; a p-k branch's speeds after it ended are left out."""
        import pandas as pd

        n_v, n_m = self.eigenvalues.shape
        j, i = np.divmod(np.arange(n_v * n_m), n_v)  # mode-major, as the CSV
        lam = self.eigenvalues[i, j]
        keep = np.isfinite(lam)
        j, i, lam = j[keep], i[keep], lam[keep]
        v = np.asarray(self.speeds, dtype=float)[i]
        eas = v * np.sqrt(self.density / RHO0)
        exact = np.ones(lam.shape, bool) if self.exact is None else self.exact[i, j]
        zeta = self.damping_ratio[i, j]
        a = self.speed_of_sound
        return pd.DataFrame(
            {
                "mode": j + 1,
                "mode_label": [self.mode_labels[k] for k in j],
                "point": i + 1,
                "velocity_m_s": v,
                "eas_m_s": eas,
                "velocity_kt": v / KNOT,
                "eas_kt": eas / KNOT,
                "mach": v / a if a is not None else np.full(v.shape, np.nan),
                "damping_g": -2.0 * zeta,
                "damping_zeta": zeta,
                "frequency_hz": self.frequencies[i, j],
                "eigenvalue_real_1_s": lam.real,
                "eigenvalue_imag_1_s": lam.imag,
                "exact": exact,
            }
        )

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

    def eas(self, speed: float | None) -> float | None:
        """Equivalent airspeed [m/s] of a true airspeed [m/s] at this density."""
        return None if speed is None else float(speed * np.sqrt(self.density / RHO0))

    def mach_of(self, speed: float | None) -> float | None:
        """Mach number of a true airspeed [m/s], or None without a speed of sound."""
        if speed is None or self.speed_of_sound is None:
            return None
        return float(speed / self.speed_of_sound)

    @property
    def flutter_eas(self) -> float | None:
        """Flutter speed as an equivalent airspeed [m/s]."""
        return self.eas(self.flutter_speed)

    @property
    def flutter_mach(self) -> float | None:
        """Flutter Mach number (None without a speed of sound)."""
        return self.mach_of(self.flutter_speed)

    @property
    def divergence_eas(self) -> float | None:
        """Divergence speed as an equivalent airspeed [m/s]."""
        return self.eas(self.divergence_speed)

    @property
    def divergence_mach(self) -> float | None:
        """Divergence Mach number (None without a speed of sound)."""
        return self.mach_of(self.divergence_speed)

    def to_dict(self) -> dict:
        """JSON-ready summary (SI units: m/s, Hz, kg/m^3; knots in the ``*_kt*`` keys)."""

        def kt(v):
            return None if v is None else v / KNOT

        return {
            "flutter_speed": self.flutter_speed,
            "flutter_eas": self.flutter_eas,
            "flutter_mach": self.flutter_mach,
            "flutter_ktas": kt(self.flutter_speed),
            "flutter_keas": kt(self.flutter_eas),
            "flutter_frequency": self.flutter_frequency,
            "flutter_mode": self.flutter_mode,
            "divergence_speed": self.divergence_speed,
            "divergence_eas": self.divergence_eas,
            "divergence_mach": self.divergence_mach,
            "divergence_ktas": kt(self.divergence_speed),
            "divergence_keas": kt(self.divergence_eas),
            "altitude": self.altitude,
            "density": self.density,
            "speed_of_sound": self.speed_of_sound,
            "mach": self.mach,
            "compressibility": self.compressibility,
            "damping": self.damping,
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
            "near_critical": [
                {
                    "speed": n.speed,
                    "speed_range": list(n.speed_range),
                    "frequency": n.frequency,
                    "damping_ratio": n.damping_ratio,
                    "threshold": n.threshold,
                    "mode": self.mode_labels[n.mode],
                }
                for n in self.near_critical
            ],
            "modes": [
                {"label": lab, "frequency_at_rest": float(self.frequencies[0, j])}
                for j, lab in enumerate(self.mode_labels)
            ],
            **self.info,
        }

    def speed_text(self, v: float, units: str = "si") -> str:
        """A speed as the field writes it: TAS with EAS and Mach, in m/s or knots."""
        eas, mach = self.eas(v), self.mach_of(v)
        if units == "knots":
            text = f"{v / KNOT:.5g} KTAS (KEAS {eas / KNOT:.5g}"
        else:
            text = f"{v:.6g} m/s TAS (EAS {eas:.5g} m/s"
        return text + (f", Mach {mach:.3f})" if mach is not None else ")")

    def condition_text(self) -> str:
        """The flight condition and the options of the analysis, one line."""
        if self.altitude is not None:
            text = f"altitude {self.altitude:.6g} m (ISA), density {self.density:.5g} kg/m^3"
            text += f", speed of sound {self.speed_of_sound:.5g} m/s"
        else:
            text = f"density {self.density:g} kg/m^3"
        text += f"; structural damping {self.damping}"
        if self.compressibility == "dlm":
            text += f"; doublet lattice at Mach {self.mach:.4g}"
        elif self.compressibility:
            text += f"; {self.compressibility} at Mach {self.mach:.4g}"
        return text

    def summary(self, warnings: bool = True, units: str = "si") -> str:
        """Readable multi-line summary (with the warnings, unless ``warnings=False``).

        Parameters
        ----------
        warnings : bool
            Include the warnings.
        units : {"si", "knots"}
            Speeds in m/s or knots.
        """
        if units not in ("si", "knots"):
            from ..errors import InputError

            raise InputError(f"units = {units!r}: allowed values are 'si', 'knots'")
        top = self.searched_up_to
        unit = "KTAS" if units == "knots" else "m/s"
        scale = 1 / KNOT if units == "knots" else 1.0
        lines = [
            self.condition_text(),
            f"speeds searched 0 .. {top * scale:.4g} {unit}" + (" TAS" if units == "si" else ""),
        ]
        if not self.complete:
            lines[1] += f" (of {self.v_max * scale:.4g} {unit} asked: the search stopped early)"
        if self.flutter is None:
            tas = " TAS" if units == "si" else ""
            lines.append(f"flutter: no flutter below {top * scale:.4g} {unit}{tas}")
        else:
            lines.append(
                f"flutter: {self.speed_text(self.flutter_speed, units)} at "
                f"{self.flutter_frequency:.5g} Hz ({self.flutter_mode})"
            )
        if self.divergence_speed is None:
            lines.append("divergence: none")
        else:
            lines.append(f"divergence: {self.speed_text(self.divergence_speed, units)}")
        for c in self.crossings:
            lines.append(
                f"  {c.kind:<10s} {c.speed * scale:10.6g} {unit}  {c.frequency:8.5g} Hz  "
                f"{self.mode_labels[c.mode]}"
            )
        for n in self.near_critical:
            lo, hi = n.speed_range
            lines.append(
                f"  near-critical {lo * scale:.5g} .. {hi * scale:.5g} {unit}  "
                f"{n.frequency:8.5g} Hz  {self.mode_labels[n.mode]}: damping ratio down to "
                f"{n.damping_ratio:.2g} at {n.speed * scale:.5g} {unit} (stable, but within "
                f"{n.threshold:g} of flutter)"
            )
        modal = self.info.get("modal_model", {})
        if modal.get("enlarged"):
            steps = modal["enlarged"]
            band = modal.get("cutoff_hz")
            band = "every mode" if band is None else f"band up to {band:.4g} Hz"
            lines.append(
                f"modal model enlarged from {steps[0]['modes'][0]} to {modal['n_modes']} modes "
                f"({band}): " + "; ".join(f"{e['by']}: {e['reason']}" for e in steps)
            )
        lines.append(
            f"{self.n_states} states; branches: "
            + ", ".join(
                f"{lab} ({self.frequencies[0, j]:.4g} Hz)" for j, lab in enumerate(self.mode_labels)
            )
        )
        if warnings:
            lines += [f"warning: {w}" for w in self.warnings]
        return "\n".join(lines)
