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

import io
import struct
import zlib
from pathlib import Path

import numpy as np

from ..errors import InputError
from .user_files import file_head, read_npz, user_path

__all__ = ["read_linear_controller", "NAME_KEYS", "TIME_KEYS"]

NAME_KEYS = {
    "inputs": ("InputName", "inputs", "input_names"),
    "outputs": ("OutputName", "outputs", "output_names"),
}
"""Variable names accepted for the signal names (MATLAB's first)."""

TIME_KEYS = ("Ts", "dt")
"""Variable names accepted for the sample time [s]."""

MAX_STATES = 500
"""Largest compensator read from a file (its states). Measured on the Goland wing with
aileron's LQR scenario, whose loop it closes (``aeroservo simulate``: margins, boundary,
judgement): 500 states take 0.8 GB of memory and 23 s, 800 states 1.5 GB, 1500 states more
than 4 GB."""

MAX_BYTES = 64 * 2**20
"""Largest total of the variables read from a controller file, inflated [bytes]."""


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


def _variables() -> tuple[str, ...]:
    """The names of the variables read (any others in the file are neither read nor counted)."""
    return ("A", "B", "C", "D", *TIME_KEYS, *(k for keys in NAME_KEYS.values() for k in keys))


def _load(path: Path) -> dict:
    suffix = path.suffix.lower()
    if suffix not in (".npz", ".mat"):
        raise InputError(f"{path}: expected a .npz or .mat file, not {suffix or 'no suffix'!r}")
    what = f"controller matrices file ({suffix})"
    head = file_head(path, 128, what)
    if suffix == ".npz":
        if head[:4] not in (b"PK\x03\x04", b"PK\x05\x06"):
            raise InputError(
                f"{path}: not a .npz archive ({'empty' if not head else 'no zip header'}); save "
                "it with numpy.savez (docs/controllers.md)"
            )
        data = read_npz(path, what=what, names=_variables(), budget=MAX_BYTES)
        _check_shape(path, data.get("A"))
        return data
    return _load_mat(path, head)


def _check_shape(path: Path, shape) -> None:
    """A's number of states, from its shape, before the matrices are read."""
    shape = getattr(shape, "shape", shape)
    if shape is not None and len(shape) == 2 and max(shape) > MAX_STATES:
        raise InputError(
            f"{path}: variable A is {shape[0]}x{shape[1]}: at most {MAX_STATES} states (a "
            "larger compensator would not fit the loop's analyses in memory; reduce it, e.g. "
            "balanced truncation)"
        )


def _load_mat(path: Path, head: bytes) -> dict:
    """The variables of a MATLAB ``.mat`` file (version 4 to 7), checked before they are read:
    A's shape and the bytes the variables read inflate to (:func:`_mat_variables`)."""
    from scipy.io import loadmat, whosmat
    from scipy.io.matlab import MatReadError, matfile_version

    if head.startswith(b"MATLAB 7.3"):  # the 128-byte text header names the format version
        raise InputError(f"{path}: a MATLAB v7.3 (HDF5) file; save it with save(..., '-v7')")
    if head.startswith((b"# Created by Octave", b"# name:")):
        raise InputError(
            f"{path}: GNU Octave's text format, not a MATLAB file; save it with save('-v7', "
            "...) (docs/controllers.md)"
        )
    names = _variables()
    try:
        source = str(path)
        if matfile_version(source)[0] == 1:
            shapes, source = _mat_variables(path, names)
        else:  # version 4: no compression, whosmat reads the headers alone
            shapes = {name: shape for name, shape, _kind in whosmat(source)}
        _check_shape(path, shapes.get("A"))
        return loadmat(source, squeeze_me=False, chars_as_strings=True, variable_names=names)
    except InputError:
        raise
    except (
        OSError, ValueError, TypeError, IndexError, EOFError, MatReadError, zlib.error,
        struct.error,
    ) as exc:  # fmt: skip
        why = " ".join(str(exc).split())[:160] or type(exc).__name__
        raise InputError(
            f"{path}: not a readable .mat file ({why}); save it with save('-v7', ...)"
        ) from None


def _chunks(fh, mdtype: int, nbytes: int):
    """The content of a variable of a version 5 file (``nbytes`` from ``fh``), inflated when
    compressed, in chunks of at most 1 MiB (never held whole)."""
    inflate = zlib.decompressobj() if mdtype == 15 else None  # miCOMPRESSED
    left = nbytes
    while left > 0:
        buf = fh.read(min(left, 2**16))
        if not buf:
            return
        left -= len(buf)
        while buf:
            if inflate is None:
                yield buf
                break
            if inflate.eof:
                return
            yield inflate.decompress(buf, 2**20)
            buf = inflate.unconsumed_tail


def _element(buf: bytes, pos: int, order: str) -> tuple[bytes, int]:
    """The data of the element at ``pos`` of a matrix header and the position after it."""
    first, second = struct.unpack(order + "II", buf[pos : pos + 8])
    if first >> 16:  # small data element: its size in the upper half of the first word
        return buf[pos + 4 : pos + 4 + (first >> 16)], pos + 8
    return buf[pos + 8 : pos + 8 + second], pos + 8 + (second + 7) // 8 * 8


def _mat_variables(path: Path, wanted: tuple) -> tuple[dict, io.BytesIO]:
    """``{name: shape}`` of the variables of a version 5-7 ``.mat`` file from their headers
    (the first bytes of each, inflated), and the file with the variables ``wanted`` alone (as
    they are, compressed or not: SciPy inflates any variable it meets in full, wanted or not);
    an :class:`InputError` when those inflate to more than :data:`MAX_BYTES` in all, counted
    chunk by chunk (never held)."""
    shapes, total, kept = {}, 0, io.BytesIO()
    with path.open("rb") as fh:
        kept.write(fh.read(128))
        order = "<" if kept.getvalue()[126:128] == b"IM" else ">"
        while len(tag := fh.read(8)) == 8:
            mdtype, nbytes = struct.unpack(order + "II", tag)
            start, head, size = fh.tell(), b"", 0
            chunks = _chunks(fh, mdtype, nbytes)
            for chunk in chunks:
                head, size = head + chunk[:4096], size + len(chunk)
                if len(head) >= 256:
                    break
            content = head[8:] if mdtype == 15 else head  # after the inner miMATRIX tag
            _flags, at = _element(content, 0, order)
            dims, at = _element(content, at, order)
            name = _element(content, at, order)[0].decode("latin-1")
            shapes[name] = struct.unpack(f"{order}{len(dims) // 4}i", dims[: len(dims) // 4 * 4])
            if name in wanted:
                total += size
                for chunk in chunks:
                    total += len(chunk)
                    if total > MAX_BYTES:
                        raise InputError(
                            f"{path}: variable {name} inflates to more than "
                            f"{MAX_BYTES / 2**20:g} MiB: not a compensator's matrices"
                        )
                fh.seek(start)
                kept.write(tag + fh.read(nbytes))
            fh.seek(start + nbytes)
    kept.seek(0)
    return shapes, kept


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
        twice = sorted({n for n in names if names.count(n) > 1})
        if twice:
            raise InputError(
                f"{path}: {k} = {names}: {', '.join(map(repr, twice))} named more than once; "
                f"each {'sensor' if what == 'inputs' else 'command'} once"
            )
        count = p if what == "inputs" else m
        if len(names) != count:
            raise InputError(f"{path}: {k} has {len(names)} names; D has {count} {what}")
        out[what] = names
    return out
