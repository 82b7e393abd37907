"""Flutter result files: a sweep as one ``.npz`` of plain arrays with a JSON header.

Everything needed to redraw any V-g / V-f / root-locus / mode-shape figure or table without
re-running: speeds, eigenvalues, damping (g and zeta), frequencies, mode labels, crossings,
the p-k branches when computed, the natural mode shapes and the flutter mode as nodal fields
(metres and radians), the wing file text, flight condition, damping model, units and the
aeroservo version. No pickled objects: a damaged or foreign file gives one clear
:class:`~aeroservo.errors.InputError`.
"""

from __future__ import annotations

import dataclasses
import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._version import __version__
from ..errors import InputError
from ..result_shape import Result
from ..stability.near_critical import NearCritical
from ..stability.result import Crossing, FlutterResult
from .summaries import json_text
from .user_files import MAX_JSON_MEMORY, file_head, json_memory, read_npz

__all__ = ["FORMAT", "SavedFlutter", "flutter_writer", "saved_writer", "read_flutter"]

FORMAT = "aeroservo-flutter-1"
UNITS = {
    "speed": "m/s",
    "frequency": "Hz",
    "eigenvalue": "1/s",
    "damping_g": "-",
    "damping_zeta": "-",
    "density": "kg/m^3",
    "altitude": "m",
    "x": "m",
    "w": "m",
    "phi": "rad",
    "delta": "rad",
}
_SCALARS = (
    "divergence_speed",
    "density",
    "v_max",
    "n_states",
    "searched_up_to",
    "altitude",
    "speed_of_sound",
    "mach",
    "compressibility",
    "damping",
)


@dataclass
class SavedFlutter(Result):
    """A flutter result read back from a file.

    A result of the common shape (:mod:`aeroservo.result_shape`): :meth:`summary` and
    :attr:`table` are the sweep's, :meth:`plot` draws ``"vg"``, ``"vf"``, ``"root-locus"``
    and, with the mode shapes, ``"modes"`` and ``"flutter-mode"``; :meth:`save` writes the
    same file again.

    Attributes
    ----------
    result : FlutterResult
        The sweep (time-domain model).
    pk : FlutterResult or None
        The p-k sweep (exact Theodorsen), when it was computed.
    wing_text : str
        The wing file (TOML) the result was computed for.
    modes : dict
        Natural modes as nodal fields: ``"x"`` [m] (n_nodes,), ``"w"`` [m], ``"phi"`` [rad]
        and ``"delta_<surface>"`` [rad] (n_nodes, n_modes), ``"frequency"`` [Hz], ``"label"``.
    flutter_mode : dict or None
        The flutter eigenvector at the flutter speed as complex nodal fields (same keys).
    surfaces : dict
        Control surface name -> ``(start, end)`` [m].
    meta : dict
        The JSON header (version, title, units, ...).
    """

    result: FlutterResult
    pk: FlutterResult | None
    wing_text: str
    modes: dict = field(default_factory=dict)
    flutter_mode: dict | None = None
    surfaces: dict = field(default_factory=dict)
    meta: dict = field(default_factory=dict)

    FIGURES = {
        "vg": "plot_vg",
        "vf": "plot_vf",
        "root-locus": "plot_root_locus",
        "modes": "plot_modes",
        "flutter-mode": "plot_flutter_mode",
    }

    @property
    def title(self) -> str | None:
        """The title saved with the sweep (None: none)."""
        return self.meta.get("title") or None

    def summary(self, warnings: bool = True, units: str = "si") -> str:
        """The sweep's summary (:meth:`FlutterResult.summary`)."""
        return self.result.summary(warnings=warnings, units=units)

    @property
    def table(self):
        """The sweep's branches (:attr:`FlutterResult.table`)."""
        return self.result.table

    def to_dict(self) -> dict:
        """The sweep's record (:meth:`FlutterResult.to_dict`) with the p-k sweep's (``pk``)."""
        return {**self.result.to_dict(), "pk": None if self.pk is None else self.pk.to_dict()}

    @property
    def figure_kinds(self) -> tuple[str, ...]:
        """The sweep's figures, and the mode shapes' when the file has them."""
        kinds = ["vg", "vf", "root-locus"] + (["modes"] if self.modes else [])
        if self.modes and self.flutter_mode is not None and self.result.flutter is not None:
            kinds.append("flutter-mode")
        return tuple(kinds)

    def plot_vg(self, **kw):
        """V-f and V-g diagrams with the p-k sweep and the saved title
        (:func:`aeroservo.plots.plot_vg`, its options)."""
        return self.result.plot_vg(**{"title": self.title, "pk": self.pk, **kw})

    def plot_vf(self, **kw):
        """The V-f panel alone (the options of :meth:`plot_vg`)."""
        return self.result.plot_vf(**{"title": self.title, "pk": self.pk, **kw})

    def plot_root_locus(self, **kw):
        """Root locus (:func:`aeroservo.plots.plot_root_locus`, its options)."""
        return self.result.plot_root_locus(**{"title": self.title, **kw})

    def plot_modes(self, fmax: float | None = None, modes=None, title: str | None = None):
        """The natural mode shapes saved with the sweep (:func:`aeroservo.plots.plot_modes`);
        ``fmax`` [Hz] and ``modes`` (numbers from 1) choose them as for :meth:`plot_vg`."""
        from .flutter_figures import mode_shapes_figure

        return mode_shapes_figure(self, fmax, modes, title or self.title)

    def plot_flutter_mode(self, title: str | None = None):
        """The flutter mode at the flutter speed (:func:`aeroservo.plots.plot_modes`)."""
        from .flutter_figures import flutter_mode_figure

        return flutter_mode_figure(self, title or self.title)


