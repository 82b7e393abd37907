"""A wing file as one model: the wing, its mesh and aerodynamics, its structural damping and its
flight condition, exactly as ``aeroservo flutter FILE`` and ``aeroservo export FILE`` use them.

``load_wing`` returns the parts (a :class:`~aeroservo.structure.wing.Wing` and the
``[analysis]``/``[damping]``/``[dlm]`` options); building the model from the wing alone silently
drops the file's elements, Wagner set, damping, aerodynamic model, Mach number, density and
altitude. :func:`load_model` keeps them::

    case = aes.load_model("my.toml")
    result = case.flutter()                 # = aeroservo flutter my.toml
    sys = case.statespace(150.0)            # = aeroservo export my.toml --speed 150
    case.model, case.density                # the AeroelasticModel and the air density
"""

from __future__ import annotations

from dataclasses import dataclass, replace
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
        Meshed with the file's ``elements``, ``wagner``, ``[damping]`` and aerodynamic model
        (``aero``, ``[dlm]``).
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
        """``"prandtl-glauert"``, ``"matched"`` or None."""
        return self.options.compressibility

    @property
    def mach(self) -> float | None:
        """The file's fixed Mach number (None: not given; 0 or matched, see :meth:`mach_at`)."""
        return self.options.mach

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
        from ..studies.flight_condition import flutter_at_condition

        kw = {"v_max": self.options.v_max, "n_modes": self.options.n_modes, **kw}
        mach = kw.pop("mach", self.mach)  # a fixed Mach number (at the altitude's density)
        comp = None if mach is not None else self.compressibility
        return flutter_at_condition(self.model, self.density, self.atmosphere, comp, mach, **kw)

    def mach_at(self, speed: float) -> float:
        """Mach number of the aerodynamics at ``speed`` [m/s], as ``aeroservo export`` uses it:
        the file's fixed ``mach``, else ``V / a`` at the file's altitude with its
        compressibility, else 0."""
        if self.mach is not None:
            return self.mach
        return correction_mach(
            speed, self.atmosphere, self.compressibility, "mach (speed / a)", self.model
        )

    def statespace(self, speed: float, inputs=None, outputs=None, **kw):
        """The linear model at ``speed`` [m/s] and the file's density (and Mach number, with
        the file's compressibility), as ``aeroservo export`` writes it (structural damping
        included); arguments as :func:`aeroservo.statespace`."""
        from ..linear.models import statespace

        kw.setdefault("mach", self.mach_at(speed))
        return statespace(self.model, speed, self.density, inputs, outputs, **kw)


def correction_mach(
    speed: float,
    atmosphere: Atmosphere | None,
    compressibility: str | None,
    field: str = "mach",
    model: AeroelasticModel | None = None,
) -> float:
    """The Mach number of a linear model at ``speed`` [m/s]: ``V / a`` of the atmosphere with
    a compressibility correction (matched), 0 without one (``field`` names it in the error at
    Mach 0.9, the Prandtl-Glauert limit, or at Mach 1 for a doublet-lattice ``model``)."""
    if compressibility in (None, "none") or atmosphere is None:
        return 0.0
    from .aero_tables import check_model_mach

    aero = None if model is None else model.aero
    return check_model_mach(aero, speed / atmosphere.speed_of_sound, field)


def load_model(
    path: str | Path,
    *,
    elements: int | None = None,
    wagner: object = None,
    aero: object = None,
    mach: float | None = None,
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
    aero : {"strip", "dlm"}, dict or DoubletLattice, optional
        Override the file's aerodynamic model (``aero`` and ``[dlm]``).
    mach : float, optional
        Override the file's fixed Mach number (and its matched compressibility).

    Returns
    -------
    WingModel
        ``.model``, ``.density``, ``.flutter()``, ``.statespace(speed, ...)``.
    """
    if not isinstance(path, (str, Path)):
        raise InputError(f"path = {path!r}: expected a wing file name or a built-in wing name")
    wing, opts = resolve_wing(path)
    if aero is not None:
        from ..aero.dlm_settings import as_aero

        opts = replace(opts, aero=as_aero(aero))
    if mach is not None:
        from .aero_tables import check_model_mach

        opts = replace(opts, mach=check_model_mach(opts.aero, mach), compressibility=None)
    atm = isa(opts.altitude) if opts.altitude is not None else None
    density = atm.density if atm is not None else opts.density
    model = AeroelasticModel(
        wing,
        opts.elements if elements is None else elements,
        opts.wagner if wagner is None else wagner,
        damping=opts.damping,
        aero="strip" if opts.aero is None else opts.aero,
    )
    return WingModel(wing, model, opts, atm, density, str(path))
