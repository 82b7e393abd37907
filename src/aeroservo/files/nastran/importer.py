"""Nastran beam models in: a cantilever stick model deck as an aeroservo wing file.

``import_nastran(deck, semichord=..., elastic_axis=...)`` returns the :class:`Wing`;
``read_nastran`` also returns the wing file text, with a comment on every value saying which
card (or option) it came from, and what was left out; ``write_nastran_wing`` writes it
atomically. Reading needs pyNastran (``pip install 'aeroservo[nastran]'``). Mapping card by
card, and what a deck must give: ``docs/nastran.md``.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ...errors import InputError
from ...structure.wing import Wing
from ..wing_file import wing_from_dict, wing_toml
from .beam import beam_line, segments
from .case import (
    analysis_tables,
    box_counts,
    case_v_max,
    panel_geometry,
    scenario_text,
    surface_geometry,
)
from .companion import check_sections, import_options
from .deck import read_deck
from .reader import same_file, scan_deck
from .units import chord_hint, span_hint
from .wing_masses import point_masses

__all__ = [
    "NastranImport",
    "import_nastran",
    "read_nastran",
    "write_nastran_wing",
    "scenario_path",
]


@dataclass(frozen=True)
class NastranImport:
    """An imported wing, its wing file text (with comments) and a one-line summary."""

    wing: Wing
    text: str
    summary: str
    left_out: tuple[str, ...]
    scenario: str | None = None  # the deck's flutter case as a flutter scenario (TOML)
    aero: object | None = None  # the deck's aerodynamic cards (files/nastran/aero.AeroDeck)


def import_nastran(deck: str | Path, **options) -> Wing:
    """The wing of a Nastran stick-model deck.

    Parameters
    ----------
    deck : str or Path
        Bulk data of a cantilever beam (GRID, GRDSET, CORD1R/CORD2R, CBAR/CBEAM, PBAR/PBARL/
        PBEAM/PBEAML, MAT1, CONM2, CONM1, CMASS1/CMASS2, SPC/SPC1) with, optionally, its
        aerodynamic and flutter cards (AERO, CAERO1, SPLINE1/2, SET1, AESURF, AELIST,
        MKAERO1/2, FLFACT, FLUTTER); ``PARAM,WTMASS`` is applied.
    **options
        ``units`` (``"si"``, ``"in-lbf-s"``, ``"ft-slug-s"``, ``"mm-t-s"``; default SI),
        ``chord`` or ``semichord`` [m, normal to the beam; default from the CAERO1 panels],
        ``elastic_axis`` (a, semichords aft of mid-chord), ``x_alpha`` [-], ``inertia``
        [kg m], ``name``, ``companion`` (a TOML table, ``docs/nastran.md``).

    Raises
    ------
    InputError
        One line: what cannot be mapped (branching, a beam out of the wing plane, offsets,
        missing properties, unsupported cards, no clamp) or a missing chord.
    """
    return read_nastran(deck, **options).wing


def read_nastran(
    deck: str | Path,
    *,
    chord: float | None = None,
    semichord: float | None = None,
    elastic_axis: float | None = None,
    x_alpha: float | None = None,
    inertia: float | None = None,
    name: str | None = None,
    companion: str | Path | None = None,
    units: str | None = None,
    wing_file: str | Path = "wing.toml",
) -> NastranImport:
    """Import a deck: the wing, the commented wing file text, a summary and the flutter
    scenario of its aero and flutter cards (see :func:`import_nastran` for the parameters;
    ``wing_file`` is the name the scenario gives the wing file)."""
    path = Path(deck)
    opts = import_options(
        companion,
        chord=chord,
        semichord=semichord,
        elastic_axis=elastic_axis,
        x_alpha=x_alpha,
        inertia=inertia,
        name=name,
    )
    data = read_deck(path, units)
    aero = data.aero
    if aero is not None and not _given_flow(opts):
        opts = replace(opts, free_stream=aero.flow)
    root, line = beam_line(data, opts)
    check_sections(opts, [0.5 * (be.start + be.end) for be in line], line[-1].end, data.units)
    mass, heaviest = _deck_mass(data, line)
    span_hint(path, line[-1].end, mass, data.units, _given_mass(opts), heaviest)
    geometry, surface_geo = {}, {}
    if aero is not None:
        geometry = panel_geometry(path, aero, line, data.grids, opts.up)
        surface_geo = surface_geometry(aero, line, data.grids, opts.up)
    try:
        segs, headers, sources = segments(line, opts, geometry)
    except InputError as exc:
        raise InputError(f"{path}: {_unit_text(exc, data.units)}") from None
    masses, mass_notes, left = point_masses(data, root, line, opts.up)
    span = line[-1].end
    chord_hint(path, span, segs, sources, data.units)
    surfaces = ()
    if opts.control_surfaces:
        rows = [{k: getattr(s, k) for k in _SEGMENT_KEYS} for s in segs]
        tables = [{**surface_geo.get(t.get("name"), {}), **t} for t in opts.control_surfaces]
        try:
            surfaces = wing_from_dict(
                {"span": span, "segments": rows, "control_surfaces": tables}
            ).control_surfaces
        except InputError as exc:
            msg = str(exc).replace("wing.control_surfaces", "control_surfaces")
            raise InputError(f"{opts.companion}: {msg}") from None
    try:
        wing = Wing(
            span=span,
            segments=tuple(segs),
            control_surfaces=surfaces,
            name=opts.name or path.stem,
            masses=tuple(masses),
        )
    except InputError as exc:
        raise InputError(f"{path}: {_unit_text(exc, data.units)}") from None
    left = [*left, *_unused_grids(data, line, root)]
    notes = [data.units.describe(), *data.notes]
    tables, scenario = "", None
    if aero is not None:
        v_max = case_v_max(aero, _frequencies(wing, len(line), aero))
        pieces = len(wing.segments) + 2 * len(wing.control_surfaces)
        boxes = box_counts(aero, opts.up, pieces, notes) if aero.panels else (0, 0)
        try:
            tables = analysis_tables(aero, len(line), boxes, v_max)
        except InputError as exc:
            raise InputError(f"{path}: {exc}") from None
        notes += _surface_notes(aero, surface_geo, surfaces)
        args = (str(wing_file), wing.name, path, data.units, len(line), boxes, v_max)
        scenario = scenario_text(aero, *args)
    text = _commented(wing, path, opts, headers, sources, mass_notes, notes, left) + (
        f"\n{tables}" if tables else ""
    )
    sweeps = [s.sweep for s in segs]
    swept = (
        ""
        if not any(sweeps)
        else f", sweep {min(sweeps) * 57.29577951308232:.3g} to "
        f"{max(sweeps) * 57.29577951308232:.3g} deg"
    )
    summary = (
        f"{len(line)} elements in {len(segs)} segment{'s' * (len(segs) != 1)} over "
        f"{span:.6g} m{swept}, {len(masses)} concentrated mass{'es' * (len(masses) != 1)}, "
        f"{len(surfaces)} control surface{'s' * (len(surfaces) != 1)}"
        + (f"; left out: {'; '.join(left)}" if left else "")
    )
    if aero is not None:
        summary += f"; {len(aero.panels)} CAERO1 panel{'s' * (len(aero.panels) != 1)}"
        if aero.flutter is not None:
            summary += f", flutter case {aero.flutter.cards}"
    return NastranImport(wing, text, summary, tuple(left), scenario, aero)


def scenario_path(out: str | Path) -> Path:
    """Where the flutter scenario of a wing file ``out`` goes: ``<stem>_flutter.toml``."""
    out = Path(out)
    return out.with_name(f"{out.stem}_flutter.toml")


def write_nastran_wing(deck: str | Path, out: str | Path, **options) -> NastranImport:
    """Import ``deck`` and write its wing file to ``out``, and its flutter case to
    :func:`scenario_path` when it has one, as one set (nothing on failure)."""
    from ...atomic import atomic_write_set, check_output_path

    check_output_path(out, "--out")
    included = scan_deck(deck)[1][1:]  # the deck checked before anything is computed
    inputs = {"the deck": deck, "the companion table": options.get("companion")}
    inputs |= {f"a file the deck INCLUDEs ({f.name})": f for f in included}
    _not_an_input("--out", out, inputs)
    result = read_nastran(deck, wing_file=Path(out).name, **options)
    files = [(Path(out), result.text)]
    if result.scenario is not None:
        _not_an_input("the flutter scenario", scenario_path(out), inputs)
        files.append((scenario_path(out), result.scenario))
    atomic_write_set([(p, lambda q, t=t: q.write_text(t, encoding="utf-8")) for p, t in files])
    return result


def _frequencies(wing: Wing, n_elements: int, aero) -> list[float]:
    """In-vacuo frequencies [Hz] of the modes a K or KE flutter case follows (LMODES, else 3)."""
    if aero.flutter is None or aero.flutter.velocities:
        return []
    from ...system.aeroelastic import AeroelasticModel

    try:  # one element per CBAR, unless the companion's surfaces need more breakpoints
        model = AeroelasticModel(wing, min(max(n_elements, 2), 300))
    except InputError:
        model = AeroelasticModel(wing, 300)
    n = min(aero.lmodes or 3, model.n_dofs)
    return list(model.natural_modes(n).frequencies)


def _unit_text(exc: InputError, units) -> str:
    """A wing check's unit hint, told which units the deck was read in."""
    return str(exc).replace(
        "check the units [SI]",
        f"the deck was read as {units.name} (--units) and converted to SI; options and "
        "companion values are SI: check both",
    )