def _sweep_arrays(prefix: str, r: FlutterResult) -> dict:
    out = {
        f"{prefix}speeds": np.asarray(r.speeds, dtype=float),
        f"{prefix}eigenvalues": np.asarray(r.eigenvalues, dtype=complex),
        f"{prefix}frequencies": np.asarray(r.frequencies, dtype=float),
        f"{prefix}damping_zeta": np.asarray(r.damping_ratio, dtype=float),
        f"{prefix}damping_g": -2.0 * np.asarray(r.damping_ratio, dtype=float),
        f"{prefix}crossing_speed": np.array([c.speed for c in r.crossings], dtype=float),
        f"{prefix}crossing_frequency": np.array([c.frequency for c in r.crossings], dtype=float),
        f"{prefix}crossing_mode": np.array([c.mode for c in r.crossings], dtype=np.int64),
        f"{prefix}crossing_kind": np.array([c.kind for c in r.crossings], dtype="U10"),
    }
    if r.exact is not None:
        out[f"{prefix}exact"] = np.asarray(r.exact, dtype=bool)
    return out


def _sweep_meta(r: FlutterResult) -> dict:
    meta = {k: getattr(r, k) for k in _SCALARS}
    meta.update(mode_labels=list(r.mode_labels), warnings=list(r.warnings), info=r.info)
    meta["near_critical"] = [
        {**dataclasses.asdict(n), "speed_range": list(n.speed_range)} for n in r.near_critical
    ]
    return meta


def _flutter_vector(model, result: FlutterResult) -> np.ndarray | None:
    """Structural part of the full model's eigenvector at the flutter speed (None without
    flutter)."""
    fl = result.flutter
    if fl is None or model is None or not hasattr(model, "state_matrix"):
        return None
    import scipy.linalg as sla

    lam, X = sla.eig(model.state_matrix(fl.speed, result.density))
    target = 2j * np.pi * fl.frequency
    return X[: model.n_dofs, int(np.argmin(np.abs(lam - target)))]


def flutter_writer(
    result: FlutterResult,
    *,
    wing_text: str,
    model=None,
    pk: FlutterResult | None = None,
    title: str = "",
):
    """A writer of a flutter result's ``.npz`` for :func:`aeroservo.atomic.atomic_write_set`.

    Parameters
    ----------
    result : FlutterResult
    wing_text : str
        The wing file text (:func:`aeroservo.files.wing_file.wing_toml` for a built-in wing).
    model : AeroelasticModel, optional
        Adds the natural mode shapes and the flutter mode (nodal fields).
    pk : FlutterResult, optional
        The p-k sweep.
    title : str
        A title for redrawn figures.
    """
    modes, labels, surfaces, fmode = {}, [], {}, {}
    if model is not None and hasattr(model, "natural_modes"):
        nat = model.natural_modes(min(len(result.mode_labels), model.n_dofs))
        modes = dict(model.mode_fields(nat.shapes))
        modes["frequency"] = np.asarray(nat.frequencies, dtype=float)
        labels = list(nat.labels)
        surfaces = {cs.name: [float(cs.start), float(cs.end)] for cs in model.wing.control_surfaces}
        q = _flutter_vector(model, result)
        if q is not None:
            fld = model.mode_fields(q[:, None])
            fmode = {k: v if k == "x" else v[:, 0] for k, v in fld.items()}
    return _writer(result, pk, wing_text, title, (modes, labels, surfaces, fmode))


