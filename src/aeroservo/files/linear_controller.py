"""Linear controllers saved by other tools: ``.npz`` (NumPy) and ``.mat`` (MATLAB, GNU Octave)
files with the matrices ``A, B, C, D``, the sample time and the signal names.

A compensator's inputs are sensors and its outputs commands, named as the loop names them.
From MATLAB (``K`` an ``ss``)::

    [A, B, C, D, Ts] = ssdata(K);
    InputName = K.InputName;  OutputName = K.OutputName;
    save('k.mat', 'A', 'B', 'C', 'D', 'Ts', 'InputName', 'OutputName');   % not -v7.3

(``save('k.mat', 'K')`` writes the ``ss`` object itself, which only MATLAB can read.) From
python-control (``K`` a ``StateSpace``)::

    np.savez("k.npz", A=K.A, B=K.B, C=K.C, D=K.D, dt=K.dt or 0.0,
             inputs=K.input_labels, outputs=K.output_labels)

A sample time of 0 is a continuous compensator (discretised at the loop's rate), MATLAB's -1
(unspecified) a discrete one at the loop's rate; a file without one is refused (no guess).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import InputError
from .user_files import check_readable, user_path

__all__ = ["read_linear_controller", "NAME_KEYS", "TIME_KEYS"]

NAME_KEYS = {
    "inputs": ("InputName", "inputs", "input_names"),
    "outputs": ("OutputName", "outputs", "output_names"),
}
"""Variable names accepted for the signal names (MATLAB's first)."""

TIME_KEYS = ("Ts", "dt")
"""Variable names accepted for the sample time [s]."""

MAX_STATES = 5000
"""Largest compensator read from a file."""


def _names(value, path: Path, key: str) -> list[str]:
    a = np.atleast_1d(np.asarray(value, dtype=object)).ravel()
    out = []
    for v in a:
        v = np.asarray(v).ravel()
        v = v[0] if v.size == 1 else "".join(str(x) for x in v)
        if not isinstance(v, str | np.str_) or not str(v).strip():
            raise InputError(f"{path}: {key}: expected signal names (a cell array of text)")
        out.append(str(v).strip())
    return out


def _load(path: Path) -> dict:
    suffix = path.suffix.lower()
    if suffix == ".npz":
        try:
            with np.load(path, allow_pickle=False) as f:
                return {k: f[k] for k in f.files}
        except (OSError, ValueError) as exc:
            raise InputError(f"{path}: not a readable .npz file ({exc})") from None
    if suffix == ".mat":
        from scipy.io import loadmat
        from scipy.io.matlab import MatReadError

        with open(path, "rb") as fh:  # the 128-byte text header names the format version
            if fh.read(116).startswith(b"MATLAB 7.3"):
                raise InputError(
                    f"{path}: a MATLAB v7.3 (HDF5) file; save it with save(..., '-v7')"
                )
        try:
            return loadmat(path, squeeze_me=False, chars_as_strings=True)
        except (OSError, ValueError, TypeError, MatReadError) as exc:
            raise InputError(f"{path}: not a readable .mat file ({exc})") from None
    raise InputError(f"{path}: expected a .npz or .mat file, not {suffix or 'no suffix'!r}")


def read_linear_controller(path: str | Path) -> dict:
    """Read a saved linear controller.

    Returns
    -------
    dict
        ``A, B, C, D`` (float arrays), ``dt`` [s] (0: continuous; None: discrete at the loop's
        rate), ``inputs`` (sensor names), ``outputs`` (command names), ``source`` (the path).

    Raises
    ------
    InputError
        Naming the file and the variable: missing, not numeric, inconsistent shapes, missing
        or miscounted names.
    """
    path = user_path(path, "controller matrices file")
    check_readable(path, "controller matrices file")
    data = _load(path)
    out: dict = {"source": str(path)}
    for key in ("A", "B", "C", "D"):
        if key not in data:
            raise InputError(f"{path}: variable {key} is missing (give A, B, C, D)")
        a = np.asarray(data[key])
        if a.dtype.kind not in "iuf" or a.ndim > 2:
            raise InputError(f"{path}: variable {key}: expected a real matrix, not {a.dtype}")
        a = a.astype(float)
        if not np.all(np.isfinite(a)):
            raise InputError(f"{path}: variable {key}: has NaN or infinite entries")
        out[key] = np.atleast_2d(a) if a.size else a.reshape(0, 0)
    D = out["D"]
    m, p = D.shape
    n = out["A"].shape[0] if out["A"].size else 0
    if n > MAX_STATES:
        raise InputError(f"{path}: A has {n} states; at most {MAX_STATES}")
    for key, shape in (("A", (n, n)), ("B", (n, p)), ("C", (m, n))):
        if out[key].size == 0:
            out[key] = np.zeros(shape)
        if out[key].shape != shape:
            raise InputError(
                f"{path}: variable {key} has shape {out[key].shape}; D is {m}x{p}, so expected "
                f"{shape}"
            )
    t = next((k for k in TIME_KEYS if k in data), None)
    if t is None:
        raise InputError(
            f"{path}: no sample time: save {TIME_KEYS[0]} (or {TIME_KEYS[1]}) [s], 0 for a "
            "continuous compensator"
        )
    ts = np.asarray(data[t])
    if ts.dtype.kind not in "iuf" or ts.size != 1:
        raise InputError(
            f"{path}: {t}: expected one sample time [s], not {ts.dtype} of size {ts.size}"
        )
    dt = float(ts.ravel()[0])
    if not np.isfinite(dt) or (dt < 0 and dt != -1):
        raise InputError(f"{path}: {t} = {dt:g}: expected a sample time >= 0 s (or -1)")
    out["dt"] = None if dt == -1 else dt
    for what, keys in NAME_KEYS.items():
        k = next((k for k in keys if k in data), None)
        if k is None:
            raise InputError(
                f"{path}: the {what} have no names: save {keys[0]} (or {keys[1]}) with the "
                f"{'sensor' if what == 'inputs' else 'command'} names"
            )
        names = _names(data[k], path, k)
        count = p if what == "inputs" else m
        if len(names) != count:
            raise InputError(f"{path}: {k} has {len(names)} names; D has {count} {what}")
        out[what] = names
    return out
