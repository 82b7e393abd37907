"""State-space models written for MATLAB (``.mat``) and NumPy (``.npz``): A, B, C, D with the
state and signal names and units, speed, density, sample time and the state scaling of a
balanced realization (``x_physical = state_scaling .* x``). ``matlab/load_aeroservo.m`` builds
a named ``ss`` from the ``.mat`` file.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..atomic import atomic_write

__all__ = ["export_mat", "export_npz"]


_STATE_UNITS = {"w": "m", "theta": "rad", "phi": "rad", "delta": "rad", "eta": "modal"}


def state_unit(name: str) -> str:
    """Unit of a state by its name: structural unknowns (``w_3`` m, ``theta_3``, ``phi_3``,
    ``delta_<surface>_3`` rad, modal ``eta_2``) and their rates (``..._dot``, per s); aerodynamic
    lag, gust and servo states have no physical unit here (empty)."""
    rate = name.endswith("_dot")
    base = name[: -len("_dot")] if rate else name
    unit = _STATE_UNITS.get(base.split("_", 1)[0], "")
    return f"{unit}/s" if unit and rate else unit


def _export_dict(sys) -> dict:
    return {
        "A": np.asarray(sys.A),
        "B": np.asarray(sys.B),
        "C": np.asarray(sys.C),
        "D": np.asarray(sys.D),
        "state_names": np.array(sys.state_labels, dtype=object),
        "state_units": np.array([state_unit(n) for n in sys.state_labels], dtype=object),
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
