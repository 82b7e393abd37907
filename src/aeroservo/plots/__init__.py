"""Figures of single results: V-g / V-f diagrams, root loci, mode shapes, flutter envelopes
(:mod:`.flutter`) and loop margins (:mod:`.margins`).

Functions return :class:`matplotlib.figure.Figure` objects built without ``pyplot`` (no GUI
backend needed; they display inline in notebooks and save with ``fig.savefig``).
"""

from .flutter import plot_envelope, plot_mode_shapes, plot_root_locus, plot_vg
from .margins import plot_loop_margins, plot_margin_sweep

__all__ = [
    "plot_vg",
    "plot_root_locus",
    "plot_mode_shapes",
    "plot_envelope",
    "plot_loop_margins",
    "plot_margin_sweep",
]
