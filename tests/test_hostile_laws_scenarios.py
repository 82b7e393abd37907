"""Hostile inputs on Python laws, gain files, engaged ranges, limit-cycle and gust-loads
scenarios and wing files (issue 40 item 2).

Each case writes a short scenario (a shipped one copied into ``tmp_path`` with keys changed),
runs the command line in this process (``aeroservo.cli.main``) with stdout and stderr
captured, and requires the rule of issue 40: exit code 2 with one line naming the file, the
key and the value (1 for a numerical failure, 3 only for a failed verdict), no traceback,
nothing written to the output folder and no file of the case changed or added (no
``__pycache__`` next to a law). A watchdog interrupts a case that runs past
:data:`CASE_LIMIT` seconds (pytest-timeout is not installed): the command line then returns 130
and the case fails instead of hanging; the laws that loop forever run with ``budget_s = 0.2``.
"""

from __future__ import annotations

import _thread
import contextlib
import hashlib
import io
import signal
import threading
import time
from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT

from aeroservo.cli import main

SCENARIOS = ROOT / "scenarios"
CONTROLLERS = ROOT / "controllers"
CASE_LIMIT = 60.0
"""Seconds a case may run before the watchdog interrupts it."""


@contextlib.contextmanager
def watchdog(seconds: float = CASE_LIMIT):
    """Interrupt the main thread (KeyboardInterrupt) if the body runs past ``seconds``."""
    timer = threading.Timer(seconds, _thread.interrupt_main)
    timer.daemon = True
    timer.start()
    try:
        yield
    finally:
        timer.cancel()


def run_cli(argv: list[str]) -> tuple[int, str, str]:
    """``(exit code, stdout, stderr)`` of the command line run in this process."""
    out, err = io.StringIO(), io.StringIO()
    with watchdog(), contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    return code, out.getvalue(), err.getvalue()


