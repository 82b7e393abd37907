"""A wing file as one model: the wing, its mesh and aerodynamics, its structural damping and its
flight condition, exactly as ``aeroservo flutter FILE`` and ``aeroservo export FILE`` use them.

``load_wing`` returns the parts (a :class:`~aeroservo.structure.wing.Wing` and the
``[analysis]``/``[damping]`` options); building the model from the wing alone silently drops
the file's elements, Wagner set, damping, density and altitude. :func:`load_model` keeps them::

    case = aes.load_model("my.toml")
    result = case.flutter()                 # = aeroservo flutter my.toml
    sys = case.statespace(150.0)            # = aeroservo export my.toml --speed 150
    case.model, case.density                # the AeroelasticModel and the air density
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ..aero.atmosphere import Atmosphere, isa
from ..errors import InputError
from ..structure.wing import Wing
from ..system.aeroelastic import AeroelasticModel
from .wing_file import AnalysisOptions, resolve_wing

__all__ = ["WingModel", "correction_mach", "load_model"]


@dataclass(frozen=True)
class WingModel:
    """A wing file's model and flight condition (from :func:`load_model`).

    Attributes
    ----------
    wing : Wing
    model : AeroelasticModel
        Meshed with the file's ``elements``, ``wagner`` and ``[damping]``.
    options : AnalysisOptions
        The file's ``[analysis]`` and ``[damping]`` tables (defaults where absent).
    atmosphere : Atmosphere or None
        The standard atmosphere of ``altitude`` / ``altitude_ft`` (None: density only).
    density : float
        Air density [kg/m^3].
    source : str
        The file (or built-in wing name) it came from.
    """

    wing: Wing
    model: AeroelasticModel
    options: AnalysisOptions
    atmosphere: Atmosphere | None
    density: float
    source: str = ""

    @property
    def compressibility(self) -> str | None:
        """``"prandtl-glauert"`` or None."""
        return self.options.compressibility

    def flutter(self, **kw):
        """Flutter and divergence as ``aeroservo flutter`` computes them for this file.

        Parameters
        ----------
        **kw
            Override the file's ``v_max`` [m/s] and ``n_modes``, or pass other arguments of
            :func:`aeroservo.flutter_boundary` (``rtol``, ``progress``, ...).

        Returns
        -------
        FlutterResult
        """
        kw = {"v_max": self.options.v_max, "n_modes": self.options.n_modes, **kw}
        if self.atmosphere is not None:
            from ..stability.matched import flutter_at

            return flutter_at(
                self.model, self.atmosphere, compressibility=self.compressibility, **kw
            )
        from ..stability.boundary import flutter_boundary

        return flutter_boundary(self.model, self.density, **kw)

    def mach_at(self, speed: float) -> float:
        """Mach number of the file's compressibility correction at ``speed`` [m/s] (0 without
        one): ``V / a`` at the file's altitude, as ``aeroservo export`` uses it."""
        return correction_mach(speed, self.atmosphere, self.compressibility, "mach (speed / a)")

    def statespace(self, speed: float, inputs=None, outputs=None, **kw):
        """The linear model at ``speed`` [m/s] and the file's density (and Mach number, with
        the file's compressibility), as ``aeroservo export`` writes it (structural damping
        included); arguments as :func:`aeroservo.statespace`."""
        from ..linear.models import statespace

        kw.setdefault("mach", self.mach_at(speed))
        return statespace(self.model, speed, self.density, inputs, outputs, **kw)


def correction_mach(
    speed: float, atmosphere: Atmosphere | None, compressibility: str | None, field: str = "mach"
) -> float:
    """The Mach number of a linear model at ``speed`` [m/s]: ``V / a`` of the atmosphere with
    a compressibility correction, 0 without one (``field`` names it in the error at Mach 0.9)."""
    if compressibility is None or atmosphere is None:
        return 0.0
    from ..system.first_order import check_mach

    return check_mach(speed / atmosphere.speed_of_sound, field)


def load_model(
    path: str | Path, *, elements: int | None = None, wagner: object = None
) -> WingModel:
    """The model a wing file (or built-in wing name) describes, its settings included.

    Parameters
    ----------
    path : str or Path
        Wing file (``docs/wing-file.md``) or a built-in wing (``"goland"``,
        ``"goland_aileron"``).
    elements : int, optional
        Override the file's number of beam elements.
    wagner : str or dict, optional
        Override the file's Wagner set.

    Returns
    -------
    WingModel
        ``.model``, ``.density``, ``.flutter()``, ``.statespace(speed, ...)``.
    """
    if not isinstance(path, (str, Path)):
        raise InputError(f"path = {path!r}: expected a wing file name or a built-in wing name")
    wing, opts = resolve_wing(path)
    atm = isa(opts.altitude) if opts.altitude is not None else None
    density = atm.density if atm is not None else opts.density
    model = AeroelasticModel(
        wing,
        opts.elements if elements is None else elements,
        opts.wagner if wagner is None else wagner,
        damping=opts.damping,
    )
    return WingModel(wing, model, opts, atm, density, str(path))
