"""What a loop's stability margins must be, and where they are judged.

MIL-F-9490D (sec. 3.1.3.6) asks 6 dB of gain margin both ways and 45 deg of phase margin at
each actuator, one loop at a time; a simultaneous (disk) margin, a delay margin and the same
requirement at the sensors are the usual additions (Seiler, Packard and Gahinet, "An
introduction to disk margins", IEEE Control Systems 40(5), 2020). A controller file's
``[margins]`` table is read into :class:`MarginRequirement`.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import InputError, check_number

__all__ = ["MarginRequirement", "BREAK_POINT_KEYS"]


BREAK_POINT_KEYS = ("inputs", "sensors", "multiloop")
"""Where a requirement may be judged (``MarginRequirement.at``)."""


@dataclass(frozen=True)
class MarginRequirement:
    """Stability-margin requirement at the actuator (controller file ``[margins]``).

    Attributes
    ----------
    gain_db : float
        Required gain margin, both ways [dB] (MIL-F-9490D: 6).
    phase_deg : float
        Required phase margin [deg] (MIL-F-9490D: 45).
    disk_alpha : float or None
        If set, the balanced disk margin ``alpha`` required instead of the gain and phase
        margins (e.g. 0.67 tolerates +-6 dB and +-37 deg simultaneously).
    delay_ms : float or None
        If set, the delay margin required [ms] (the pure time delay the loop tolerates).
    at : tuple of str
        Where it is judged (:data:`BREAK_POINT_KEYS`): ``"inputs"`` (each actuator command,
        the default), ``"sensors"`` (each sensor), ``"multiloop"`` (all inputs at once: the
        simultaneous disk margin must cover the gain and phase, or ``disk_alpha``).
    """

    gain_db: float = 6.0
    phase_deg: float = 45.0
    disk_alpha: float | None = None
    delay_ms: float | None = None
    at: tuple = ("inputs",)

    def __post_init__(self) -> None:
        check_number("margins.gain_db", self.gain_db, unit="dB", lo=0.0)
        check_number("margins.phase_deg", self.phase_deg, unit="deg", lo=0.0, hi=180.0)
        if self.disk_alpha is not None:
            check_number("margins.disk_alpha", self.disk_alpha, lo=0.0, hi=2.0, lo_open=True)
        if self.delay_ms is not None:
            check_number("margins.delay_ms", self.delay_ms, unit="ms", lo=0.0, hi=1e4)
        at = (self.at,) if isinstance(self.at, str) else tuple(self.at)
        bad = [a for a in at if a not in BREAK_POINT_KEYS]
        if bad or not at or len(set(at)) != len(at):
            raise InputError(
                f"margins.at = {list(at)!r}: expected distinct break points among "
                f"{list(BREAK_POINT_KEYS)}"
            )
        object.__setattr__(self, "at", at)

    def describe(self) -> str:
        """The requirement in words (``6 dB, 45 deg, 10 ms at inputs, sensors``)."""
        parts = (
            [f"a disk margin of {self.disk_alpha:g}"]
            if self.disk_alpha is not None
            else [f"{self.gain_db:g} dB", f"{self.phase_deg:g} deg"]
        )
        if self.delay_ms is not None:
            parts.append(f"a delay margin of {self.delay_ms:g} ms")
        return ", ".join(parts) + f" at the {', '.join(self.at)}"
