"""Results of a trade study: one table row per case and a labelled N-dimensional dataset."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ...errors import InputError
from ...result_shape import Result
from .plots import HEATMAP_METRICS, _heatmap, _pareto
from .ranking import BEST_CRITERION, best_index, is_closed_loop
from .study import FORMAT, METRICS, PARAMETERS

__all__ = ["TradeResult", "load_trade"]

_TEXT = ("status", "failed_stage", "error")


@dataclass
class TradeResult(Result):
    """Results of a trade study.

    A result of the common shape (:mod:`aeroservo.result_shape`): :meth:`summary`,
    :attr:`table`, :meth:`plot` (``"pareto"``: :meth:`pareto`, ``"heatmap"``:
    :meth:`heatmap`), :meth:`to_json` and :meth:`save` (a folder as a run writes it:
    ``study.json``, the CSV and the NetCDF file).

    Attributes
    ----------
    name : str
    parameters : dict
        ``{name: values}`` of the swept parameters (the dataset's dimensions).
    table : pandas.DataFrame
        One row per case, in grid order: ``case_id``, the parameters, ``status``,
        ``failed_stage``, ``error`` and the metrics (NaN when unavailable).
    dataset : xarray.Dataset
        One dimension per parameter, one variable per metric (units in ``attrs``), plus
        ``case_id``, ``status`` and ``error``.
    csv_path, netcdf_path : Path or None
    n_skipped : int
        Cases already finished before this run.
    n_failed : int
        Cases that failed.
    elapsed : float
        Wall time of the run [s].
    settings : dict
        The study's fixed settings (:func:`study_settings`).
    """

    name: str
    parameters: dict
    table: object
    dataset: object
    settings: dict = field(default_factory=dict)
    csv_path: Path | None = None
    netcdf_path: Path | None = None
    n_skipped: int = 0
    elapsed: float = 0.0

    FIGURES = {"pareto": "pareto", "heatmap": "heatmap"}

    @property
    def n_cases(self) -> int:
        return len(self.table)

    @property
    def n_failed(self) -> int:
        return int((self.table["status"] != "ok").sum())

    def __repr__(self) -> str:
        dims = " x ".join(f"{k}[{len(v)}]" for k, v in self.parameters.items())
        return (
            f"TradeResult({self.name!r}: {dims} = {self.n_cases} cases, {self.n_failed} failed, "
            f"{self.n_skipped} skipped, {self.elapsed:.1f} s)"
        )

    @property
    def closed_loop(self) -> bool:
        """Whether the study designed controllers (False: open-loop flutter only)."""
        return is_closed_loop(self.table, self.settings)

    @property
    def best_criterion(self) -> str:
        """What :meth:`best_case` maximizes (:data:`~.ranking.BEST_CRITERION`)."""
        return BEST_CRITERION[self.closed_loop]

    def best_case(self):
        """The best case (:attr:`best_criterion`), a row of :attr:`table`, or None.

        Returns
        -------
        pandas.Series or None
        """
        i = best_index(self.table, self.closed_loop)
        return None if i is None else self.table.iloc[i]

    def heatmap(
        self,
        metric: str | None = None,
        x: str | None = None,
        y: str | None = None,
        *,
        small_multiples: bool = True,
        **fixed: float,
    ):
        """Heat map of a metric over two parameters, the best case outlined.

        Parameters
        ----------
        metric : str, optional
            A name of :data:`METRICS` (default: the suppression margin, or the open-loop
            flutter speed of an open-loop study).
        x, y : str, optional
            Swept parameters on the axes (default: the first two not fixed).
        small_multiples : bool
            Draw one panel per value of the other parameters when there are at most
            :data:`~.plots.MAX_PANELS` panels (False: hold them at the best case).
        **fixed
            The other parameters' positions: an ``int`` is an index into the parameter's
            values, a ``float`` a value (the nearest one). Parameters neither fixed nor on
            the axes give the panels or are held at their values in the best case.

        Returns
        -------
        matplotlib.figure.Figure
        """
        metric = HEATMAP_METRICS[self.closed_loop][0] if metric is None else metric
        return _heatmap(
            self.table,
            self.parameters,
            metric,
            x,
            y,
            fixed,
            best=best_index(self.table, self.closed_loop),
            criterion=self.best_criterion,
            name=self.name,
            small_multiples=small_multiples,
        )

    def pareto(self):
        """Suppression margin versus peak hinge moment: the Pareto front highlighted and
        labelled with its cases' parameter values, saturated cases and the best case marked.

        Returns
        -------
        matplotlib.figure.Figure
        """
        best = best_index(self.table, self.closed_loop)
        return _pareto(self.table, self.name, list(self.parameters), best)

    def summary(self) -> str:
        """The grid, the cases that failed and the best case, a line each."""
        dims = " x ".join(f"{k} [{len(v)}]" for k, v in self.parameters.items())
        lines = [
            f"trade study {self.name}: {dims} = {self.n_cases} cases, {self.n_failed} failed "
            f"({'closed loop' if self.closed_loop else 'open loop'})"
        ]
        failed = self.table[self.table["status"] != "ok"]
        for stage, n in failed["failed_stage"].value_counts(sort=False).items():
            lines.append(f"  {n} failed in {stage or 'an unknown stage'}")
        best = self.best_case()
        if best is None:
            lines.append("  no best case (no case succeeded)")
        else:
            at = ", ".join(f"{k} = {best[k]:g}" for k in self.parameters)
            lines.append(f"  best case {best['case_id']} ({self.best_criterion}): {at}")
            for m in ("open_loop_flutter_speed", "closed_loop_flutter_speed",
                      "suppression_margin", "hinge_moment_peak"):  # fmt: skip
                if m in best and np.isfinite(best[m]):
                    lines.append(f"    {m} = {best[m]:.6g} {METRICS[m][0]}")
        return "\n".join(lines)

    def to_dict(self) -> dict:
        """The study's name, parameters, settings and every case (a row of :attr:`table`)."""
        return {
            "name": self.name,
            "parameters": {k: list(v) for k, v in self.parameters.items()},
            "settings": dict(self.settings),
            "cases": self.table.to_dict(orient="records"),
        }

    def figures(self) -> dict:
        """The figures a run writes: ``{file name: figure}``.

        ``heatmap_<metric>.png`` for each metric of :data:`~.plots.HEATMAP_METRICS` that has a
        value (a study of two or more parameters) and ``pareto.png`` (a closed-loop study);
        none when no case succeeded.
        """
        ok = self.table["status"] == "ok"
        if not ok.any():
            return {}
        out = {}
        if len(self.parameters) >= 2:
            for m in HEATMAP_METRICS[self.closed_loop]:
                if self.table.loc[ok, m].notna().any():
                    out[f"heatmap_{m}.png"] = self.heatmap(m)
        if self.closed_loop:
            out["pareto.png"] = self.pareto()
        return out


def _assemble(name: str, parameters: dict, rows: list[dict], settings: dict):
    import pandas as pd
    import xarray as xr

    names = list(parameters)
    cols = ["case_id", *names, *_TEXT, *METRICS]
    table = pd.DataFrame([{c: r.get(c) for c in cols} for r in rows], columns=cols)
    for m in METRICS:
        table[m] = pd.to_numeric(table[m].astype(object).where(table[m].notna(), np.nan))
        table[m] = table[m].astype(float)
    for c in ("case_id", *_TEXT):
        table[c] = table[c].where(table[c].notna(), "").astype(str)
    shape = tuple(len(v) for v in parameters.values())
    data_vars = {}
    for m, (unit, desc) in METRICS.items():
        data_vars[m] = (
            names,
            table[m].to_numpy().reshape(shape),
            {"units": unit, "long_name": desc},
        )
    for c in ("case_id", *_TEXT):
        arr = np.array(table[c].tolist(), dtype=object).reshape(shape)
        data_vars[c] = (names, arr)
    coords = {
        k: (
            k,
            np.asarray(v, dtype=float),
            {"units": PARAMETERS[k][0], "long_name": PARAMETERS[k][1]},
        )
        for k, v in parameters.items()
    }
    ds = xr.Dataset(
        data_vars,
        coords=coords,
        attrs={
            "title": f"aeroservo trade study {name!r}",
            "study": name,
            "format": FORMAT,
            "settings": json.dumps(settings, sort_keys=True),
        },
    )
    return TradeResult(
        name=name, parameters=dict(parameters), table=table, dataset=ds, settings=settings
    )


def load_trade(out_dir: str | Path) -> TradeResult:
    """Re-read a finished study from its folder (for re-plotting).

    Parameters
    ----------
    out_dir : str or Path
        The ``out_dir`` of :func:`run_trade`.

    Returns
    -------
    TradeResult
        Table from the CSV, dataset from the NetCDF file (``n_skipped`` = number of cases).
    """

    out = Path(out_dir)
    try:
        manifest = json.loads((out / "study.json").read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise InputError(f"out_dir = {str(out)!r}: no readable study.json ({exc})") from None
    if not isinstance(manifest, dict):
        raise InputError(f"{out / 'study.json'}: not a trade-study manifest (a JSON object)")
    if manifest.get("format") != FORMAT:
        raise InputError(
            f"{out / 'study.json'}: format = {manifest.get('format')!r}; expected {FORMAT!r}"
        )
    try:
        return _read_study(out, manifest)
    except InputError:
        raise
    except (KeyError, TypeError, ValueError, OSError, AttributeError) as exc:
        why = " ".join(str(exc).split())[:120]
        raise InputError(
            f"{out}: not a readable trade study ({type(exc).__name__}: {why})"
        ) from None


def _read_study(out: Path, manifest: dict) -> TradeResult:
    """The table and dataset a study's manifest names (any damage raises)."""
    import pandas as pd
    import xarray as xr

    csv, nc = out / manifest["csv"], out / manifest["netcdf"]
    for p in (csv, nc):
        if not p.is_file():
            raise InputError(f"{p}: missing; the study has not finished (run it again)")
    table = pd.read_csv(csv, keep_default_na=False, na_values={m: ["", "NaN"] for m in METRICS})
    for c in ("case_id", *_TEXT):
        table[c] = table[c].astype(str)
    with xr.open_dataset(nc, engine="scipy") as ds:
        dataset = ds.load()
    params = {k: tuple(float(x) for x in v) for k, v in manifest["parameters"].items()}
    result = TradeResult(
        name=manifest["name"],
        parameters=params,
        table=table,
        dataset=dataset,
        settings=manifest.get("settings", {}),
        csv_path=csv,
        netcdf_path=nc,
        n_skipped=len(table),
    )
    return result