def snapshot(folder: Path) -> dict:
    """Every file under ``folder`` with the hash of its content."""
    return {
        str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


# -- the files of a case -------------------------------------------------------------------


def simulate_files(tmp: Path, controller: str, edits: dict | None = None) -> Path:
    """``s.toml``: ``goland_aileron_lqr.toml`` with the wing beside it, controller file
    ``ctrl.toml`` (its text), no closed-loop sweep, 0.2 s; ``edits``: lines replaced."""
    (tmp / "wing.toml").write_text((SCENARIOS / "goland_aileron.toml").read_text())
    text = (SCENARIOS / "goland_aileron_lqr.toml").read_text()
    edits = {
        'file = "goland_aileron.toml"': 'file = "wing.toml"',
        'spec = "../controllers/lqr.toml"': 'spec = "ctrl.toml"',
        "closed_loop_boundary = true": "closed_loop_boundary = false",
        "duration = 3.0": "duration = 0.2",
    } | (edits or {})
    for old, new in edits.items():
        assert old in text, old
        text = text.replace(old, new)
    (tmp / "s.toml").write_text(text)
    (tmp / "ctrl.toml").write_text(controller)
    return tmp / "s.toml"


PYTHON = (
    'type = "python"\nfile = "{file}"\nfunction = "command"\n'
    'sensors = ["tip_le_accel", "tip_te_accel", "tip_twist"]\n{extra}'
)


def law_case(law: str, *, file: str = "law.py", extra: str = "budget_s = 0.2\n"):
    """A simulate scenario whose controller is the Python law ``law`` (the text of its file)."""

    def make(tmp: Path) -> list[str]:
        (tmp / file).write_text(law)
        s = simulate_files(tmp, PYTHON.format(file=file, extra=extra))
        return ["simulate", str(s)]

    return make


def lqr_case(edits: dict, controller: str | None = None):
    """A simulate scenario with the shipped LQR (or ``controller``) and ``edits``."""

    def make(tmp: Path) -> list[str]:
        text = controller or (CONTROLLERS / "lqr.toml").read_text()
        return ["simulate", str(simulate_files(tmp, text, edits))]

    return make


SECTION = """[scenario]
name = "section"
kind = "lco"
[section]
semichord = 0.127
a = -0.5
mass = 3.3843
x_alpha = 0.19979
inertia = 0.01347
k_plunge = 2818.8
k_pitch = 37.34
hinge = 0.5
flap_static_moment = 0.00395
flap_inertia = 0.0003264
k_flap = 3.9
[flight]
density = 1.225
[lco]
speeds = {speeds}
amplitudes = {amplitudes}
duration = {duration}
dt = {dt}
[[lco.hinges]]
target = "flap"
law = "freeplay"
gap = 0.074
[output]
result = "lco"
"""


def lco_case(
    key: str | None = None,
    value: str = "",
    *,
    speeds="[10.0, 20.0]",
    amplitudes="[0.05]",
    duration="1.0",
    dt="0.001",
):
    """A limit-cycle scenario of a typical section with ``[section] key = value``."""

    def make(tmp: Path) -> list[str]:
        text = SECTION.format(speeds=speeds, amplitudes=amplitudes, duration=duration, dt=dt)
        if key is not None:
            lines = [f"{key} = {value}" if ln.startswith(f"{key} = ") else ln for ln in
                     text.splitlines()]  # fmt: skip
            text = "\n".join(lines) + "\n"
        (tmp / "s.toml").write_text(text)
        return ["lco", str(tmp / "s.toml")]

    return make


def gust_case(points: list[tuple], gust_loads: str = "", flight: str = "speed_factor = 1.1"):
    """A gust-loads scenario (open loop without a flight table; the LQR of ``lqr.toml`` with
    ``flight``) with flight points ``(altitude, speed, speed_name)``."""

    def make(tmp: Path) -> list[str]:
        (tmp / "wing.toml").write_text((SCENARIOS / "goland_aileron.toml").read_text())
        text = (
            '[scenario]\nname = "g"\nkind = "gust_loads"\n[wing]\nfile = "wing.toml"\n'
            "[model]\nelements = 6\n"
        )
        if flight:
            (tmp / "ctrl.toml").write_text((CONTROLLERS / "lqr.toml").read_text())
            text += (
                f"[flight]\ndensity = 1.225\n{flight}\n"
                '[signals]\ncontrols = ["aileron_hinge_moment"]\n'
                'sensors = ["tip_le_accel", "tip_te_accel", "tip_twist"]\n'
                'outputs = ["tip_disp", "aileron_deflection"]\n'
                '[controller]\nspec = "ctrl.toml"\n'
            )
        text += f"[gust_loads]\nn_gradients = 3\nturbulence = false\n{gust_loads}\n"
        for alt, speed, name in points:
            text += (
                f'[[gust_loads.points]]\naltitude = {alt}\nspeed = {speed}\nspeed_name = "{name}"\n'
            )
        text += '[output]\nresult = "g"\n'
        (tmp / "s.toml").write_text(text)
        return ["loads", str(tmp / "s.toml")]

    return make


RAISES = "def command(t, y):\n    if t > 0.05:\n        raise KeyError('boom')\n    return [0.0]\n"


def law_study_case(kind: str):
    """A limit-cycle (``kind = "lco"``, the wing's freeplay under the loop) or gust-loads
    scenario whose controller is a Python law that raises at t = 0.051 s: the study stops
    (a failed march of its own would be recorded, a failing law is not)."""

    def make(tmp: Path) -> list[str]:
        (tmp / "law.py").write_text(RAISES)
        ctrl = PYTHON.format(file="law.py", extra="budget_s = 0.2\n")
        if kind == "loads":
            argv = gust_case([(0.0, 100.0, "V_C")])(tmp)
            (tmp / "ctrl.toml").write_text(ctrl)
            return argv
        (tmp / "wing.toml").write_text((SCENARIOS / "goland_aileron.toml").read_text())
        text = (SCENARIOS / "goland_aileron_freeplay_lqr.toml").read_text()
        for old, new in {
            'file = "goland_aileron.toml"': 'file = "wing.toml"',
            'spec = "../controllers/lqr.toml"': 'spec = "ctrl.toml"',
            "speeds = [120.0, 130.0, 137.0, 140.0, 145.0, 150.0, 155.0, 160.0]": "speeds = [130.0]",
            "duration = 10.0": "duration = 1.0",
            "history = 2.0": "history = 0.5",
        }.items():
            assert old in text, old
            text = text.replace(old, new)
        (tmp / "s.toml").write_text(text)
        (tmp / "ctrl.toml").write_text(ctrl)
        return ["lco", str(tmp / "s.toml")]

    return make


def wing_case(line: str):
    """The flutter command on the shipped Goland wing with ``line`` added to its segment."""

    def make(tmp: Path) -> list[str]:
        text = (SCENARIOS / "goland.toml").read_text()
        assert "GJ = " in text
        head, tail = text.split("GJ = ", 1)
        gj, rest = tail.split("\n", 1)
        (tmp / "w.toml").write_text(f"{head}GJ = {gj}\n{line}\n{rest}")
        return ["flutter", str(tmp / "w.toml")]

    return make


# -- the corpus: (id, case, exit code, what the one line must name) -------------------------

LOOP = "def command(t, y):\n    while True:\n        pass\n"
CASES = [
    # C. Python laws: at import
    ("py_exit0_at_import", law_case("import sys\nsys.exit(0)\n"), 2,
     ["ctrl.toml", "file = 'law.py'", "sys.exit(0)", "at import"]),
    ("py_exit_text_at_import", law_case("raise SystemExit('bye\\nnow')\n"), 2,
     ["ctrl.toml", "file = 'law.py'", "sys.exit('bye\\nnow')"]),
    ("py_argparse_at_import", law_case(
        "import argparse\np = argparse.ArgumentParser(prog='aeroservo')\np.add_argument('x')\n"
        "p.add_argument('y')\np.add_argument('z')\np.add_argument('w')\np.parse_args()\n"
        "def command(t, y):\n    return [0.0]\n"), 2,
     ["ctrl.toml", "file = 'law.py'", "sys.exit(2)", "usage: aeroservo"]),
    ("py_exception_at_import", law_case("raise RuntimeError('first\\nsecond\\nthird')\n"), 2,
     ["ctrl.toml", "file = 'law.py'", "RuntimeError: first"]),
    ("py_syntax_error", law_case("def command(t, y)\n    return [0.0]\n"), 2,
     ["ctrl.toml", "file = 'law.py'", "SyntaxError"]),
    ("py_endless_import", law_case("while True:\n    pass\n",
                                   extra="import_budget_s = 0.3\n"), 2,
     ["ctrl.toml", "file = 'law.py'", "import_budget_s", "0.3 s"]),
    ("py_txt_file", law_case("def command(t, y):\n    return [0.0]\n", file="law.txt"), 2,
     ["ctrl.toml", "file = 'law.txt'", ".py"]),
    ("py_no_function", law_case("command = 3\n"), 2,
     ["ctrl.toml", "function = 'command'", "law.py"]),
    ("py_budget_zero", law_case("def command(t, y):\n    return [0.0]\n",
                                extra="budget_s = 0\n"), 2, ["ctrl.toml", "budget_s = 0"]),
    ("py_budget_huge", law_case("def command(t, y):\n    return [0.0]\n",
                                extra="budget_s = 1e9\n"), 2, ["ctrl.toml", "budget_s = 1000000000.0"]),
    ("py_budget_text", law_case("def command(t, y):\n    return [0.0]\n",
                                extra='budget_s = "1"\n'), 2, ["ctrl.toml", "budget_s = '1'"]),
    # C. Python laws: while marching
    ("py_exit3_in_law", law_case("import sys\ndef command(t, y):\n    sys.exit(3)\n"), 2,
     ["law.py:command", "t = 0 s", "sys.exit(3)"]),
    ("py_exit_later", law_case(
        "import sys\ndef command(t, y):\n    if t > 0.0095:\n        sys.exit('stop')\n"
        "    return [0.0]\n"), 2, ["law.py:command", "t = 0.01 s", "sys.exit('stop')"]),
    ("py_returns_1e300", law_case("def command(t, y):\n    return [1e300]\n"), 2,
     ["law.py:command", "t = 0 s", "[1e+300]", "at most 1e+12"]),
    ("py_returns_nan", law_case("def command(t, y):\n    return [float('nan')]\n"), 2,
     ["law.py:command", "t = 0 s", "[nan]"]),
    ("py_returns_inf_later", law_case(
        "def command(t, y):\n    return [float('-inf') if t > 0.05 else 0.0]\n"), 2,
     ["law.py:command", "[-inf]"]),
    ("py_returns_two", law_case("def command(t, y):\n    return [0.0, 0.0]\n"), 2,
     ["law.py:command", "[0.0, 0.0]", "1 finite commands"]),
    ("py_returns_text", law_case("def command(t, y):\n    return 'up'\n"), 2,
     ["law.py:command", "'up'"]),
    ("py_multiline_exception", law_case(
        "def command(t, y):\n    raise ValueError('line one\\nline two\\nline three')\n"), 2,
     ["law.py:command", "t = 0 s", "ValueError: line one"]),
    ("py_endless_loop", law_case(LOOP), 2,
     ["law.py:command", "t = 0 s", "budget of 0.2 s", "budget_s"]),
    ("py_sleep_swallowed", law_case(
        "import time\ndef command(t, y):\n    try:\n        time.sleep(600)\n"
        "    except Exception:\n        pass\n    return [0.0]\n"), 2,
     ["law.py:command", "budget of 0.2 s"]),
    ("py_loop_catching_twice", law_case(
        "def command(t, y):\n    for _ in range(2):\n        try:\n            while True:\n"
        "                t += 0\n        except BaseException:\n            pass\n"
        "    while True:\n        t += 0\n"), 2, ["law.py:command", "budget of 0.2 s"]),
    ("py_raises_in_lco_study", law_study_case("lco"), 2,
     ["law.py:command", "t = 0.051 s", "KeyError: 'boom'"]),
    ("py_raises_in_gust_loads", law_study_case("loads"), 2,
     ["law.py:command", "t = 0.051 s", "KeyError: 'boom'"]),
    # D. gain files, derived speeds, sections, limit-cycle and gust-loads scenarios
    ("gain_unknown_states", lqr_case({}, controller=(
        'type = "gain"\nsign = -1\n[gain]\ncontrols = ["aileron_hinge_moment"]\n'
        'states = ["w_3", "no_such_state"]\nmatrix = [[1.0, 2.0]]\n')), 2,
     ["ctrl.toml", "gain.states", "no_such_state"]),
    ("speed_factor_beyond", lqr_case({"speed_factor = 1.1 ": "speed_factor = 7.5 "}), 2,
     ["s.toml", "flight.speed_factor = 7.5", "beyond the airspeed range"]),
    ("engaged_factors_beyond", lqr_case(
        {"engaged_speed_factors = [0.95, 1.1]": "engaged_speed_factors = [0.95, 9.0]"}), 2,
     ["s.toml", "controller.engaged_speed_factors = [0.95, 9.0]", "flutter_margin"]),
    ("engaged_speeds_beyond", lqr_case(
        {"engaged_speed_factors = [0.95, 1.1]": "engaged_speeds = [100.0, 950.0]"}), 2,
     ["s.toml", "controller.engaged_speeds = [100.0, 950.0]", "flutter_margin"]),
    ("design_speed_beyond", lqr_case(
        {"engaged_speed_factors = [0.95, 1.1]": "", "speed_factor = 1.1 ": "speed = 950.0 "}), 2,
     ["s.toml", "flight.speed = 950.0", "flutter_margin"]),
    ("v_max_factor_beyond", lqr_case(
        {"closed_loop_boundary = true": "closed_loop_boundary = true",  # kept on
         "v_max_factor = 2.0": "v_max_factor = 9.0", "duration = 3.0": "duration = 0.1"}), 2,
     ["s.toml", "analysis.v_max_factor = 9.0"]),
    ("schedule_beyond", lqr_case({}, controller=(CONTROLLERS / "lqr_scheduled.toml").read_text()
                                 .replace("speed_factors = [", "speed_factors = [0.5, 8.0] # [")),
     2, ["ctrl.toml", "schedule.speed_factors = [0.5, 8.0]"]),
    *[(f"section_{key}_1e300", lco_case(key, "1e300"), 2, ["s.toml", f"section.{key} = 1e+300"])
      for key in ("semichord", "mass", "inertia", "k_plunge", "k_pitch", "flap_static_moment",
                  "flap_inertia", "k_flap", "x_alpha", "a", "hinge")],
    ("section_inertia_negative", lco_case("inertia", "-1.0"), 2, ["s.toml", "section.inertia"]),
    ("lco_study_too_long", lco_case(speeds="{ start = 1.0, stop = 100.0, num = 1000 }",
                                    amplitudes=str([0.01 * (i + 1) for i in range(10)]),
                                    duration="500.0", dt="0.0001"), 2,
     ["s.toml", "lco.duration = 500", "6e+10 steps in all", "1e+09"]),
    ("gust_vd_below_vc_named", gust_case([(0.0, 100.0, "V_C"), (0.0, 90.0, "V_D")], flight=""),
     2, ["s.toml", "gust_loads.points[1].speed = 90", "V_D is not below V_C"]),
    ("gust_vd_below_v_c", gust_case([(0.0, 80.0, "V_D")], "v_c = 100.0", flight=""), 2,
     ["s.toml", "gust_loads.points[0].speed = 80", "v_c = 100"]),
    ("gust_vc_above_v_d", gust_case([(0.0, 130.0, "V_C")], "v_d = 125.0", flight=""), 2,
     ["s.toml", "gust_loads.points[0].speed = 130", "v_d = 125"]),
    ("gust_design_speed_beyond", gust_case([(0.0, 100.0, "V_C")], flight="speed_factor = 8.0"),
     2, ["s.toml", "flight.speed_factor = 8.0", "beyond the airspeed range"]),
    # F. wing files
    ("wing_sweep_1e308", wing_case("sweep = 1e308"), 2, ["w.toml", "sweep = 1e+308 rad"]),
    ("wing_sweep_minus_1e308", wing_case("sweep = -1e308"), 2, ["w.toml", "sweep = -1e+308"]),
    ("wing_sweep_deg_1e308", wing_case("sweep_deg = 1e308"), 2, ["w.toml", "sweep_deg = 1e+308"]),
    ("wing_sweep_nan", wing_case("sweep = nan"), 2, ["w.toml", "sweep = nan"]),
    ("wing_sweep_inf", wing_case("sweep = inf"), 2, ["w.toml", "sweep = inf"]),
]  # fmt: skip


@pytest.mark.parametrize("make, code, names", [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_hostile_case_is_one_line(tmp_path, make, code, names):
    argv = make(tmp_path)
    before = snapshot(tmp_path)
    handler = signal.getsignal(signal.SIGALRM)
    out_dir = tmp_path / "out"
    t0 = time.perf_counter()
    rc, out, err = run_cli([*argv, "--out", str(out_dir)] if argv[0] != "flutter" else argv)
    elapsed = time.perf_counter() - t0
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert rc != 130, f"interrupted by the watchdog after {elapsed:.1f} s: {err}"
    assert rc == code, (rc, err, out[-500:])
    assert len(lines) == 1, err
    assert lines[0].startswith("aeroservo: "), lines[0]
    assert "Traceback" not in out + err
    for name in names:
        assert name in lines[0], (name, lines[0])
    assert not out_dir.exists() or not any(out_dir.iterdir()), list(out_dir.iterdir())
    assert snapshot(tmp_path) == before  # nothing changed, nothing added (no __pycache__)
    assert signal.getsignal(signal.SIGALRM) is handler  # a law's timer leaves nothing behind
    assert signal.getitimer(signal.ITIMER_REAL) == (0.0, 0.0)


def test_the_shipped_python_law_runs_within_its_budget(tmp_path):
    """The shipped law (``controllers/python.toml``, ``budget_s = 1``) still passes; its file
    gets no ``__pycache__``; a law that prints while loaded gets one warning line."""
    (tmp_path / "python_law.py").write_text((CONTROLLERS / "python_law.py").read_text())
    s = simulate_files(tmp_path, (CONTROLLERS / "python.toml").read_text())
    rc, out, err = run_cli(["simulate", str(s), "--out", str(tmp_path / "out"), "--no-plots"])
    assert rc == 0, err
    assert "verdict stable, passed" in out
    assert not (tmp_path / "__pycache__").exists()
    law = "print('loading my law')\ndef command(t, y):\n    return [0.0]\n"
    (tmp_path / "printing").mkdir()
    argv = law_case(law)(tmp_path / "printing")
    rc, out, err = run_cli([*argv, "--out", str(tmp_path / "out2"), "--no-plots"])
    warnings = [ln for ln in err.splitlines() if "warning" in ln]
    assert len(warnings) == 1 and "'loading my law'" in warnings[0], err
    assert "loading my law" not in out


def test_budget_through_the_api_restores_the_alarm_handler():
    """``python_law(..., budget=)``: an endless loop is stopped on the main thread (the
    previous SIGALRM handler restored, no timer left), and in another thread (no timer there)
    a call over its budget fails once it returns."""
    from aeroservo.design import python_law
    from aeroservo.design.user_code import LawError, call_within

    def endless(t, y):
        while True:
            pass

    before = signal.getsignal(signal.SIGALRM)
    law = python_law(endless, ["u"], ["y"], sample_rate=100.0, budget=0.1, name="endless")
    with watchdog(20.0), pytest.raises(LawError, match=r"endless: at t = 0 s: ran over its bud"):
        law.command(np.zeros(1))
    assert signal.getsignal(signal.SIGALRM) is before
    assert signal.getitimer(signal.ITIMER_REAL) == (0.0, 0.0)
    assert call_within(0.5, lambda: 42) == 42

    slow = python_law(
        lambda t, y: time.sleep(0.3) or [0.0], ["u"], ["y"], sample_rate=100.0, budget=0.1
    )
    caught: list = []

    def in_thread():
        try:
            slow.command(np.zeros(1))
        except LawError as exc:
            caught.append(str(exc))

    worker = threading.Thread(target=in_thread)
    worker.start()
    worker.join(10.0)
    assert caught and "ran over its budget of 0.1 s" in caught[0], caught
    with pytest.raises(Exception, match="budget = 0"):
        python_law(endless, ["u"], ["y"], sample_rate=100.0, budget=0.0)


def test_study_of_too_many_steps_is_refused_through_the_api():
    """``LCOSweep.steps`` (checked by ``run_lco``) bounds the steps of a whole study."""
    from aeroservo.errors import InputError
    from aeroservo.studies.lco.study import MAX_STUDY_STEPS, LCOSweep

    sweep = LCOSweep(speeds=tuple(np.linspace(1.0, 100.0, 1000)), amplitudes=(0.1,) * 1,
                     duration=500.0, dt=1e-4)  # fmt: skip
    with pytest.raises(InputError, match=r"steps in all, above the limit of 1e\+09"):
        sweep.steps(1e-4)
    assert LCOSweep(speeds=(10.0,), amplitudes=(0.1,), duration=3.0).steps(1e-3) == 9000
    assert MAX_STUDY_STEPS == 10**9
