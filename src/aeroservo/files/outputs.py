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
    sc = run.scenario
    summary = run.summary
    items: list = []
    files: dict[str, str] = {}
    plots = sc.plots

    def add(kind: str, path: Path, writer) -> None:
        files[kind] = str(path)
        items.append((path, writer))

    if sc.kind == "flutter":
        json_path = out / f"{sc.result}.json"
        files["summary"] = str(json_path)
        if plots:
            from ..plots import plot_vg

            png = out / f"{sc.result}_vg.png"
            add("vg_plot", png, figure_writer(plot_vg(run.flutter, title=run.title), png, dpi=120))
    elif sc.kind == "simulate":
        npz = out / f"{sc.result}.npz"
        add("result", npz, result_writer(run.simulation, dict(summary)))
        if plots:
            png = out / f"{sc.result}.png"
            fig = run.simulation.plot(open_loop=run.open_loop)
            add("plot", png, figure_writer(fig, png, dpi=120))
            judged = getattr(run.judgement, "boundary", None)
            boundary = run.boundary if run.boundary is not None else judged
            if boundary is not None:
                png = out / f"{sc.result}_boundary.png"
                e = run.judgement.engaged
                fig = boundary.plot(
                    open_loop=run.flutter, engaged=(e.low, e.high), stable_to=e.stable_to
                )
                fig.axes[0].set_title(
                    f"{sc.name}\nengaged {e.text()} (shaded), stability required to "
                    f"{e.stable_to:.4g} m/s (dotted)",
                    fontsize=9,
                )
                add("boundary_plot", png, figure_writer(fig, png, dpi=120))
            if run.margins is not None:
                from ..plots import plot_loop_margins, plot_margin_sweep

                png = out / f"{sc.result}_margins.png"
                fig = plot_loop_margins(run.margins, title=sc.name)
                add("margins_plot", png, figure_writer(fig, png, dpi=120))
                if run.margin_sweep is not None:
                    png = out / f"{sc.result}_margin_sweep.png"
                    fig = plot_margin_sweep(run.margin_sweep, title=sc.name)
                    add("margin_sweep_plot", png, figure_writer(fig, png, dpi=120))

        json_path = out / f"{sc.result}.json"
        files["summary"] = str(json_path)
    elif sc.kind in ("gust_loads", "lco"):
        from ..studies.gust_scenario import gust_figures
        from ..studies.lco_scenario import lco_figures
        from .gust_loads_file import gust_loads_items
        from .lco_file import lco_items

        gust = sc.kind == "gust_loads"
        res, items_of, figures = (
            (run.loads, gust_loads_items, gust_figures)
            if gust
            else (run.lco, lco_items, lco_figures)
        )
        data = items_of(res, out / f"{sc.result}.json", summary)
        for kind, (path, writer) in data.items():
            add(kind, path, writer)  # the JSON's text is made when written, files included
        for name, fig in figures(res).items() if plots else ():
            png = out / f"{sc.result}_{name}.png"
            add(f"{name}_plot", png, figure_writer(fig, png, dpi=120))
        summary["files"] = files
        atomic_write_set(items)
        return files
    else:
        res, folder = run.trade, run.folder
        files["csv"], files["netcdf"] = str(res.csv_path), str(res.netcdf_path)
        for name, fig in res.figures().items() if plots else ():
            png = folder / name
            add(png.stem, png, figure_writer(fig, png, dpi=120))
        json_path = folder / "summary.json"
    summary["files"] = files
    items.append((json_path, _text_writer(json_text(summary))))
    atomic_write_set(items)
    return files
