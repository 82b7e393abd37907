"""Flutter clearance over altitude: matched flutter and divergence points against a V_D / M_D
envelope with the certification margin.

At each altitude of the standard atmosphere the flutter and divergence speeds are found at the
altitude's density (:func:`aeroservo.stability.matched.flutter_at`, Mach matched when the
Prandtl-Glauert correction is on) and given as TAS, EAS and Mach. The design envelope in
equivalent airspeed is ``V_env(h) = min(V_D, M_D a(h) sqrt(rho(h) / rho0))`` (V_D an EAS, M_D a
Mach number; either may be omitted); CS 25.629 and MIL-A-8870 ask for no flutter and no
divergence up to ``margin x V_env`` (margin 1.15: the envelope enlarged by 15 % in EAS at
constant altitude). A point passes (``margin_ok``) when both speeds lie above that line, or when
none was found and the search went past it.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from ..aero.atmosphere import ALTITUDE_RANGE, KNOT, RHO0, isa
from ..errors import InputError, check_number, check_quantity, parse_number
from ..result_shape import Result
from ..stability.matched import flutter_at
from .envelope_point import EnvelopePoint, _checked_point, _optional_number

__all__ = ["EnvelopePoint", "Envelope", "flutter_envelope", "MARGIN"]

MARGIN = 1.15
"""Required margin on the design envelope in EAS (CS 25.629, MIL-A-8870)."""


_COLUMNS = (
    "altitude",
    "density",
    "speed_of_sound",
    "flutter_speed",
    "flutter_eas",
    "flutter_mach",
    "flutter_frequency",
    "divergence_speed",
    "divergence_eas",
    "divergence_mach",
    "searched_eas",
)
"""The columns of an envelope's table (with ``envelope_eas``, ``required_eas``, ``margin_ok``
when it has a design envelope)."""
_SPEEDS = ("flutter_speed", "flutter_eas", "divergence_speed", "divergence_eas", "searched_eas")
_SPEEDS += ("envelope_eas", "required_eas")
_KEYS = ("kind", "wing", "compressibility", "damping", "vd_eas", "md", "margin", "margin_ok")
_KEYS += ("points", "units", "format")


@dataclass
class Envelope(Result):
    """A flutter envelope: one :class:`EnvelopePoint` per altitude, increasing.

    A result of the common shape (:mod:`aeroservo.result_shape`): :meth:`summary`,
    :attr:`table` (one row per altitude), :meth:`plot` (``"envelope"``), :meth:`to_json` and
    :meth:`save` (the JSON of ``aeroservo envelope --save``).
    """

    points: list
    vd: float | None = None
    md: float | None = None
    margin: float = MARGIN
    compressibility: str | None = None
    damping: str = "none"
    wing: str = ""
    info: dict = field(default_factory=dict)

    FIGURES = {"envelope": "plot_envelope"}

    @property
    def altitudes(self) -> np.ndarray:
        return np.array([p.altitude for p in self.points])

    def column(self, name: str) -> np.ndarray:
        """A quantity over the altitudes (NaN where None)."""
        return np.array(
            [np.nan if getattr(p, name) is None else getattr(p, name) for p in self.points],
            dtype=float,
        )

    @property
    def margin_ok(self) -> bool | None:
        """Whether every altitude passes (None without an envelope)."""
        oks = [p.margin_ok for p in self.points]
        return None if oks and oks[0] is None else all(oks)

    def to_dict(self) -> dict:
        """JSON-ready: ``points`` and the settings (speeds in m/s)."""
        out = {
            "kind": "envelope",
            "wing": self.wing,
            "compressibility": self.compressibility,
            "damping": self.damping,
            "vd_eas": self.vd,
            "md": self.md,
            "margin": self.margin if self.envelope else None,
            "margin_ok": self.margin_ok,
            "points": [p.to_dict() for p in self.points],
            "units": {"speed": "m/s", "altitude": "m", "density": "kg/m^3", "frequency": "Hz"},
        }
        out.update(self.info)
        return out

    @classmethod
    def from_dict(cls, data: dict) -> Envelope:
        """The envelope of :meth:`to_dict` (e.g. read back from ``envelope --save``)."""
        names = set(EnvelopePoint.__dataclass_fields__)
        if not isinstance(data, dict) or not isinstance(data.get("points"), list):
            raise InputError("not a valid flutter envelope (no list 'points')")
        try:
            points = [
                EnvelopePoint(**_checked_point(i, p, names)) for i, p in enumerate(data["points"])
            ]
            return cls(
                points=points,
                vd=_optional_number("vd_eas", data.get("vd_eas")),
                md=_optional_number("md", data.get("md")),
                margin=_optional_number("margin", data.get("margin")) or MARGIN,
                compressibility=data.get("compressibility"),
                damping=str(data.get("damping", "none")),
                wing=str(data.get("wing", "")),
                info={k: v for k, v in data.items() if k not in _KEYS},
            )
        except (KeyError, TypeError, AttributeError) as exc:
            raise InputError(f"not a valid flutter envelope ({exc})") from None

    @property
    def envelope(self) -> bool:
        return self.vd is not None or self.md is not None

    def envelope_line(self, altitudes: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Design envelope EAS [m/s], sqrt(rho / rho0) and a [m/s] at any altitudes [m]."""
        atms = [isa(float(h)) for h in altitudes]
        env = np.array([_envelope_eas(float(h), self.vd, self.md) for h in altitudes], dtype=float)
        sig = np.array([math.sqrt(a.density / RHO0) for a in atms])
        return env, sig, np.array([a.speed_of_sound for a in atms])

    def _columns(self) -> list[str]:
        return list(_COLUMNS) + (["envelope_eas", "required_eas", "margin_ok"] * self.envelope)

    def csv_text(self, units: str = "si") -> str:
        """The table as CSV (one row per altitude; speeds in m/s, or knots)."""
        cols = self._columns()
        kt = units == "knots"
        head = [f"{c}_kt" if kt and c in _SPEEDS else c for c in cols]
        lines = [",".join(head)]
        for p in self.points:
            row = []
            for c in cols:
                v = getattr(p, c)
                if v is None:
                    row.append("")
                elif isinstance(v, bool):
                    row.append("1" if v else "0")
                else:
                    row.append(f"{v / KNOT if kt and c in _SPEEDS else v:.10g}")
            lines.append(",".join(row))
        return "\n".join(lines) + "\n"

    @property
    def table(self):
        """One row per altitude, the columns of :meth:`csv_text` (pandas DataFrame; SI units:
        m, kg/m^3, m/s, Hz; NaN where a speed was not found)."""
        import pandas as pd

        cols = self._columns()
        out = pd.DataFrame({c: self.column(c) for c in cols if c != "margin_ok"}, columns=cols)
        if self.envelope:
            out["margin_ok"] = [bool(p.margin_ok) for p in self.points]
        return out

    def summary(self) -> str:
        """The settings, then flutter and divergence at each altitude against the envelope."""
        head = f"flutter envelope of {self.wing or 'the wing'}: damping {self.damping}, "
        head += self.compressibility or "incompressible"
        if self.envelope:
            parts = [] if self.vd is None else [f"V_D {self.vd:.5g} m/s EAS"]
            parts += [] if self.md is None else [f"M_D {self.md:.4g}"]
            head += f"; {' and '.join(parts)} x {self.margin:g}: "
            head += "every altitude passes" if self.margin_ok else "FAILS"
        lines = [head]
        for p in self.points:
            text = f"  {p.altitude:8.6g} m: flutter {_at(p.flutter_eas, p.flutter_mach)}, "
            text += f"divergence {_at(p.divergence_eas, p.divergence_mach)}; searched to "
            text += f"{p.searched_eas:.5g} m/s EAS"
            if p.required_eas is not None:
                text += f"; required {p.required_eas:.5g}: {'ok' if p.margin_ok else 'FAILS'}"
            lines.append(text)
        return "\n".join(lines)

    def plot_envelope(self, *, units: str = "si", x: str = "eas"):
        """Altitude against EAS (or Mach, ``x="mach"``): flutter and divergence boundaries,
        the design envelope and the margin line, failing points marked (matplotlib Figure)."""
        from ..plots import plot_envelope

        return plot_envelope(self, units=units, x=x)


