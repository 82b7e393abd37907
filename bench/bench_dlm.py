"""Doublet-lattice benchmarks (issue 36); every figure is a ratio to a baseline measured in the
same run: the flutter boundary of a fresh strip-theory Goland model (10 elements).

1. Cold AICs of Goland at the default grid (6 chordwise x 20 spanwise boxes, mirrored at the
   root), the 12 default reduced frequencies and the steady vortex lattice (k = 0), with a fresh
   disk cache and the in-memory cache cleared (target, issue 36: < 5 s). The parabolic kernel
   and the read-back from the disk cache are reported too.
2. A cached flutter boundary: a fresh doublet-lattice model whose AICs are in the disk cache
   (the in-memory cache cleared, as in a repeated run), its GAFs, RFA fit and flutter boundary,
   versus a fresh strip model and its boundary (target: <= 3 x).
3. The RFA fit (GAFs from cached AICs, the default Roger fit of the modal and gust columns,
   fit errors; target: < 1 s), the minimum-state fit reported too, and the time-domain
   model's size (structural states, lag states, gust states).

The benchmark uses its own temporary AIC cache (``AEROSERVO_CACHE``), never the user's.

Run: ``make bench`` (or ``python bench/bench_dlm.py [--quick]``). Medians of repeated runs
(``--quick``: fewer).
"""

from __future__ import annotations

import os
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path

from _timing import median

import aeroservo as aes
from aeroservo.aero import dlm as dlm_aics
from aeroservo.aero.dlm_settings import DoubletLattice

RHO = 1.225


def strip_boundary() -> None:
    """The baseline: a fresh strip model of Goland and its flutter boundary."""
    aes.flutter_boundary(aes.AeroelasticModel(aes.examples.goland(), 10), RHO)


def dlm_model(**settings) -> aes.AeroelasticModel:
    return aes.AeroelasticModel(aes.examples.goland(), 10, aero=DoubletLattice(**settings))


def fresh_cache(root: Path, i: int) -> None:
    """An empty disk cache and an empty in-memory cache."""
    os.environ["AEROSERVO_CACHE"] = str(root / f"cache{i}")
    dlm_aics._MEMORY.clear()


def cold_aics(root: Path, repeats: int) -> dict:
    """Cold AICs (quartic and parabolic kernels) alternated with the baseline."""
    model = dlm_model()
    lattice, k = model.dlm.grid.lattice, model.aero.k_values / model.dlm.b_ref
    dlm_aics._panelaero()  # PanelAero's import (once per process) is not part of the AICs
    strip_boundary()  # warm-up
    t = {"quartic": [], "parabolic": [], "strip": [], "read": []}
    n = 0
    for _ in range(repeats):
        for kernel in ("quartic", "parabolic"):
            fresh_cache(root, n)
            n += 1
            t[kernel].append(
                median(lambda kern=kernel: dlm_aics.aics(lattice, 0.0, k, kernel=kern), 1)
            )
        dlm_aics._MEMORY.clear()  # the parabolic set stays on disk: read it back
        t["read"].append(median(lambda: dlm_aics.aics(lattice, 0.0, k, kernel="parabolic"), 1))
        t["strip"].append(median(strip_boundary, 3))
    out = {key: statistics.median(v) for key, v in t.items()}
    out.update(
        boxes=lattice.n_boxes,
        mirrored=2 * lattice.n_boxes if lattice.symmetric else lattice.n_boxes,
        n_k=int((model.aero.k_values > 0).sum()),
        threads=dlm_aics.THREADS,
    )
    return out


def cached_boundary(root: Path, repeats: int) -> dict:
    """A repeated run's boundary (AICs on disk, not in memory) and the baseline, alternated."""
    fresh_cache(root, 1000)
    first = time.perf_counter()
    aes.flutter_boundary(dlm_model(), RHO)  # computes and stores the AICs
    first = time.perf_counter() - first

    def disk():
        dlm_aics._MEMORY.clear()
        return aes.flutter_boundary(dlm_model(), RHO)

    def memory():
        return aes.flutter_boundary(dlm_model(), RHO)

    disk()  # warm-up
    ratios, t_dlm, t_strip = [], [], []
    for _ in range(repeats):
        t_dlm.append(median(disk, 1))
        t_strip.append(median(strip_boundary, 1))
        ratios.append(t_dlm[-1] / t_strip[-1])
    result = disk()
    return {
        "first_s": first,
        "dlm_s": statistics.median(t_dlm),
        "memory_s": median(memory, 3),
        "strip_s": statistics.median(t_strip),
        "ratio": statistics.median(ratios),
        "speed": result.flutter_speed,
        "frequency": result.flutter_frequency,
    }


