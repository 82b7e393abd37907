"""The redrawing of a saved limit-cycle result (``aeroservo plot RESULT.json``); the ``lco``
command itself is made from the registry of scenario kinds (:mod:`.scenarios`)."""

from __future__ import annotations

import argparse

from ..errors import InputError

__all__ = ["plot_saved", "LCO_KINDS"]

LCO_KINDS = ("bifurcation", "histories")
"""The figures of a saved limit-cycle result (``aeroservo plot --kind``)."""


def plot_saved(res, src, args: argparse.Namespace, kind: str) -> int:
    """The figures of a saved limit-cycle result: the bifurcation diagram and, when its NPZ
    was next to it, the time histories, next to the result (as ``aeroservo lco`` names
    them); or ``--kind`` alone (to ``--out``)."""
    from pathlib import Path

    from ..atomic import save_figure
    from ..studies.lco_scenario import lco_figures

    which = LCO_KINDS if args.kind is None and args.out is None else (kind,)
    figs = lco_figures(res, which)
    if not figs:
        raise InputError(
            f"--kind = {kind!r}: {args.result} has no time histories (its "
            f"{Path(args.result).stem}_histories.npz is not next to it)"
        )
    for name, fig in figs.items():
        out = Path(args.out) if args.out else src.with_name(f"{src.stem}_{name}.png")
        save_figure(fig, out, dpi=130)
        print(f"plot written to {out}")
    return 0