def _at(eas: float | None, mach: float | None) -> str:
    if eas is None:
        return "none"
    return f"{eas:.5g} m/s EAS" + ("" if mach is None else f" (Mach {mach:.3f})")


def _envelope_eas(alt, vd: float | None, md: float | None) -> float | None:
    if vd is None and md is None:
        return None
    atm = isa(alt)
    vals = []
    if vd is not None:
        vals.append(vd)
    if md is not None:
        vals.append(md * atm.speed_of_sound * math.sqrt(atm.density / RHO0))
    return min(vals)


def parse_altitudes(text: str, unit: str = "m") -> list[float]:
    """Altitudes from ``"start:stop:step"`` (inclusive) or ``"a,b,c"``, in metres."""
    scale = 0.3048 if unit == "ft" else 1.0
    key = "--altitudes-ft" if unit == "ft" else "--altitudes"
    try:
        if ":" in text:
            start, stop, step = (parse_number(t) for t in text.split(":"))
            if not step > 0 or stop < start or (stop - start) / step > 1000:
                raise ValueError
            n = int(math.floor((stop - start) / step + 1e-9)) + 1
            vals = [start + i * step for i in range(n)]
        else:
            vals = [parse_number(t) for t in text.split(",")]  # a blank item is a ValueError
    except ValueError:
        raise InputError(
            f"{key} = {text!r}: expected start:stop:step (step > 0, at most 1000 points) or a "
            "comma-separated list"
        ) from None
    if len(set(vals)) != len(vals):
        raise InputError(f"{key} = {text!r}: altitudes must not repeat")
    lo, hi = (a / scale for a in ALTITUDE_RANGE)
    for v in vals:
        if not lo <= v <= hi:  # NaN included
            raise InputError(
                f"{key} = {text!r}: altitude {v:g} {unit} outside the standard atmosphere "
                f"[{lo:.6g}, {hi:.6g}] {unit}"
            )
    return [v * scale for v in vals]


