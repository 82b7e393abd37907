"""One altitude of a flutter envelope (:class:`EnvelopePoint`) and the checks of a saved one
(:mod:`aeroservo.studies.envelope`)."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

from ..errors import InputError, check_number

__all__ = ["EnvelopePoint"]


@dataclass
class EnvelopePoint:
    """Flutter and divergence at one altitude (SI units; None: not found below the search).

    ``searched_eas`` is the top of the search as an EAS [m/s]; ``envelope_eas`` and
    ``required_eas`` the design envelope and ``margin`` x it [m/s EAS] (None without V_D/M_D).
    """

    altitude: float
    density: float
    speed_of_sound: float
    flutter_speed: float | None
    flutter_eas: float | None
    flutter_mach: float | None
    flutter_frequency: float | None
    divergence_speed: float | None
    divergence_eas: float | None
    divergence_mach: float | None
    searched_eas: float
    envelope_eas: float | None = None
    required_eas: float | None = None
    margin_ok: bool | None = None
    warnings: list = field(default_factory=list)

    def to_dict(self) -> dict:
        out = asdict(self)
        if self.envelope_eas is None:
            for k in ("envelope_eas", "required_eas", "margin_ok"):
                out.pop(k)
        return out


def _optional_number(key: str, value: object) -> float | None:
    return None if value is None else check_number(key, value)


def _checked_point(i: int, p: object, names: set) -> dict:
    """The fields of a saved envelope point, with their types checked."""
    if not isinstance(p, dict):
        raise InputError(f"points[{i}] = {p!r}: expected an object")
    out = {k: v for k, v in p.items() if k in names}
    for k, v in out.items():
        if k == "warnings":
            if not isinstance(v, list) or not all(isinstance(w, str) for w in v):
                raise InputError(f"points[{i}].warnings = {v!r}: expected a list of strings")
        elif k == "margin_ok":
            if v is not None and not isinstance(v, bool):
                raise InputError(f"points[{i}].margin_ok = {v!r}: expected true, false or null")
        elif k == "altitude":
            out[k] = check_number(f"points[{i}].altitude", v, unit="m", lo=-1000.0, hi=47000.0)
        else:  # densities, speeds, Mach numbers, frequencies: positive where given
            out[k] = _optional_number(f"points[{i}].{k}", v)
            if out[k] is not None and out[k] < 0:
                raise InputError(f"points[{i}].{k} = {out[k]:g}: must be >= 0")
    return out
