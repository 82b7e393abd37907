"""Doublet-lattice aerodynamic influence coefficients (AICs) from DLR's PanelAero, cached.

For a lattice (:mod:`aeroservo.aero.lattice`), a Mach number M < 1 and a reduced frequency, the
AIC matrix ``Q_jj`` gives the pressure jumps of the boxes from their normalwash:
``dcp = Q_jj (w / V)``, with ``w / V`` the normalwash angle at each box's downwash point
(positive as an angle of attack: flow from below) and ``dcp`` positive up; box j then carries
the force ``q dcp_j A_j`` up at its load point (``q = rho V^2 / 2``). The steady part is the
vortex-lattice method, the oscillatory increment the doublet-lattice method (Albano and Rodden
1969) with Rodden, Taylor and McIntosh's quartic kernel approximation (1998) or the parabolic
one (Rodden, Giesing and Kalman 1971), as implemented and checked against MSC Nastran by
PanelAero (Voss, DLR-IB-AE-GO-2020-137). With a symmetric lattice the mirror image in the root
plane is added and the AICs are those of symmetric motion.

AICs depend on the geometry, the Mach number and the reduced frequency only: they are kept in
memory and on disk (``AEROSERVO_CACHE``: a folder, or ``off``; default
``$XDG_CACHE_HOME/aeroservo`` or ``~/.cache/aeroservo``), keyed by a digest of all three and of
the PanelAero version. A damaged cache file is recomputed, never used.
"""

from __future__ import annotations

import hashlib
import os
import threading
from pathlib import Path

import numpy as np

from ..errors import InputError, NumericalError, check_number
from .lattice import Lattice

__all__ = ["aics", "check_dlm_mach", "cache_folder", "DLM_MACH_WARN", "KERNELS"]

KERNELS = ("quartic", "parabolic")
"""Kernel approximations of the doublet-lattice method."""

DLM_MACH_WARN = 0.9
"""Above this Mach number results of the (linear, subsonic) doublet-lattice method get a
warning: transonic flow has shocks the method does not have."""

THREADS = 2
"""Frequencies computed at the same time (threads: PanelAero's kernels are numpy's)."""

_MEMORY: dict[str, np.ndarray] = {}
_MEMORY_BYTES = 1 << 30  # at most this much AIC data is kept in memory
_LOCK = threading.Lock()


def check_dlm_mach(mach: object, field: str = "mach") -> float:
    """Validate the Mach number of the doublet-lattice method, ``0 <= M < 1``."""
    m = check_number(field, mach, lo=0.0)
    if m >= 1.0:
        raise InputError(
            f"{field} = {m:g}: the doublet-lattice method is subsonic, Mach < 1 (supersonic "
            "flow needs another kernel)"
        )
    return m


def _panelaero():
    """PanelAero's DLM and VLM modules (numpy's error state restored: PanelAero silences it)."""
    old = np.geterr()
    try:
        from panelaero import DLM, VLM
    except ImportError as exc:
        raise InputError(
            "aero = 'dlm' needs DLR's PanelAero: pip install 'aeroservo[dlm]' (or pip install "
            f"panelaero) ({exc})"
        ) from None
    finally:
        np.seterr(**old)
    return DLM, VLM


def _version() -> str:
    try:
        from importlib.metadata import version

        return version("panelaero")
    except Exception:  # noqa: BLE001 - any failure: an unversioned key
        return "unknown"


def cache_folder() -> Path | None:
    """The folder of the AIC cache on disk, or None when it is off (``AEROSERVO_CACHE=off``)."""
    text = os.environ.get("AEROSERVO_CACHE")
    if text is not None and text.strip().lower() in ("off", "0", "none", ""):
        return None
    if text:
        return Path(text).expanduser()
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "aeroservo"


def _digest(lattice: Lattice, mach: float, k: np.ndarray, kernel: str) -> str:
    h = hashlib.sha256()
    h.update(lattice.key().encode())
    h.update(np.float64(mach).tobytes())
    h.update(np.asarray(k, dtype="<f8").tobytes())
    h.update(kernel.encode())
    h.update(_version().encode())
    return h.hexdigest()[:40]