def _not_an_input(what: str, out: Path | str, inputs: dict) -> None:
    """Refuse an output that would overwrite an input file (the same path, through links)."""
    for name, path in inputs.items():
        if path is not None and same_file(out, path):
            raise InputError(f"{what} = {out}: that is {name}; name another file")


def _deck_mass(data, line) -> tuple[float, str]:
    """The mass the deck gives its beam line [kg] (its sections' and its mass cards') and the
    card that gives more than half of it ('' if none)."""
    parts = {f"{pm.card} {pm.eid} at GRID {pm.grid}": pm.mass for pm in data.masses}
    for be in line:
        sec = be.element.section
        parts[sec.label] = parts.get(sec.label, 0.0) + (sec.rho * sec.A + sec.nsm) * (
            be.end - be.start
        )
    total = sum(parts.values())
    big = max(parts, key=parts.get) if parts else ""
    return total, big if big and parts[big] > 0.5 * total else ""


def _given_mass(opts) -> bool:
    """Whether the options or the companion table give a mass per length."""
    return "mass" in opts.defaults or any("mass" in s.values for s in opts.sections)


def _given_flow(opts) -> bool:
    """Whether the companion table gave a flow direction other than the default +X."""
    return not np.allclose(opts.free_stream, [1.0, 0.0, 0.0])


