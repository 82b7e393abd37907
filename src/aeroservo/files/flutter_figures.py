"""The mode-shape figures of a sweep read back from its file
(:class:`~aeroservo.files.flutter_file.SavedFlutter`): the natural modes and the flutter mode
saved as nodal fields, drawn by :func:`aeroservo.plots.plot_modes`."""

from __future__ import annotations

from ..errors import InputError

__all__ = ["mode_shapes_figure", "flutter_mode_figure"]


def mode_shapes_figure(saved, fmax: float | None, modes, title: str | None):
    """The natural modes of ``saved`` up to ``fmax`` [Hz] or the ``modes`` (from 1)."""
    from ..plots.flutter import select_modes
    from ..plots.modes import plot_modes

    if not saved.modes:
        raise InputError("kind = 'modes': the sweep was saved without its mode shapes")
    freqs = saved.modes["frequency"]
    cols = [j for j in select_modes(saved.result, fmax, modes) if j < freqs.size]
    return plot_modes(
        saved.modes, saved.modes["label"], freqs, surfaces=saved.surfaces, modes=cols, title=title
    )


def flutter_mode_figure(saved, title: str | None):
    """The flutter eigenvector of ``saved`` at its flutter speed."""
    from ..plots.modes import plot_modes

    r = saved.result
    if not saved.modes:
        raise InputError("kind = 'flutter-mode': the sweep was saved without its mode shapes")
    if saved.flutter_mode is None or r.flutter is None:
        raise InputError("kind = 'flutter-mode': no flutter in the sweep, so no flutter mode")
    fields = {k: (v if k == "x" else v[:, None]) for k, v in saved.flutter_mode.items()}
    fl = r.flutter
    label = f"flutter mode ({r.mode_labels[fl.mode]}) at {fl.speed:.4g} m/s"
    return plot_modes(fields, [label], [fl.frequency], surfaces=saved.surfaces, title=title)