def _read(path: Path, shape: tuple) -> np.ndarray | None:
    try:
        with np.load(path, allow_pickle=False) as data:
            q = np.asarray(data["Q"])
    except Exception:  # noqa: BLE001 - a damaged or foreign file is recomputed
        return None
    if q.shape != shape or q.dtype != np.complex128 or not np.all(np.isfinite(q)):
        return None
    return q


def _write(path: Path, q: np.ndarray) -> None:
    from ..atomic import atomic_write

    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        atomic_write(path, lambda p: np.savez(p, Q=q))
    except (OSError, InputError):  # a read-only or full cache: computing again is enough
        pass


def _remember(key: str, q: np.ndarray) -> None:
    with _LOCK:
        _MEMORY[key] = q
        total = sum(a.nbytes for a in _MEMORY.values())
        while total > _MEMORY_BYTES and len(_MEMORY) > 1:
            oldest = next(iter(_MEMORY))
            total -= _MEMORY.pop(oldest).nbytes


def aics(
    lattice: Lattice,
    mach: float,
    k: np.ndarray,
    *,
    kernel: str = "quartic",
    progress=None,
) -> np.ndarray:
    """AIC matrices of a lattice at one Mach number and several reduced frequencies.

    Parameters
    ----------
    lattice : Lattice
    mach : float
        Mach number, ``0 <= M < 1``.
    k : ndarray (n_k,)
        Reduced frequencies ``omega / V`` [1/m] (per unit length: multiply the usual
        ``omega b / V`` by ``1 / b``); 0 is the steady vortex-lattice solution.
    kernel : {"quartic", "parabolic"}
        Kernel approximation of the doublet-lattice method.
    progress : callable, optional
        Called with the number of frequencies done.

    Returns
    -------
    ndarray (n_k, n, n) complex
        ``Q_jj`` per frequency: ``dcp = Q_jj (w / V)`` (module notes).
    """
    mach = check_dlm_mach(mach)
    if kernel not in KERNELS:
        raise InputError(f"kernel = {kernel!r}: allowed values are {', '.join(KERNELS)}")
    k = np.asarray(k, dtype=float).ravel()
    if k.size == 0 or not np.all(np.isfinite(k)) or np.any(k < 0):
        raise InputError("reduced frequencies: expected finite values >= 0")
    n = lattice.n_boxes
    key = _digest(lattice, mach, k, kernel)
    if key in _MEMORY:
        return _MEMORY[key]
    folder = cache_folder()
    path = None if folder is None else folder / "aic" / f"{key}.npz"
    if path is not None and path.is_file():
        q = _read(path, (k.size, n, n))
        if q is not None:
            _remember(key, q)
            return q
    q = _compute(lattice, mach, k, kernel, progress)
    if path is not None:
        _write(path, q)
    _remember(key, q)
    return q


def _compute(lattice: Lattice, mach: float, k: np.ndarray, kernel: str, progress) -> np.ndarray:
    import copy
    from concurrent.futures import ThreadPoolExecutor

    DLM, VLM = _panelaero()
    mirror = lattice.symmetric
    grid = lattice.aerogrid(mirror=mirror)
    n = lattice.n_boxes
    out = np.empty((k.size, n, n), dtype=complex)
    done = [0]

    def one(i: int) -> None:
        a = a_vlm.astype(complex)
        if k[i] > 0.0:
            with np.errstate(all="ignore"):  # per thread
                a = a + DLM.calc_Ajj(aerogrid=copy.deepcopy(grid), Ma=mach, k=k[i], method=kernel)
        q = -np.linalg.inv(a)[:n]
        out[i] = q[:, :n] + q[:, n:] if mirror else q
        with _LOCK:
            done[0] += 1
            if progress is not None:
                progress(done[0])

    # PanelAero divides by zero where it masks the result afterwards; numpy releases the GIL
    # in its element-wise kernels, so two frequencies at a time use two cores
    with np.errstate(all="ignore"):
        a_vlm, _ = VLM.calc_Ajj(aerogrid=copy.deepcopy(grid), Ma=mach)
        workers = max(1, min(THREADS, os.cpu_count() or 1, k.size))
        with ThreadPoolExecutor(max_workers=workers) as pool:
            list(pool.map(one, range(k.size)))
    if not np.all(np.isfinite(out)):
        raise NumericalError(
            "doublet-lattice AICs are not finite: boxes too thin or overlapping (check the box "
            "counts and the planform)"
        )
    return out