def _surface_notes(aero, geometry: dict, surfaces) -> list[str]:
    """One note per AESURF: the control surface it gives, or what to add to use it."""
    named = {cs.name for cs in surfaces}
    out = []
    for label, geo in geometry.items():
        where = (
            f"AESURF {label}: {geo['start']:.6g} to {geo['end']:.6g} m along the beam, hinge "
            f"{geo['hinge']:.6g} semichords aft of mid-chord (its boxes' forward edge)"
        )
        if label in named:
            out.append(f"{where}: the control surface '{label}'")
        else:
            out.append(
                f'{where}: not in the wing; give [[control_surfaces]] name = "{label}" with its '
                "inertia, static moment and hinge stiffness in the companion table to add it"
            )
    return out


_SEGMENT_KEYS = ("start", "end", "semichord", "a", "mass", "x_alpha", "inertia", "EI", "GJ")


def _unused_grids(deck, line, root) -> list[str]:
    on_line = {root} | {be.outboard for be in line}
    extra = sorted(set(deck.grids) - on_line)
    if not extra:
        return []
    shown = ", ".join(str(g) for g in extra[:6]) + ("..." if len(extra) > 6 else "")
    return [f"GRID {shown} (on no beam element)"]


_KEY = re.compile(r"^(\w+) = ")


def _commented(wing, path, opts, headers, sources, mass_notes, notes, left) -> str:
    """:func:`wing_toml` with a header and a comment on each imported value."""
    head = [
        f"# Imported from the Nastran deck {path.name} by 'aeroservo import nastran'",
        "# (docs/nastran.md). Spanwise stations are along the beam line (the elastic axis)",
        "# from the clamped root; every value says where it came from. Edit freely.",
    ]
    if opts.companion:
        head.append(f"# Companion table: {opts.companion}")
    head += [f"# {n}" for n in notes]
    head += [f"# Left out: {item}" for item in left]
    out = []
    block, index = None, {"segments": -1, "masses": -1}
    for line in wing_toml(wing).splitlines():
        if line == "[[wing.segments]]":
            block = "segments"
            index[block] += 1
            out += [f"# {headers[index[block]]}", line]
            continue
        if line == "[[wing.masses]]":
            block = "masses"
            index[block] += 1
            out += [f"# {mass_notes[index[block]]}", line]
            continue
        if line.startswith("[["):
            block = None
        m = _KEY.match(line)
        if block == "segments" and m:
            src = sources[index["segments"]]
            key = m.group(1)
            comment = src.get(key) or ("along the beam line" if key in ("start", "end") else "")
            line = f"{line}  # {comment}" if comment else line
        out.append(line)
    return "\n".join(head) + "\n" + "\n".join(out) + "\n"
