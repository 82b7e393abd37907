"""Flutter-boundary benchmarks; every figure is a ratio to a baseline measured in the same run.

1. In-process Goland flutter boundary, 10 elements, certificate included, versus one dense
   ``scipy.linalg.eig`` of the same state matrix (target: <= 30 such eig times).
2. The same for 100 elements (target: < 1 s), model assembly reported separately.
3. Whole process ``aeroservo flutter goland --json`` versus ``python -c "import numpy,
   scipy.linalg"`` (target: <= 3x).
4. A 16-altitude flutter envelope (0-15 km, incompressible) versus one one-altitude boundary
   on a fresh model of the same wing (target: <= 20 such boundaries: the density-independent
   matrices are built once); the Prandtl-Glauert envelope (matched Mach at every altitude)
   is reported too.

Run: ``make bench`` (or ``python bench/bench_flutter.py``). Medians of repeated runs.
"""

from __future__ import annotations

import statistics
import subprocess
import sys
import time

import scipy.linalg as sla

import aeroservo as aes


def median_time(fn, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def in_process(n_elements: int, repeats: int) -> dict:
    t0 = time.perf_counter()
    model = aes.AeroelasticModel(aes.examples.goland(), n_elements)
    build = time.perf_counter() - t0
    aes.flutter_boundary(model, 1.225)  # warm-up (imports, caches)
    t_fb = median_time(lambda: aes.flutter_boundary(model, 1.225), repeats)
    a = model.state_matrix(137.0, 1.225)
    t_eig = median_time(lambda: sla.eig(a), max(3, repeats))
    return {
        "elements": n_elements,
        "n_states": model.n_states,
        "build_s": build,
        "boundary_s": t_fb,
        "eig_s": t_eig,
    }


def whole_process(repeats: int) -> dict:
    cli = [sys.executable, "-m", "aeroservo", "flutter", "goland", "--json"]
    base = [sys.executable, "-c", "import numpy, scipy.linalg"]

    def run(cmd):
        subprocess.run(cmd, check=True, capture_output=True)

    run(cli)
    return {
        "cli_s": median_time(lambda: run(cli), repeats),
        "import_s": median_time(lambda: run(base), repeats),
    }


def envelope_cost() -> dict:
    from aeroservo.studies.envelope import flutter_envelope

    alts = [1000.0 * k for k in range(16)]

    def one():
        aes.flutter_boundary(aes.AeroelasticModel(aes.examples.goland(), 10), 1.225)

    def env(comp):
        flutter_envelope(
            aes.AeroelasticModel(aes.examples.goland(), 10), alts, compressibility=comp
        )

    one()
    return {
        "one_s": median_time(one, 5),
        "env_s": median_time(lambda: env(None), 3),
        "env_pg_s": median_time(lambda: env("prandtl-glauert"), 1),
    }


def main() -> None:
    print("aeroservo flutter benchmarks (medians; ratios to baselines of the same run)")
    for n, reps in ((10, 15), (100, 3)):
        r = in_process(n, reps)
        ratio = r["boundary_s"] / r["eig_s"]
        ok = ratio <= 30.0 if n == 10 else r["boundary_s"] < 1.0
        target = "target <= 30 x eig" if n == 10 else "target < 1 s"
        print(
            f"  Goland {n:3d} elements ({r['n_states']} states): "
            f"boundary {r['boundary_s'] * 1e3:8.1f} ms = {ratio:6.1f} x one dense eig "
            f"({r['eig_s'] * 1e3:.2f} ms); assembly {r['build_s'] * 1e3:.1f} ms "
            f"[{target}: {'PASS' if ok else 'FAIL'}]"
        )
    e = envelope_cost()
    ratio = e["env_s"] / e["one_s"]
    print(
        f"  16-altitude envelope: {e['env_s']:.3f} s = {ratio:.1f} x one boundary "
        f"({e['one_s'] * 1e3:.1f} ms, fresh model) [target <= 20: "
        f"{'PASS' if ratio <= 20 else 'FAIL'}]; with Prandtl-Glauert (matched Mach) "
        f"{e['env_pg_s']:.2f} s = {e['env_pg_s'] / e['one_s']:.0f} x"
    )
    w = whole_process(5)
    ratio = w["cli_s"] / w["import_s"]
    print(
        f"  whole process 'aeroservo flutter goland --json': {w['cli_s']:.3f} s = {ratio:.2f} x "
        f"'import numpy, scipy.linalg' ({w['import_s']:.3f} s)"
    )


if __name__ == "__main__":
    main()
