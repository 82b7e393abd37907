"""The aerodynamic model of a file: ``aero = "strip" | "dlm"``, a fixed ``mach`` and a table of
:class:`~aeroservo.aero.dlm_settings.DoubletLattice` keys.

Wing files have ``aero`` and ``mach`` in ``[analysis]`` and the settings in a top-level
``[dlm]`` table (``docs/wing-file.md``); scenario files have them in ``[model]`` and
``[model.dlm]`` (``docs/scenarios.md``); optimization files in ``[optimize]`` and ``[dlm]``.
Every error names the key and the value (the callers add the file).
"""

from __future__ import annotations

from collections.abc import Mapping

from ..errors import InputError, show_value
from .toml_tables import Table, _key

__all__ = [
    "AERO_CHOICES",
    "aero_options",
    "dlm_settings",
    "dlm_toml",
    "check_model_mach",
    "model_aero",
]

AERO_CHOICES = ("strip", "dlm")
"""Values of ``aero`` (as :data:`aeroservo.aero.dlm_settings.AERO_MODELS`)."""


def check_model_mach(aero: object, mach: object, field: str = "mach") -> float:
    """A fixed Mach number of a model's aerodynamics: ``0 <= M < 1`` for the doublet lattice
    (``aero`` not None), ``0 <= M < 0.9`` for strip theory (the Prandtl-Glauert correction)."""
    if aero is not None:
        from ..aero.dlm import check_dlm_mach

        return check_dlm_mach(mach, field)
    from ..system.first_order import check_mach

    return check_mach(mach, field)


def dlm_settings(data: object, where: str = "dlm"):
    """A :class:`~aeroservo.aero.dlm_settings.DoubletLattice` from a table of its keys; an
    unknown key or a bad value is one line naming ``<where>.<key>`` and the value."""
    from ..aero.dlm_settings import DoubletLattice

    if not isinstance(data, Mapping):
        raise InputError(f"{where} = {show_value(data)}: expected a table of doublet-lattice keys")
    known = sorted(DoubletLattice.__dataclass_fields__)
    for k, v in data.items():
        if k not in known:
            raise InputError(
                f"{where}.{_key(k)} = {show_value(v)}: unknown key; allowed keys are {known}"
            )
    try:
        return DoubletLattice(**data)
    except InputError as exc:
        msg = str(exc)
        raise InputError(where + msg[3:] if msg.startswith("dlm.") else msg) from None


def aero_options(
    values: Mapping,
    where: str,
    dlm: object = None,
    dlm_where: str = "dlm",
    compressibility: str | None = None,
) -> tuple:
    """``(settings, mach)`` of a table with optional ``aero`` and ``mach`` keys.

    Parameters
    ----------
    values : mapping
        The table (``[analysis]``, ``[model]``, ``[optimize]``).
    where : str
        Its name in messages.
    dlm : mapping, optional
        The table of doublet-lattice settings (refused unless ``aero = "dlm"``).
    dlm_where : str
        Its name in messages.
    compressibility : str, optional
        The table's matched compressibility (a fixed ``mach`` is refused with it).

    Returns
    -------
    settings : DoubletLattice or None
        None: strip theory.
    mach : float or None
        The fixed Mach number (None: not given).
    """
    aero = values.get("aero", "strip")
    if not isinstance(aero, str) or aero not in AERO_CHOICES:
        raise InputError(
            f"{where}.aero = {show_value(aero)}: allowed values are {list(AERO_CHOICES)}"
        )
    if dlm is not None and aero != "dlm":
        raise InputError(
            f'{dlm_where}: doublet-lattice settings need {where}.aero = "dlm" (the model is '
            f"{'strip theory' if aero == 'strip' else aero})"
        )
    settings = dlm_settings({} if dlm is None else dlm, dlm_where) if aero == "dlm" else None
    mach = None
    if "mach" in values:
        if compressibility not in (None, "none"):
            raise InputError(
                f"{where}.mach = {show_value(values['mach'])}: give a fixed Mach number or "
                f"{where}.compressibility = {compressibility!r} (Mach matched to the speed), "
                "not both"
            )
        mach = check_model_mach(settings, values["mach"], f"{where}.mach")
    return settings, mach


def model_aero(md: Table, kw: dict, fixed_mach: bool, section: bool) -> None:
    """``model.aero``, ``model.mach`` and ``[model.dlm]`` of a scenario into ``kw`` (``aero``:
    DoubletLattice or None, ``mach``: float or None); ``fixed_mach``: whether the scenario's
    kind takes a fixed Mach number, ``section``: whether it describes a typical section."""
    if not (md.has("aero") or md.has("mach") or md.has("dlm")):
        return
    try:
        aero, mach = aero_options(
            md.data, md.where, md.data.get("dlm"), f"{md.where}.dlm", kw.get("compressibility")
        )
    except InputError as exc:
        raise InputError(f"{md.file}: {exc}") from None
    if aero is not None and section:
        md.fail(
            "aero",
            "dlm",
            "the typical section ([section]) has strip aerodynamics only; give a [wing] for "
            "the doublet lattice",
        )
    if mach is not None and not fixed_mach:
        md.fail(
            "mach",
            mach,
            "only flutter scenarios take a fixed Mach number (the control loops of the other "
            "kinds are built at Mach 0)",
        )
    kw["aero"], kw["mach"] = aero, mach


def dlm_toml(settings) -> list:
    """The lines of a ``[dlm]`` table with the settings that differ from the defaults (read
    back by :func:`dlm_settings` as the same settings); none for None (strip theory)."""
    if settings is None:
        return []
    import dataclasses
    import json

    lines = ["", "[dlm]"]
    for f in dataclasses.fields(settings):
        v = getattr(settings, f.name)
        if v is None or v == f.default:
            continue
        if isinstance(v, tuple):
            lines.append(f"{f.name} = [{', '.join(repr(float(x)) for x in v)}]")
        elif isinstance(v, bool):
            lines.append(f"{f.name} = {'true' if v else 'false'}")
        else:
            lines.append(f"{f.name} = {json.dumps(v) if isinstance(v, str) else repr(v)}")
    return lines