def rfa_fit(repeats: int) -> dict:
    """GAFs and the RFA fit of a fresh model whose AICs are in memory (the cache above)."""
    out = {}
    for kind in ("roger", "minimum-state"):
        dlm_model(rfa=kind).dlm_fit(0.0)  # warm-up (AICs already cached: same lattice and k)

        def fit(kind=kind):
            m = dlm_model(rfa=kind)
            t0 = time.perf_counter()
            f = m.dlm_fit(0.0)
            return time.perf_counter() - t0, m, f

        runs = [fit() for _ in range(repeats)]
        _, model, f = runs[-1]
        system = model.system(RHO)
        out[kind] = {
            "fit_s": statistics.median(r[0] for r in runs),
            "n_states": system.n_states,
            "n_modes": model.dlm.n_a,
            "lag_states": f.forces.n_lag_states,
            "gust_states": f.gust.n_lag_states,
            "max_error": float(f.error.max()),
            "max_gust_error": float(f.gust_error.max()),
            "roots": f.forces.roots.size,
            "model": model,
        }
    m = out["roger"]["model"]
    import control  # noqa: F401  (its import, ~0.6 s, is not the model's build)

    t0 = time.perf_counter()
    ss = aes.statespace(m, 150.0, RHO)
    out["statespace_s"] = time.perf_counter() - t0
    out["ss_states"] = ss.nstates
    out["ss_inputs"] = list(ss.input_labels)
    return out


def main() -> None:
    quick = "--quick" in sys.argv
    root = Path(tempfile.mkdtemp(prefix="aeroservo-bench-dlm-"))
    try:
        run(quick, root)
    finally:
        shutil.rmtree(root, ignore_errors=True)


def run(quick: bool, root: Path) -> None:
    print(
        "aeroservo doublet-lattice benchmarks, Goland 10 elements, default grid (medians; "
        "ratios to a fresh strip model's flutter boundary in the same run)"
    )
    a = cold_aics(root, 1 if quick else 3)
    ok = a["quartic"] < 5.0
    print(
        f"  AICs cold: {a['boxes']} boxes ({a['mirrored']} with the mirror image), "
        f"{a['n_k']} reduced frequencies + steady, {a['threads']} threads: quartic kernel "
        f"{a['quartic']:.2f} s = {a['quartic'] / a['strip']:.0f} x one strip boundary "
        f"({a['strip'] * 1e3:.1f} ms); parabolic {a['parabolic']:.2f} s; read back from the "
        f"disk cache {a['read'] * 1e3:.1f} ms "
        f"[target < 5 s: {'PASS' if ok else 'FAIL'}]"
    )
    c = cached_boundary(root, 3 if quick else 9)
    ok = c["ratio"] <= 3.0
    print(
        f"  cached flutter boundary (fresh model, AICs from the disk cache, GAFs, fit, "
        f"boundary): {c['dlm_s'] * 1e3:.1f} ms = {c['ratio']:.2f} x a fresh strip model's "
        f"boundary ({c['strip_s'] * 1e3:.1f} ms); AICs in memory {c['memory_s'] * 1e3:.1f} ms; "
        f"first (cold) {c['first_s']:.2f} s; {c['speed']:.2f} m/s, {c['frequency']:.2f} Hz "
        f"[target <= 3 x: {'PASS' if ok else 'FAIL'}]"
    )
    f = rfa_fit(3 if quick else 9)
    r, ms = f["roger"], f["minimum-state"]
    ok = r["fit_s"] < 1.0  # the default (Roger) fit; the minimum-state fit is reported
    print(
        f"  RFA fit (GAFs from cached AICs, {r['n_modes']} modes + 3 root rows, {r['roots']} lag "
        f"roots): Roger {r['fit_s'] * 1e3:.1f} ms = {r['fit_s'] / c['strip_s']:.1f} x one strip "
        f"boundary, fit error {r['max_error']:.3f} (gust {r['max_gust_error']:.3f}) "
        f"[target < 1 s: {'PASS' if ok else 'FAIL'}]; minimum-state (reported) "
        f"{ms['fit_s'] * 1e3:.1f} ms, fit error {ms['max_error']:.3f}"
    )
    for kind, d in (("Roger", r), ("minimum-state", ms)):
        print(
            f"  time-domain model, {kind}: {d['n_states']} states = {2 * d['n_modes']} "
            f"structural ({d['n_modes']} modes) + {d['lag_states']} lag states; "
            f"+ {d['gust_states']} gust lag states with the gust input"
        )
    print(
        f"  state space at 150 m/s (inputs {', '.join(f['ss_inputs'])}): {f['ss_states']} "
        f"states, built in {f['statespace_s'] * 1e3:.0f} ms"
    )


if __name__ == "__main__":
    main()
