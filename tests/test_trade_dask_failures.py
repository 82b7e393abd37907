"""Failures of a trade study's Dask cluster, on a real scheduler and workers that the tests
start on loopback as subprocesses (``python -m dask scheduler`` / ``dask worker``) and kill,
with their process groups, when they end.

* no scheduler at the address: one line naming it, in seconds (it took 60 s), no files left;
* a scheduler without workers: one line naming it and how to start a worker (it took 60 s and
  ended in Dask's raw "No valid workers found");
* a worker killed while the study runs: the study completes and a warning names the worker and
  the cases Dask resubmitted (it passed unnoticed);
* Ctrl-C (SIGINT to the command's process group, as a terminal sends it): one line saying how
  many cases are written (it printed a screen of ``CancelledError`` warnings and tracebacks).

No test times anything closely: "in seconds" is checked against a generous 30 s.
"""

from __future__ import annotations

import json
import os
import re
import signal
import socket
import subprocess
import sys
import threading
import time
import warnings
from pathlib import Path

import pytest

import aeroservo as aes
from aeroservo.errors import InputError
from aeroservo.files import load_controller
from aeroservo.studies import trade

ROOT = Path(__file__).parent.parent
SCENARIO = ROOT / "scenarios" / "trade_aileron.toml"
ENV = {
    **os.environ,
    "OMP_NUM_THREADS": "1",
    "OPENBLAS_NUM_THREADS": "1",
    "MKL_NUM_THREADS": "1",
    "PYTHONUNBUFFERED": "1",
}
STARTUP = 120.0  # s allowed for a subprocess to come up on a loaded 2-core machine
SECONDS = 30.0  # "fails within a few seconds": well under Dask's former 60 s, with margin


class Processes:
    """Subprocesses of a test, each in its own process group, all killed at the end."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder
        self.procs: list[subprocess.Popen] = []

    def start(self, name: str, *args: str) -> subprocess.Popen:
        log = open(self.folder / f"{name}.log", "w")  # noqa: SIM115 (closed in stop)
        p = subprocess.Popen(
            [sys.executable, *args],
            stdout=log,
            stderr=subprocess.STDOUT,
            env=ENV,
            cwd=self.folder,
            start_new_session=True,
        )
        p.log = log
        self.procs.append(p)
        return p

    @staticmethod
    def kill(p: subprocess.Popen) -> None:
        try:
            os.killpg(p.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        p.wait(timeout=30)

    def stop(self) -> None:
        for p in self.procs:
            self.kill(p)
            p.log.close()


@pytest.fixture
def procs(tmp_path):
    p = Processes(tmp_path)
    yield p
    p.stop()


def scheduler(procs: Processes) -> str:
    """Start a scheduler on loopback; its address."""
    info = procs.folder / "scheduler.json"
    p = procs.start(
        "scheduler",
        *("-m", "dask", "scheduler", "--host", "127.0.0.1", "--port", "0"),
        *("--no-dashboard", "--scheduler-file", str(info)),
    )
    deadline = time.monotonic() + STARTUP
    while time.monotonic() < deadline:
        assert p.poll() is None, (procs.folder / "scheduler.log").read_text()
        try:
            return json.loads(info.read_text())["address"]
        except (OSError, ValueError, KeyError):
            time.sleep(0.1)
    raise AssertionError("the scheduler did not start")


def worker(procs: Processes, address: str, name: str) -> subprocess.Popen:
    """Start a single-threaded worker process (no nanny: killing it loses it)."""
    return procs.start(
        f"worker-{name}",
        *("-m", "dask", "worker", address, "--name", name, "--nthreads", "1"),
        *("--no-nanny", "--host", "127.0.0.1", "--no-dashboard"),
        *("--local-directory", str(procs.folder)),
    )


def free_port() -> int:
    """A loopback port nobody listens on (bound and released)."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def case_files(folder: Path) -> list[Path]:
    """The finished case files in ``folder`` (not the temporary files being written)."""
    return [f for f in folder.glob("*.json") if not f.name.startswith(".")]


def files_under(folder: Path) -> list[Path]:
    return [p for p in folder.rglob("*") if p.is_file()] if folder.exists() else []


def run_cli(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "aeroservo", *args],
        capture_output=True,
        text=True,
        env=ENV,
        cwd=cwd,
        timeout=300,
    )


def one_line(stderr: str) -> str:
    lines = [line for line in stderr.splitlines() if line.strip()]
    assert len(lines) == 1, stderr
    assert "Traceback" not in stderr and "CancelledError" not in stderr, stderr
    return lines[0]


@pytest.fixture(scope="module")
def study() -> trade.TradeStudy:
    """8 closed-loop cases of a second or so each."""
    return trade.TradeStudy(
        base_wing=aes.examples.goland_aileron(),
        controller=load_controller(ROOT / "controllers" / "lqr.toml"),
        parameters={
            "aileron_chord": (0.15, 0.2),
            "bryson_hinge_moment": (250.0, 500.0, 1000.0, 2000.0),
        },
        gust_duration=0.3,
        n_grid=11,
        name="lost",
    )


