"""State-space models written for MATLAB (``.mat``) and NumPy (``.npz``): A, B, C, D with the
signal names and units, speed, density, sample time and the state scaling of a balanced
realization (``x_physical = state_scaling .* x``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..atomic import atomic_write

__all__ = ["export_mat", "export_npz"]


def _export_dict(sys) -> dict:
    return {
        "A": np.asarray(sys.A),
        "B": np.asarray(sys.B),
        "C": np.asarray(sys.C),
        "D": np.asarray(sys.D),
        "state_names": np.array(sys.state_labels, dtype=object),
        "input_names": np.array(sys.input_labels, dtype=object),
        "output_names": np.array(sys.output_labels, dtype=object),
        "input_units": np.array(
            [getattr(sys, "signal_units", {}).get(n, "") for n in sys.input_labels], dtype=object
        ),
        "output_units": np.array(
            [getattr(sys, "signal_units", {}).get(n, "") for n in sys.output_labels], dtype=object
        ),
        "speed": float(getattr(sys, "speed", np.nan)),
        "density": float(getattr(sys, "density", np.nan)),
        "dt": 0.0 if sys.dt in (0, None) else float(sys.dt),
        "state_scaling": np.asarray(
            getattr(sys, "state_scaling", np.ones(sys.nstates)), dtype=float
        ),
    }


def export_mat(sys, path: str | Path) -> Path:
    """Write ``A, B, C, D``, names and units, speed, density, dt and state_scaling (MATLAB)."""

    from scipy.io import savemat

    data = _export_dict(sys)
    return atomic_write(path, lambda p: savemat(p, data, do_compression=True))


def export_npz(sys, path: str | Path) -> Path:
    """Same content as :func:`export_mat` in a NumPy ``.npz`` file (names as str arrays)."""

    data = {
        k: (v.astype(str) if isinstance(v, np.ndarray) and v.dtype == object else v)
        for k, v in _export_dict(sys).items()
    }

    def write(p: Path) -> None:
        with open(p, "wb") as fh:
            np.savez(fh, **data)

    return atomic_write(path, write)
