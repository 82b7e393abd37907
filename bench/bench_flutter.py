"""Flutter-boundary benchmarks; every figure is a ratio to a baseline measured in the same run.

1. In-process Goland flutter boundary, 10 elements, certificate included, versus one dense
   ``scipy.linalg.eig`` of the same state matrix (target, issue 17: <= 10 such eig times).
2. The same for 100 elements (target, issue 17: <= 0.2 s), model assembly reported separately.
3. A 16-altitude flutter envelope (0-15 km, incompressible) versus one one-altitude boundary
   on a fresh model of the same wing (target: <= 20 such boundaries: the density-independent
   matrices are built once); the Prandtl-Glauert envelope (matched Mach at every altitude)
   is reported too.
4. All analytic sensitivities of the Goland wing with aileron (17 parameters: flutter speed and
   frequency, divergence speed) versus one flutter boundary of the same model (target, issue
   16: <= 3 boundaries; central differences would cost 34).

The whole-process start-up is in ``bench_startup.py``.

Run: ``make bench`` (or ``python bench/bench_flutter.py [--quick]``). Medians of repeated runs
(``--quick``: fewer, and no Prandtl-Glauert envelope).
"""

from __future__ import annotations

import statistics
import sys
import time

import scipy.linalg as sla
from _timing import median

import aeroservo as aes


def in_process(n_elements: int, repeats: int) -> dict:
    """Boundary and baseline eig timed alternately (the machine's speed drifts between runs:
    the ratio of each pair is robust to it); the baseline eig runs with the same BLAS thread
    limit as the boundary (:mod:`aeroservo._threads`)."""
    from aeroservo._threads import blas_limited

    t0 = time.perf_counter()
    model = aes.AeroelasticModel(aes.examples.goland(), n_elements)
    build = time.perf_counter() - t0
    aes.flutter_boundary(model, 1.225)  # warm-up (imports, caches)
    a = model.state_matrix(137.0, 1.225)
    eig = blas_limited(sla.eig)
    t_fb, t_eig, ratios = [], [], []
    for _ in range(repeats):
        t_fb.append(median(lambda: aes.flutter_boundary(model, 1.225), 1))
        t_eig.append(median(lambda: eig(a), 5 if n_elements <= 20 else 1))
        ratios.append(t_fb[-1] / t_eig[-1])
    return {
        "elements": n_elements,
        "n_states": model.n_states,
        "build_s": build,
        "boundary_s": statistics.median(t_fb),
        "eig_s": statistics.median(t_eig),
        "ratio": statistics.median(ratios),
    }


def envelope_cost(quick: bool) -> dict:
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
        "one_s": median(one, 3 if quick else 5),
        "env_s": median(lambda: env(None), 1 if quick else 3),
        "env_pg_s": None if quick else median(lambda: env("prandtl-glauert"), 1),
    }


def sensitivity_cost(quick: bool) -> dict:
    from aeroservo.stability.sensitivity import flutter_sensitivities

    model = aes.AeroelasticModel(aes.examples.goland_aileron(), 10)
    flutter_sensitivities(model, 1.225)  # warm-up
    ratios = []
    for _ in range(3 if quick else 9):
        one = median(lambda: aes.flutter_boundary(model, 1.225), 1)
        sens = median(lambda: flutter_sensitivities(model, 1.225), 1)
        ratios.append(sens / one)
    n = len(flutter_sensitivities(model, 1.225).values)
    return {"ratio": statistics.median(ratios), "n": n, "one_s": one}


def main() -> None:
    quick = "--quick" in sys.argv
    print("aeroservo flutter benchmarks (medians; ratios to baselines of the same run)")
    for n, reps in ((10, 5 if quick else 21), (100, 1 if quick else 5)):
        r = in_process(n, reps)
        ratio = r["ratio"]
        ok = ratio <= 10.0 if n == 10 else r["boundary_s"] <= 0.2
        target = "target <= 10 x eig" if n == 10 else "target <= 0.2 s"
        print(
            f"  Goland {n:3d} elements ({r['n_states']} states): "
            f"boundary {r['boundary_s'] * 1e3:8.1f} ms = {ratio:6.1f} x one dense eig "
            f"({r['eig_s'] * 1e3:.2f} ms); assembly {r['build_s'] * 1e3:.1f} ms "
            f"[{target}: {'PASS' if ok else 'FAIL'}]"
        )
    e = envelope_cost(quick)
    ratio = e["env_s"] / e["one_s"]
    pg = (
        ""
        if e["env_pg_s"] is None
        else f"; with Prandtl-Glauert (matched Mach) {e['env_pg_s']:.2f} s = "
        f"{e['env_pg_s'] / e['one_s']:.0f} x"
    )
    print(
        f"  16-altitude envelope: {e['env_s']:.3f} s = {ratio:.1f} x one boundary "
        f"({e['one_s'] * 1e3:.1f} ms, fresh model) [target <= 20: "
        f"{'PASS' if ratio <= 20 else 'FAIL'}]{pg}"
    )
    s = sensitivity_cost(quick)
    print(
        f"  sensitivities, Goland with aileron: {s['n']} parameters for {s['ratio']:.2f} x one "
        f"boundary ({s['one_s'] * 1e3:.1f} ms; central differences: {2 * s['n']} boundaries) "
        f"[target <= 3: {'PASS' if s['ratio'] <= 3 else 'FAIL'}]"
    )


if __name__ == "__main__":
    main()