def timed_trade(address: str, out: Path, cwd: Path):
    """``aeroservo trade`` of the quick study on the scheduler at ``address``, and how long it
    took [s]."""
    t0 = time.monotonic()
    r = run_cli(
        "trade", str(SCENARIO), "--quick", "--out", str(out), "--scheduler", address, cwd=cwd
    )
    return r, time.monotonic() - t0


@pytest.mark.slow
def test_no_scheduler_at_address(tmp_path, study):
    address = f"tcp://127.0.0.1:{free_port()}"
    out = tmp_path / "out"
    r, elapsed = timed_trade(address, out, tmp_path)
    assert r.returncode == 2, r.stderr
    line = one_line(r.stderr)
    assert line.startswith("aeroservo: error: ") and address in line, line
    assert "no Dask scheduler answered within 5 s" in line, line
    assert elapsed < SECONDS, elapsed
    assert not files_under(out), files_under(out)

    # the API: the timeout is a parameter
    with pytest.raises(InputError, match=re.escape(f"scheduler = '{address}': no Dask sch")):
        trade.run_trade(study, tmp_path / "api", scheduler=address, connect_timeout=1.0)
    assert not (tmp_path / "api").exists()


@pytest.mark.slow
def test_scheduler_without_workers(procs, tmp_path, study):
    address = scheduler(procs)
    out = tmp_path / "out"
    r, elapsed = timed_trade(address, out, tmp_path)
    assert r.returncode == 2, r.stderr
    line = one_line(r.stderr)
    assert f"scheduler = '{address}' has no workers (waited 10 s)" in line, line
    assert f"'dask worker {address}'" in line, line
    assert "No valid workers" not in line
    assert elapsed < SECONDS, elapsed
    assert not files_under(out), files_under(out)

    with pytest.raises(InputError, match="has no workers .waited 1 s"):
        trade.run_trade(study, tmp_path / "api", scheduler=address, worker_timeout=1.0)
    assert not (tmp_path / "api").exists()


@pytest.mark.slow
def test_lost_worker_reported_and_study_completes(procs, tmp_path, study):
    from distributed import Client

    address = scheduler(procs)
    worker(procs, address, "a")
    doomed = worker(procs, address, "b")
    with Client(address, timeout=f"{STARTUP}s") as client:
        client.wait_for_workers(2, timeout=STARTUP)
        [doomed_address] = [
            w for w, info in client.scheduler_info()["workers"].items() if info["name"] == "b"
        ]

    out = tmp_path / "study"
    cases = out / "cases"

    def kill_once_a_case_is_written():
        deadline = time.monotonic() + STARTUP
        while time.monotonic() < deadline and not case_files(cases):
            time.sleep(0.02)
        procs.kill(doomed)  # cases remain: the doomed worker is processing some

    killer = threading.Thread(target=kill_once_a_case_is_written, daemon=True)
    killer.start()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = trade.run_trade(study, out, scheduler=address, progress=False)
    killer.join(timeout=60)
    assert doomed.poll() is not None  # it was killed while the study ran

    assert result.n_cases == 8 and result.n_failed == 0, result.table[["status", "error"]]
    assert len(case_files(cases)) == 8
    notes = [str(w.message) for w in caught if "Dask worker" in str(w.message)]
    assert len(notes) == 1, [str(w.message) for w in caught]
    m = re.fullmatch(
        rf"Dask worker {re.escape(doomed_address)} was lost during the study; (\d+) of its "
        r"cases (was|were) resubmitted to the other workers",
        notes[0],
    )
    assert m and 1 <= int(m[1]) <= 7, notes[0]


@pytest.mark.slow
def test_ctrl_c_prints_one_line(procs, tmp_path):
    out = tmp_path / "out"
    cases = out / "trade_aileron" / "cases"
    p = subprocess.Popen(
        [sys.executable, "-m", "aeroservo", "trade", str(SCENARIO), "--quick"]
        + ["--out", str(out), "--no-progress", "--workers", "2"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=ENV,
        cwd=tmp_path,
        start_new_session=True,  # its own process group, its local cluster's workers in it
    )
    p.log = open(os.devnull, "w")  # noqa: SIM115 (closed by the fixture)
    procs.procs.append(p)
    deadline = time.monotonic() + STARTUP
    while time.monotonic() < deadline and p.poll() is None:
        if case_files(cases):
            break
        time.sleep(0.02)
    assert p.poll() is None, p.communicate()
    os.killpg(p.pid, signal.SIGINT)  # Ctrl-C in a terminal: the whole foreground group
    _, stderr = p.communicate(timeout=120)
    assert p.returncode == 130, stderr
    line = one_line(stderr)
    m = re.fullmatch(
        rf"aeroservo: interrupted: (\d+) of (\d+) cases written to {re.escape(str(cases))}; run "
        "the study again to resume",
        line,
    )
    assert m, line
    # the count is what is on disk (a case seen by the poll above is normally among them;
    # once, under a full-suite load, the count was 0: see the issue 25 note)
    assert int(m[1]) == len(case_files(cases)) < int(m[2]), (line, case_files(cases))
