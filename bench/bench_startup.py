"""Start-up benchmarks of the command line (issue 17); every figure is a ratio to a baseline
measured in the same run, interleaved with it.

1. Whole process ``aeroservo flutter goland --json`` versus ``python -c "import numpy,
   scipy.linalg"`` (target: <= 1.5 x).
2. ``aeroservo --help`` and an input error (a missing wing file, exit 2) versus ``python -c
   "import numpy"`` (target: each answers before numpy's import alone would finish, <= 1 x).
3. Peak resident memory of ``aeroservo flutter goland --json`` (target: <= 100 MB).
4. Issue 13: ``--save sweep.npz`` added to that run (target: < 5 % more time), and
   ``aeroservo plot sweep.npz`` versus ``python -c "import matplotlib.pyplot"`` (target:
   < 2 x).

The source is byte-compiled first (as ``make install`` does); Python would otherwise compile
every aeroservo module at each start where ``PYTHONDONTWRITEBYTECODE`` is set.

Run: ``make bench`` (or ``python bench/bench_startup.py [--quick]``). Times are medians of
interleaved runs (``--quick``: fewer runs); each ratio is the median of the ratios within one
round of the interleaving, which cancels the machine's slower and faster phases (a 5 % target
is below the spread of single runs).
"""

from __future__ import annotations

import compileall
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CLI = [sys.executable, "-m", "aeroservo"]
TMP = Path(tempfile.mkdtemp(prefix="aeroservo-bench-"))
SWEEP = str(TMP / "sweep.npz")
COMMANDS = {
    "flutter": [*CLI, "flutter", "goland", "--json"],
    "flutter --save": [*CLI, "flutter", "goland", "--json", "--save", SWEEP],
    "plot": [*CLI, "plot", SWEEP, "--out", str(TMP / "vg.png")],
    "matplotlib.pyplot": [sys.executable, "-c", "import matplotlib.pyplot"],
    "numpy+scipy.linalg": [sys.executable, "-c", "import numpy, scipy.linalg"],
    "help": [*CLI, "--help"],
    "input error": [*CLI, "flutter", "no_such_wing.toml"],
    "numpy": [sys.executable, "-c", "import numpy"],
}


def run(cmd: list[str]) -> tuple[float, float]:
    """Wall time [s] and peak RSS [MB] of one run of ``cmd`` (its exit code is not checked:
    the input error exits 2)."""
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _, _, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    proc.returncode = 0  # reaped by wait4
    return wall, usage.ru_maxrss / 1024.0  # kB on Linux


def verdict(ok: bool) -> str:
    return "PASS" if ok else "FAIL"


def main() -> None:
    quick = "--quick" in sys.argv
    repeats = 3 if quick else 15
    compileall.compile_dir(ROOT / "src", quiet=1)
    for cmd in COMMANDS.values():  # warm the file cache
        run(cmd)
    times: dict[str, list[float]] = {k: [] for k in COMMANDS}
    rss: list[float] = []
    for i in range(repeats):
        order = list(COMMANDS.items())
        for name, cmd in order if i % 2 == 0 else order[::-1]:  # no command always runs first
            wall, mem = run(cmd)
            times[name].append(wall)
            if name == "flutter":
                rss.append(mem)
    med = {k: statistics.median(v) for k, v in times.items()}

    def ratio(name: str, base: str) -> float:
        return statistics.median(a / b for a, b in zip(times[name], times[base], strict=True))

    print(
        f"aeroservo start-up (medians of {repeats} interleaved runs; ratios: medians of the "
        "ratios within each round)"
    )
    r = ratio("flutter", "numpy+scipy.linalg")
    print(
        f"  'aeroservo flutter goland --json': {med['flutter']:.3f} s = {r:.2f} x 'import numpy, "
        f"scipy.linalg' ({med['numpy+scipy.linalg']:.3f} s) [target <= 1.5 x: {verdict(r <= 1.5)}]"
    )
    for name in ("help", "input error"):
        r = ratio(name, "numpy")
        print(
            f"  'aeroservo {' '.join(COMMANDS[name][3:])}': {med[name]:.3f} s = {r:.2f} x "
            f"'import numpy' ({med['numpy']:.3f} s) [target <= 1 x: {verdict(r <= 1.0)}]"
        )
    r = ratio("flutter --save", "flutter")
    print(
        f"  '--save sweep.npz' adds {100 * (r - 1):+.1f} % to that run "
        f"[target < 5 %: {verdict(r < 1.05)}]"
    )
    r = ratio("plot", "matplotlib.pyplot")
    print(
        f"  'aeroservo plot sweep.npz': {med['plot']:.3f} s = {r:.2f} x 'import matplotlib.pyplot'"
        f" ({med['matplotlib.pyplot']:.3f} s) [target < 2 x: {verdict(r < 2.0)}]"
    )
    peak = max(rss)
    print(
        f"  peak RSS of 'aeroservo flutter goland --json': {peak:.0f} MB "
        f"[target <= 100 MB: {verdict(peak <= 100)}]"
    )


if __name__ == "__main__":
    main()
