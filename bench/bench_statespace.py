"""State-space export benchmarks (targets from issue 3), with a same-run baseline.

* one model of the 10-element Goland-with-aileron at one speed, after the first build: < 10 ms;
* a 50-speed family: < 100 ms;
* baseline: one dense ``scipy.linalg.eig`` of the same state matrix.
"""

from __future__ import annotations

import time

import numpy as np
import scipy.linalg as sla
from _timing import median

import aeroservo as aes


def main() -> None:
    wing = aes.examples.goland_aileron()
    t0 = time.perf_counter()
    import control  # noqa: F401  (python-control's own import, reported apart)

    imp = time.perf_counter() - t0
    t0 = time.perf_counter()
    aes.statespace(wing, 120.0, 1.225)
    first = time.perf_counter() - t0
    speeds = np.linspace(60.0, 200.0, 50)
    one = median(lambda: aes.statespace(wing, 130.0, 1.225), 50)
    fam = median(lambda: aes.statespace_family(wing, speeds, 1.225), 10)
    sys = aes.statespace(wing, 130.0, 1.225)
    eig = median(lambda: sla.eig(np.asarray(sys.A)), 20)
    print("aeroservo state-space export (10-element Goland with aileron, medians)")
    print(f"  import control (python-control itself): {imp * 1e3:8.2f} ms")
    print(f"  first build (mesh, assembly, builder): {first * 1e3:8.2f} ms")
    print(f"  one dense eig of the same A (baseline): {eig * 1e3:8.3f} ms")
    print(f"  one speed after the first build:       {one * 1e3:8.3f} ms = {one / eig:.2f} x eig")
    print(f"  50-speed family:                       {fam * 1e3:8.2f} ms = {fam / eig:.1f} x eig")


if __name__ == "__main__":
    main()
