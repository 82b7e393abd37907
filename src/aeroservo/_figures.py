"""The one way aeroservo makes a matplotlib figure (:func:`new_figure`).

Every ``plot*`` function and ``.plot()`` method of the package returns a figure made here:

* **pyplot in use** (``matplotlib.pyplot`` imported: a notebook, a script that calls
  ``plt.show()``): the figure is made by ``pyplot.figure`` and is the current figure, as after
  any pyplot command: ``plt.gcf()``, ``plt.savefig(...)``, ``plt.title(...)`` and ``plt.show()``
  act on it. In a Jupyter notebook (inline backend) it is shown **once**: at the end of the
  cell like any pyplot figure, or where the returned figure is displayed (the cell's last line
  ``result.plot()``, or ``display(fig)``), which then releases it from pyplot so that the
  backend does not show it a second time.
* **pyplot not imported** (the command line, a script that only calls ``fig.savefig``): a
  detached :class:`matplotlib.figure.Figure` (no GUI backend is loaded, nothing to close).

:func:`detached` makes every figure of a block detached whatever pyplot's state: figures that
are written to files and dropped (:func:`aeroservo.files.outputs.write_run`) do not pile up in
pyplot, nor show up in a notebook.
"""

from __future__ import annotations

import contextlib
import contextvars
import functools
import sys
from collections.abc import Iterator
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

__all__ = ["new_figure", "detached"]

_DETACHED: contextvars.ContextVar[bool] = contextvars.ContextVar(
    "aeroservo_detached", default=False
)


def new_figure(**kw) -> Figure:
    """A figure with constrained layout (unless ``layout`` is given), made through pyplot when
    pyplot is imported (see the module docstring).

    Parameters
    ----------
    **kw
        :class:`matplotlib.figure.Figure` arguments (``figsize`` [in], ``layout``, ...).
    """
    kw.setdefault("layout", "constrained")
    plt = sys.modules.get("matplotlib.pyplot")
    if plt is None or _DETACHED.get():
        from matplotlib.figure import Figure

        return Figure(**kw)
    fig = plt.figure(**kw)
    if "inline" in plt.get_backend():
        fig._ipython_display_ = functools.partial(_show_once, fig)
    return fig


@contextlib.contextmanager
def detached() -> Iterator[None]:
    """Within the block, :func:`new_figure` makes detached figures (not registered in pyplot)."""
    token = _DETACHED.set(True)
    try:
        yield
    finally:
        _DETACHED.reset(token)


def _show_once(fig: Figure) -> None:
    """IPython's display of a figure that the inline backend would also show after the cell:
    the figure is released from pyplot (the inline backend closes its figures after each cell
    anyway) and displayed here, once."""
    import matplotlib.pyplot as plt
    from IPython.display import display

    fig.__dict__.pop("_ipython_display_", None)
    plt.close(fig)
    display(fig)
