"""Nastran beam models in: a cantilever stick model deck as an aeroservo wing file.

``import_nastran(deck, semichord=..., elastic_axis=...)`` returns the :class:`Wing`;
``read_nastran`` also returns the wing file text, with a comment on every value saying which
card (or option) it came from, and what was left out; ``write_nastran_wing`` writes it
atomically. Reading needs pyNastran (``pip install 'aeroservo[nastran]'``). Mapping card by
card, and what a deck must give: ``docs/nastran.md``.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from ..errors import InputError
from ..structure.wing import Wing
from .nastran_beam import beam_line, point_masses, segments
from .nastran_companion import import_options
from .nastran_deck import read_deck
from .wing_file import wing_from_dict, wing_toml

__all__ = ["NastranImport", "import_nastran", "read_nastran", "write_nastran_wing"]


@dataclass(frozen=True)
class NastranImport:
    """An imported wing, its wing file text (with comments) and a one-line summary."""

    wing: Wing
    text: str
    summary: str
    left_out: tuple[str, ...]


def import_nastran(deck: str | Path, **options) -> Wing:
    """The wing of a Nastran stick-model deck.

    Parameters
    ----------
    deck : str or Path
        Bulk data of a cantilever beam (GRID, CORD1R/CORD2R, CBAR/CBEAM, PBAR/PBARL/PBEAM,
        MAT1, CONM2, CMASS2, SPC/SPC1), SI units (N, m, kg; ``PARAM,WTMASS`` is applied).
    **options
        ``chord`` or ``semichord`` [m], ``elastic_axis`` (a, semichords aft of mid-chord),
        ``x_alpha`` [-], ``inertia`` [kg m], ``name``, ``companion`` (a TOML table,
        ``docs/nastran.md``).

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
) -> NastranImport:
    """Import a deck: the wing, the commented wing file text and a summary (see
    :func:`import_nastran` for the parameters)."""
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
    data = read_deck(path)
    root, line = beam_line(data, opts)
    try:
        segs, headers, sources = segments(line, opts)
    except InputError as exc:
        raise InputError(f"{path}: {exc}") from None
    masses, mass_notes, left = point_masses(data, root, line, opts.up)
    span = line[-1].end
    surfaces = ()
    if opts.control_surfaces:
        rows = [{k: getattr(s, k) for k in _SEGMENT_KEYS} for s in segs]
        try:
            surfaces = wing_from_dict(
                {"span": span, "segments": rows, "control_surfaces": opts.control_surfaces}
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
        raise InputError(f"{path}: {exc}") from None
    left = [*left, *_unused_grids(data, line, root)]
    notes = list(data.notes)
    text = _commented(wing, path, opts, headers, sources, mass_notes, notes, left)
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
    return NastranImport(wing, text, summary, tuple(left))


def write_nastran_wing(deck: str | Path, out: str | Path, **options) -> NastranImport:
    """Import ``deck`` and write its wing file to ``out`` atomically (nothing on failure)."""
    from ..atomic import atomic_write_text, check_output_path

    check_output_path(out, "--out")
    result = read_nastran(deck, **options)
    atomic_write_text(out, result.text)
    return result


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
