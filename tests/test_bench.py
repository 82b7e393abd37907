"""The quick benchmarks run as a smoke test (issue 17): each prints its targets with a ratio
to a same-run baseline and PASS or FAIL, and exits 0. Timing is reported, never asserted (a
loaded CI machine may print FAIL; that does not fail the test)."""

import re
import subprocess
import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[1] / "bench"


@pytest.mark.slow
@pytest.mark.parametrize(
    "script,targets",
    [
        ("bench_startup.py", 6),
        ("bench_flutter.py", 4),
        ("bench_mpc_step.py", 1),
        ("bench_trade.py", 1),
        ("bench_gust_loads.py", 5),
        ("bench_lco.py", 5),
        ("bench_dlm.py", 3),
    ],
)
def test_quick_benchmark_reports_its_targets(script, targets):
    proc = subprocess.run(
        [sys.executable, str(BENCH / script), "--quick"],
        capture_output=True,
        text=True,
        timeout=900,
        cwd=BENCH,
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    verdicts = re.findall(r"\b(PASS|FAIL)\b", proc.stdout)
    assert len(verdicts) == targets, proc.stdout
    assert "Traceback" not in proc.stderr