def saved_writer(saved: SavedFlutter):
    """A writer of the ``.npz`` of a sweep read back (:class:`SavedFlutter`): the same file
    again, with this aeroservo's version."""
    modes = {k: v for k, v in saved.modes.items() if k != "label"}
    labels = list(saved.modes.get("label", []))
    return _writer(
        saved.result,
        saved.pk,
        saved.wing_text,
        str(saved.meta.get("title") or ""),
        (modes, labels, dict(saved.surfaces), dict(saved.flutter_mode or {})),
    )


def _writer(result, pk, wing_text: str, title: str, shapes: tuple):
    """The writer of the arrays and JSON header of a sweep; ``shapes``: the mode fields
    (``x``, ..., ``frequency``), their labels, the surfaces and the flutter mode's fields."""
    modes, labels, surfaces, fmode = shapes
    arrays = _sweep_arrays("", result)
    meta = {
        "format": FORMAT,
        "aeroservo_version": __version__,
        "title": title,
        "units": UNITS,
        "sweep": _sweep_meta(result),
        "pk": None if pk is None else _sweep_meta(pk),
        "surfaces": surfaces if modes else {},
        "mode_labels": labels if modes else [],
    }
    if pk is not None:
        arrays.update(_sweep_arrays("pk.", pk))
    arrays.update({f"modes.{k}": v for k, v in modes.items()})
    arrays.update({f"flutter_mode.{k}": v for k, v in fmode.items()})
    arrays["wing_text"] = np.array(wing_text)
    arrays["meta"] = np.array(json_text(meta))

    def write(p: Path) -> None:
        with open(p, "wb") as fh:
            np.savez_compressed(fh, **arrays)

    return write


def _need(data: dict, key: str, path: Path, kind: str, ndim: int, shape=None) -> np.ndarray:
    if key not in data:
        raise InputError(f"{path}: not a complete aeroservo flutter result (no array {key!r})")
    a = data[key]
    ok_kind = a.dtype.kind in kind
    if not ok_kind or a.ndim != ndim or (shape is not None and a.shape != shape):
        want = f"{ndim}-D" + (f" of shape {shape}" if shape is not None else "")
        raise InputError(
            f"{path}: array {key!r} has dtype {a.dtype} and shape {a.shape}; expected {want}"
        )
    return a


def _sweep_from(data: dict, meta: dict, prefix: str, path: Path) -> FlutterResult:
    V = _need(data, f"{prefix}speeds", path, "f", 1)
    if V.size < 2 or not np.all(np.isfinite(V)) or np.any(np.diff(V) <= 0) or V[0] < 0:
        raise InputError(f"{path}: {prefix}speeds are not finite increasing speeds >= 0")
    lam = _need(data, f"{prefix}eigenvalues", path, "c", 2)
    if lam.shape[0] != V.size:
        raise InputError(f"{path}: {prefix}eigenvalues has {lam.shape[0]} rows for {V.size} speeds")
    n_c = _need(data, f"{prefix}crossing_speed", path, "f", 1).size
    cs = [
        _need(data, f"{prefix}crossing_{k}", path, kinds, 1, (n_c,))
        for k, kinds in (("speed", "f"), ("frequency", "f"), ("mode", "iu"), ("kind", "U"))
    ]
    exact = data.get(f"{prefix}exact")
    if exact is not None and (exact.dtype != bool or exact.shape != lam.shape):
        raise InputError(f"{path}: array {prefix + 'exact'!r} does not match the eigenvalues")
    labels = meta.get("mode_labels")
    if not isinstance(labels, list) or len(labels) != lam.shape[1]:
        raise InputError(f"{path}: header mode_labels does not match {lam.shape[1]} modes")
    try:
        scalars = {k: meta[k] for k in _SCALARS}
        crossings = [
            Crossing(float(s), float(f), int(m), str(k)) for s, f, m, k in zip(*cs, strict=True)
        ]
        return FlutterResult(
            speeds=V,
            eigenvalues=lam,
            mode_labels=[str(x) for x in labels],
            crossings=crossings,
            exact=exact,
            warnings=[str(w) for w in meta.get("warnings", [])],
            info=dict(meta.get("info") or {}),
            near_critical=[_near_critical(n, lam.shape[1]) for n in meta.get("near_critical", [])],
            **scalars,
        )
    except (KeyError, TypeError, ValueError) as exc:
        raise InputError(f"{path}: header of the flutter result is not valid ({exc})") from None