def flutter_envelope(
    model,
    altitudes: Sequence[float],
    *,
    compressibility: str | None = None,
    vd: float | None = None,
    md: float | None = None,
    margin: float = MARGIN,
    v_max: float | None = None,
    progress: Callable[[int], None] | None = None,
    **kw,
) -> Envelope:
    """Matched flutter and divergence points over altitude, checked against an envelope.

    Parameters
    ----------
    model : AeroelasticModel
    altitudes : sequence of float
        Geopotential altitudes [m].
    compressibility : {None, "prandtl-glauert"}
        Compressibility correction (Mach matched at each altitude).
    vd : float, optional
        Design dive speed V_D as an equivalent airspeed [m/s].
    md : float, optional
        Design dive Mach number M_D.
    margin : float
        Required margin on the envelope in EAS (default 1.15).
    v_max : float, optional
        Upper end of each search [m/s TAS]; default the boundary's own, raised to
        1.3 x the required speed when an envelope is given.
    progress : callable, optional
        Called with the number of altitudes done.
    **kw
        Passed to :func:`aeroservo.flutter_boundary` (``n_modes``, ``rtol``, ...).

    Returns
    -------
    Envelope
    """
    alts = [float(a) for a in altitudes]
    if not alts:
        raise InputError("altitudes = []: give at least one altitude")
    if vd is not None:
        vd = check_quantity("vd", vd, "flight_speed")
    if md is not None:
        md = check_number("md", md, lo=0.0, hi=5.0, lo_open=True)
    margin = check_number("margin", margin, lo=1.0, hi=3.0)
    points = []
    mach = 0.0
    for i, h in enumerate(sorted(alts)):
        atm = isa(h)
        env = _envelope_eas(h, vd, md)
        req = None if env is None else margin * env
        top = v_max
        if top is None and req is not None:
            top = _search_top(model, atm, 1.3 * req * math.sqrt(RHO0 / atm.density))
        r = flutter_at(
            model, atm, compressibility=compressibility, v_max=top, mach_start=mach, **kw
        )
        if r.compressibility and r.flutter_mach is not None:
            mach = r.flutter_mach  # the next altitude starts from this one's match

        searched = r.eas(r.searched_up_to)
        p = EnvelopePoint(
            altitude=atm.altitude,
            density=atm.density,
            speed_of_sound=atm.speed_of_sound,
            flutter_speed=r.flutter_speed,
            flutter_eas=r.flutter_eas,
            flutter_mach=r.flutter_mach,
            flutter_frequency=r.flutter_frequency,
            divergence_speed=r.divergence_speed,
            divergence_eas=r.divergence_eas,
            divergence_mach=r.divergence_mach,
            searched_eas=searched,
            envelope_eas=env,
            required_eas=req,
            warnings=list(r.warnings),
        )
        if req is not None:
            ok_f = (p.flutter_eas or np.inf) >= req and (
                p.flutter_eas is not None or searched >= req
            )
            ok_d = p.divergence_eas is None or p.divergence_eas >= req
            p.margin_ok = bool(ok_f and ok_d)
        points.append(p)
        if progress is not None:
            progress(i + 1)
    return Envelope(
        points=points,
        vd=vd,
        md=md,
        margin=margin,
        compressibility=compressibility if compressibility not in (None, "none") else None,
        damping=model.damping.describe() if hasattr(model, "damping") else "none",
        wing=getattr(getattr(model, "wing", None), "name", ""),
    )


def _search_top(model, atm, wanted: float) -> float:
    """The boundary's default range at this density, raised to ``wanted`` [m/s TAS]."""
    from ..stability.boundary import default_v_max
    from ..stability.divergence import divergence_speeds

    system = model.system(atm.density)
    lam, _ = system.modes_at_rest(min(2, system.n_q))
    default = default_v_max(system.semichord, float(abs(lam[-1])), divergence_speeds(system))
    return max(default, wanted)
