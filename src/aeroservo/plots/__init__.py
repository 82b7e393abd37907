"""Figures of single results: V-g / V-f diagrams, root loci, flutter envelopes (:mod:`.flutter`),
mode shapes and their animation (:mod:`.modes`), the planform (:mod:`.planform`) and loop
margins (:mod:`.margins`).

Functions return :class:`matplotlib.figure.Figure` objects made by
:func:`aeroservo._figures.new_figure`: when pyplot is in use (imported) the figure is the current
pyplot figure (``plt.gcf()``, ``plt.savefig``, ``plt.show()`` act on it) and a notebook shows it
once, also when it is the cell's last value; otherwise a detached figure (no GUI backend
needed), saved with ``fig.savefig``. Angles are drawn in degrees (labels say ``[deg]``); the
results, their files and the API keep radians.
"""

from .._lazy import lazy_attributes

_PUBLIC = {
    "plot_describing": "lco",
    "plot_envelope": "flutter",
    "plot_loop_margins": "margins",
    "plot_margin_sweep": "margins",
    "animate_mode": "modes",
    "plot_mode_shapes": "modes",
    "plot_modes": "modes",
    "plot_planform": "planform",
    "plot_root_locus": "flutter",
    "plot_sensitivities": "sensitivity",
    "plot_vg": "flutter",
}

__all__ = [
    "plot_describing",
    "plot_vg",
    "plot_root_locus",
    "plot_mode_shapes",
    "plot_modes",
    "plot_planform",
    "animate_mode",
    "plot_envelope",
    "plot_loop_margins",
    "plot_margin_sweep",
    "plot_sensitivities",
]

__getattr__, __dir__ = lazy_attributes(__name__, _PUBLIC)
