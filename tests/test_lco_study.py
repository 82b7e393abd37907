"""Limit-cycle studies of the freeplay section of Conner, Tang, Dowell & Virgin (1997), J. Fluids
Struct. 11, 89-109 (shared/reference README, case "Freeplay section"; undamped, rho = 1.225,
R. T. Jones lag states): the marches against the describing function, and the scaling in gap.

* Where a march settles in a limit cycle, the describing-function branch through that speed has
  its amplitude and frequency. The DF keeps the first harmonic only and ignores how the harmonics
  feed back on it; the march's half peak-to-peak is 2-5 % above its first harmonic (least squares
  at the limit cycle's frequency, computed here). The DF amplitude must lie within 2 % of the
  first harmonic (measured 0.5-1.5 %: the harmonics' feedback it neglects is second order in
  them) and within 5 % of the half peak-to-peak (the harmonic content itself, 4-5 %); the
  frequency within 1 % (measured 0.3 %).
* Onset: the marches (from rest, and from the 10 m/s limit cycle carried down) settle in no limit
  cycle below 9 m/s, while the describing function keeps a stable branch down to about 2.5 m/s:
  near the gap edge the motion is far from sinusoidal and the DF predicts limit cycles the
  equations do not have. The test pins this, so that it stays documented (docs/freeplay.md).
* The equations are homogeneous in the gap: a study with twice the gap and twice the initial
  rotations gives the same amplitudes per gap and frequencies to rounding.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from aeroservo.structure.hinge_laws import Freeplay
from aeroservo.studies.lco.result import _branch_at
from aeroservo.studies.lco.run import run_lco
from aeroservo.studies.lco.study import LCOSetup, LCOSweep
from aeroservo.system.hinge_elements import NonlinearHinge
from aeroservo.system.section import CONNER, conner_section

ROOT = Path(__file__).resolve().parent.parent

GAP = CONNER["gap"]
U_F = 23.73  # m/s, gap closed, R. T. Jones (reference README)


def _study(gap: float, speeds, amplitudes, duration=20.0, continuation=False, describing=True):
    setup = LCOSetup(conner_section(), [NonlinearHinge("flap", Freeplay(gap))], 1.225)
    sweep = LCOSweep(speeds, amplitudes, duration=duration, continuation=continuation, history=5.0)
    return run_lco(setup, sweep, describing=describing)


@pytest.fixture(scope="module")
def study():
    return _study(GAP, [6.0, 8.0, 10.0, 14.0, 18.0, 22.0], [2.0 * GAP])


def _first_harmonic(row, gap: float) -> float:
    h = row["history"]
    t, y = np.asarray(h["t"]), np.asarray(h["flap_rotation"])
    w = 2.0 * np.pi * row["frequency"]
    basis = np.column_stack([np.ones_like(t), np.sin(w * t), np.cos(w * t)])
    c = np.linalg.lstsq(basis, y, rcond=None)[0]
    return float(np.hypot(c[1], c[2]))


@pytest.mark.slow
def test_describing_function_agrees_with_the_marches_where_they_settle(study):
    b = study.branches
    seen = b.stable & b.others_stable
    lco = study.lco_rows()
    assert [r["speed"] for r in lco] == [10.0, 14.0, 18.0, 22.0]
    table = []
    for r in lco:
        hit = _branch_at(b, seen, r["speed"], r["frequency"])
        assert hit is not None, r["speed"]
        a_df, f_df = hit
        a1 = _first_harmonic(r, GAP)
        table.append((r["speed"] / U_F, r["rms_per_gap"], r["amplitude_per_gap"], a1 / GAP,
                      a_df / GAP, r["frequency"], f_df))  # fmt: skip
    for row in table:  # U/U_F, RMS/gap, peak/gap, first harmonic/gap, DF/gap, f, f DF
        u, rms, peak, a1, a_df, f, f_df = row
        print(f"U/U_F {u:.2f}  rms/gap {rms:.3f}  peak/gap {peak:.3f}  H1/gap {a1:.3f}  "
              f"DF/gap {a_df:.3f}  {f:.2f} Hz (DF {f_df:.2f})")  # fmt: skip
    for _, _, peak, a1, a_df, f, f_df in table:
        # the harmonics: the half peak-to-peak is a few % above the first harmonic, and the DF
        # (first harmonic, no interaction of harmonics) lies within that spread
        assert 0.0 < peak / a1 - 1.0 < 0.06
        assert abs(a_df / a1 - 1.0) < 0.02
        assert abs(a_df / peak - 1.0) < 0.05
        assert abs(f_df / f - 1.0) < 0.01


@pytest.mark.slow
def test_describing_function_predicts_limit_cycles_below_the_marches_onset(study):
    b = study.branches
    seen = b.stable & b.others_stable & (b.frequency > 10.0)
    assert b.speed[seen].min() < 4.0  # the DF's 11-12 Hz branch reaches down to low speed
    rows = {r["speed"]: r for r in study.rows}
    assert rows[6.0]["kind"] == "decay"
    assert rows[8.0]["kind"] != "lco"
    assert study.onset(("lco",)) == 10.0  # periodic limit cycles


def test_amplitude_per_gap_does_not_depend_on_the_gap():
    a = _study(GAP, [12.0], [2.0 * GAP], duration=10.0, describing=False)
    b = _study(2.0 * GAP, [12.0], [4.0 * GAP], duration=10.0, describing=False)
    (ra,), (rb,) = a.rows, b.rows
    assert ra["kind"] == rb["kind"] == "lco"
    assert rb["amplitude_per_gap"] == pytest.approx(ra["amplitude_per_gap"], rel=1e-9)
    assert rb["rms_per_gap"] == pytest.approx(ra["rms_per_gap"], rel=1e-9)
    assert rb["frequency"] == pytest.approx(ra["frequency"], rel=1e-9)


def test_continuation_sweeps_and_the_summary():
    res = _study(GAP, [6.0, 10.0, 26.0], [0.5 * GAP, 2.0 * GAP], duration=10.0, continuation=True,
                 describing=False)  # fmt: skip
    up = [r for r in res.rows if r["start"] == "up"]
    down = [r for r in res.rows if r["start"] == "down"]
    assert [r["speed"] for r in up] == [6.0, 10.0, 26.0]
    assert [r["speed"] for r in down] == [26.0, 10.0, 6.0]
    assert up[0]["initial"] == 0.5 * GAP and down[0]["initial"] == 2.0 * GAP
    assert up[-1]["kind"] == "divergence"  # above the gap-closed flutter speed
    # the down sweep restarts from rest after the diverged march: its 10 m/s march equals the
    # march from rest with the largest rotation
    point = next(r for r in res.rows if r["start"] == "point" and r["speed"] == 10.0
                 and r["initial"] == 2.0 * GAP)  # fmt: skip
    assert down[1]["amplitude"] == pytest.approx(point["amplitude"], rel=1e-12)
    text = res.summary()
    # issue 40: slowing down from the 10 m/s limit cycle, the section stays in a sustained
    # 4.7 Hz oscillation at 6 m/s (where every march from rest decays): quasi-periodic, counted
    # in the onset and named in the summary
    assert down[-1]["kind"] == "quasi-periodic", down[-1]["reason"]
    assert res.onset() == 6.0 and res.onset(("lco",)) == 10.0
    assert "sustained oscillations from 6 to 10 m/s" in text
    assert "\n  periodic at 10 m/s: amplitude 0.896 to 0.91 x gap" in text
    assert "\n  quasi-periodic at 6 m/s: amplitude 0.658 x gap, RMS 0.382 x gap, 4.75 Hz" in text
    assert "divergent motion from 26 m/s" in text


def test_a_surface_resting_at_a_gap_edge_is_said_with_its_offset(tmp_path):
    """Issue 40 item 4: a march that decays against an edge of the gap (here a preloaded
    freeplay, centre 0.05 rad > half the 0.074 rad gap, so the spring holds the flap at the
    lower edge) is not a plain decay: its reason says 'rest at the lower edge' and the offset
    from the gap's centre, -0.5 x gap (the spring slightly compressed)."""
    from dataclasses import replace

    from aeroservo.files.scenario_file import load_scenario
    from aeroservo.studies.kinds import run_scenario

    src = ROOT / "scenarios" / "conner_freeplay_lco.toml"
    text = src.read_text().replace("offset = 0.0 ", "offset = 0.05")
    (tmp_path / "edge.toml").write_text(text)
    sc = load_scenario(tmp_path / "edge.toml")
    opts = replace(
        sc.lco, speeds=(15.0,), amplitudes=(0.0185,), duration=2.0, history=0.5,
        continuation=False, describing=False,
    )  # fmt: skip
    (row,) = run_scenario(replace(sc, options=opts)).lco.rows
    assert row["kind"] == "decay"
    m = re.search(
        r"rest at the lower edge of the gap: offset (\S+) rad \((\S+) x gap\)", row["reason"]
    )
    assert m, row["reason"]
    assert float(m.group(2)) == pytest.approx(-0.5, abs=0.03)
    assert float(m.group(1)) == pytest.approx(row["mean"] - 0.05, rel=1e-3)
