"""The outputs of a scenario run, written as one set (:func:`write_run`).

A flutter run writes ``<result>.json`` and ``<result>_vg.png``; a simulation writes
``<result>.npz`` (:mod:`aeroservo.files.results`), ``<result>.png``, ``<result>_margins.png``
(Nyquist, Bode, S and T at the actuator), ``<result>_boundary.png`` (closed-loop stability over
speed, the engaged range shaded) and ``<result>_margin_sweep.png`` (margins across the engaged
range) for a controlled linear loop, and ``<result>.json``; a trade study writes
``summary.json``, ``heatmap_<metric>.png`` (one per metric of
:data:`aeroservo.studies.trade.plots.HEATMAP_METRICS`) and ``pareto.png`` into its folder
``<result>/`` (next to its case store, ``<result>.csv`` and ``<result>.nc``); gust loads write
``<result>.json`` (summary and every record), ``<result>.npz`` (critical-gust histories),
``<result>.csv`` (limit loads), ``<result>_histories.csv`` (the critical gusts' time
histories), ``<result>_alleviation.csv`` (both loops) and the figures ``<result>_envelope.png``,
``<result>_correlated.png``, ``<result>_critical_gusts.png`` and ``<result>_spanwise.png`` (with
load stations) (:mod:`aeroservo.files.gust_loads_file`); limit cycles write ``<result>.json``,
``<result>.csv``, ``<result>_branches.csv``, ``<result>_histories.npz``, ``<result>_summary.txt``,
``<result>_bifurcation.png`` and ``<result>_histories.png`` (:mod:`aeroservo.files.lco_file`).
Every file of a
run is renamed into place only when all of them have been written
(:func:`aeroservo.atomic.atomic_write_set`), so a failed run leaves none behind.
"""

from __future__ import annotations

from pathlib import Path

from .._figures import detached
from ..atomic import atomic_write_set, figure_writer
from ..studies.runs import Run
from .results import result_writer
from .summaries import json_text

__all__ = ["write_run"]


def _text_writer(text: str):
    return lambda p: p.write_text(text, encoding="utf-8")


def write_run(run: Run, out_dir: str | Path) -> dict[str, str]:
    """Write the summary, result file and figures of a run; returns ``{kind: path}``.

    The paths are also recorded in ``run.summary["files"]`` (and so in the JSON summary).

    Parameters
    ----------
    run : Run
        From :func:`aeroservo.studies.runs.run_scenario`.
    out_dir : str or Path
        Output folder (must exist); a trade study writes into its own folder ``run.folder``.
    """
    with detached():  # figures written to files, not left in pyplot nor shown in a notebook
        return _write_run(run, Path(out_dir))


def _write_run(run: Run, out: Path) -> dict[str, str]:
    """:func:`write_run` into the folder ``out``."""
    files: dict[str, str] = {}
    items: list = []

    def add(kind: str, path: Path, writer) -> None:
        files[kind] = str(path)
        items.append((path, writer))

    summary_path = WRITERS[run.scenario.kind](run, out, add, files)
    run.summary["files"] = files
    if summary_path is not None:
        items.append((summary_path, _text_writer(json_text(run.summary))))
    atomic_write_set(items)
    return files


def _figure(add, name: str, png: Path, fig) -> None:
    add(name, png, figure_writer(fig, png, dpi=120))


def _flutter_files(run: Run, out: Path, add, files: dict) -> Path:
    """A flutter run's V-g figure; its summary is ``<result>.json``."""
    sc = run.scenario
    files["summary"] = str(out / f"{sc.result}.json")
    if sc.plots:
        from ..plots import plot_vg

        _figure(add, "vg_plot", out / f"{sc.result}_vg.png", plot_vg(run.flutter, title=run.title))
    return out / f"{sc.result}.json"


def _simulation_files(run: Run, out: Path, add, files: dict) -> Path:
    """A simulation's NPZ and figures: time histories, the closed-loop boundary, the margins
    and their sweep; its summary is ``<result>.json``."""
    sc = run.scenario
    npz = out / f"{sc.result}.npz"
    add("result", npz, result_writer(run.simulation, dict(run.summary)))
    if sc.plots:
        fig = run.simulation.plot(open_loop=run.open_loop)
        _figure(add, "plot", out / f"{sc.result}.png", fig)
        judged = getattr(run.judgement, "boundary", None)
        boundary = run.boundary if run.boundary is not None else judged
        if boundary is not None:
            e = run.judgement.engaged
            fig = boundary.plot(
                open_loop=run.flutter, engaged=(e.low, e.high), stable_to=e.stable_to
            )
            fig.axes[0].set_title(
                f"{sc.name}\nengaged {e.text()} (shaded), stability required to "
                f"{e.stable_to:.4g} m/s (dotted)",
                fontsize=9,
            )
            _figure(add, "boundary_plot", out / f"{sc.result}_boundary.png", fig)
        if run.margins is not None:
            from ..plots import plot_loop_margins, plot_margin_sweep

            fig = plot_loop_margins(run.margins, title=sc.name)
            _figure(add, "margins_plot", out / f"{sc.result}_margins.png", fig)
            if run.margin_sweep is not None:
                fig = plot_margin_sweep(run.margin_sweep, title=sc.name)
                _figure(add, "margin_sweep_plot", out / f"{sc.result}_margin_sweep.png", fig)
    files["summary"] = str(out / f"{sc.result}.json")
    return out / f"{sc.result}.json"


def _study_files(items_of, figures):
    """The writer of a study whose JSON holds its summary and records (gust loads, limit
    cycles): ``items_of(result, json_path, summary)`` gives its data files, ``figures(result)``
    its figures by file suffix."""

    def write(run: Run, out: Path, add, files: dict) -> None:
        sc = run.scenario
        data = items_of(run.result, out / f"{sc.result}.json", run.summary)
        for kind, (path, writer) in data.items():
            add(kind, path, writer)  # the JSON's text is made when written, files included
        for name, fig in figures(run.result).items() if sc.plots else ():
            _figure(add, f"{name}_plot", out / f"{sc.result}_{name}.png", fig)

    return write


def _gust_loads_files(run: Run, out: Path, add, files: dict) -> None:
    from ..studies.gust.scenario import gust_figures
    from .gust_loads_file import gust_loads_items

    return _study_files(gust_loads_items, gust_figures)(run, out, add, files)


def _lco_files(run: Run, out: Path, add, files: dict) -> None:
    from ..studies.lco.scenario import lco_figures
    from .lco_file import lco_items

    return _study_files(lco_items, lco_figures)(run, out, add, files)


def _trade_files(run: Run, out: Path, add, files: dict) -> Path:
    """A trade study's figures into its folder (its cases, CSV and NetCDF are written as they
    come); its summary is ``<result>/summary.json``."""
    res, folder = run.trade, run.folder
    files["csv"], files["netcdf"] = str(res.csv_path), str(res.netcdf_path)
    for name, fig in res.figures().items() if run.scenario.plots else ():
        png = folder / name
        _figure(add, png.stem, png, fig)
    return folder / "summary.json"


WRITERS = {
    "flutter": _flutter_files,
    "simulate": _simulation_files,
    "trade": _trade_files,
    "gust_loads": _gust_loads_files,
    "lco": _lco_files,
}
"""Per scenario kind (:data:`aeroservo.studies.kinds.KINDS`): ``f(run, out, add, files)``
adds the run's files (``add(kind, path, writer)``) and returns the path of its JSON summary
(None: one of its data files holds it)."""