def _near_critical(n: dict, n_modes: int) -> NearCritical:
    lo, hi = (float(v) for v in n["speed_range"])
    mode = int(n["mode"])
    if not 0 <= mode < n_modes:
        raise ValueError(f"near_critical mode {mode} out of range")
    return NearCritical(
        float(n["speed"]),
        float(n["frequency"]),
        float(n["damping_ratio"]),
        (lo, hi),
        mode,
        float(n["threshold"]),
    )


def read_flutter(path: Path, data: dict, meta: dict) -> SavedFlutter:
    """A :class:`SavedFlutter` from the arrays and header of a flutter file (checked)."""
    if not isinstance(meta.get("sweep"), dict):
        raise InputError(f"{path}: header of the flutter result has no 'sweep' table")
    result = _sweep_from(data, meta["sweep"], "", path)
    pk = None
    if isinstance(meta.get("pk"), dict):
        pk = _sweep_from(data, meta["pk"], "pk.", path)
    wing = data.get("wing_text")
    if wing is None or wing.dtype.kind != "U" or wing.ndim != 0:
        raise InputError(f"{path}: not a complete aeroservo flutter result (no wing text)")
    modes, fmode = {}, None
    if "modes.x" in data:
        n = _need(data, "modes.x", path, "f", 1).size
        freq = _need(data, "modes.frequency", path, "f", 1)
        for key in [k for k in data if k.startswith("modes.") and k != "modes.frequency"]:
            shape = (n,) if key == "modes.x" else (n, freq.size)
            modes[key[6:]] = _need(data, key, path, "f", len(shape), shape)
        modes["frequency"] = freq
        modes["label"] = [str(x) for x in meta.get("mode_labels", [])]
        if len(modes["label"]) != freq.size:
            raise InputError(f"{path}: header mode_labels does not match the mode shapes")
        keys = [k for k in data if k.startswith("flutter_mode.")]
        if keys:
            fmode = {k[13:]: _need(data, k, path, "fc", 1, (n,)) for k in keys}
    surfaces = meta.get("surfaces") or {}
    if not isinstance(surfaces, dict):
        raise InputError(f"{path}: header 'surfaces' is not a table")
    return SavedFlutter(result, pk, str(wing), modes, fmode, surfaces, meta)


def open_npz(path: Path) -> tuple[dict, dict]:
    """The arrays and JSON header of an aeroservo ``.npz`` result (one clear error otherwise)."""
    what = "aeroservo result file (.npz)"
    head = file_head(path, 4, what)
    if head not in (b"PK\x03\x04", b"PK\x05\x06"):  # an archive (or an empty one)
        hint = "; a JSON summary? save a sweep with 'aeroservo flutter ... --save FILE.npz'"
        raise InputError(
            f"{path}: not an aeroservo result file (not a .npz archive"
            + (hint if head[:1] in (b"{", b"[") else "")
            + ")"
        )
    data = read_npz(path, what=what)
    raw = data.get("meta")
    if raw is None or raw.dtype.kind != "U" or raw.ndim != 0:
        raise InputError(f"{path}: not an aeroservo result file (no JSON header 'meta')")
    text = str(raw)
    if json_memory(text) > MAX_JSON_MEMORY:
        raise InputError(f"{path}: the result header is too large ({len(text)} characters)")
    try:
        meta = json.loads(text)
    except (json.JSONDecodeError, RecursionError) as exc:
        why = getattr(exc, "msg", "nested too deeply")
        raise InputError(f"{path}: the result header is not valid JSON ({why})") from None
    if not isinstance(meta, dict):
        raise InputError(f"{path}: the result header is not a JSON object")
    return data, meta
