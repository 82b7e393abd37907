"""Gust-loads studies (CS-25.341) over flight points, mass cases, with and without the loop.

Independent checks in this file:

* the rule's linearity: open loop, a V_D point (gust velocities halved, CS-25.341(a)(5)(i) and
  (b)(3)) has exactly half the loads of the same point flown as V_C;
* F_g per altitude from CS-25.341(a)(6) transcribed here; TAS from EAS by the ISA density;
* a state-feedback gain carried to another altitude: the closed-loop eigenvalues against the
  gain applied by hand in physical (unbalanced) coordinates, ``u = -G diag(1/s_ref) x_phys``;
* the gust-load-alleviation percentages against the loads of separate open- and closed-loop
  searches on the same plant, and the ``raised`` flag against their ratio;
* Dask (2 workers) against the serial run.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import ROOT

import aeroservo as aes
from aeroservo.aero.atmosphere import isa
from aeroservo.design.closed_loop import closed_loop_matrix
from aeroservo.design.interface import static_gain
from aeroservo.design.law import pad_state_map
from aeroservo.errors import InputError
from aeroservo.files.scenario_file import load_scenario
from aeroservo.studies.gust.point import design_point, evaluate_point, in_state_basis
from aeroservo.studies.gust.results import RAISE_TOLERANCE
from aeroservo.studies.gust.run import run_gust_loads
from aeroservo.studies.gust.study import FlightPoint, GustLoadsStudy
from aeroservo.studies.gust.tuned import tuned_gust_loads

LOADS = ("root_shear", "root_bending_moment", "root_torque", "tip_twist")
CONTROL = "aileron_hinge_moment"


def _study(**kw) -> GustLoadsStudy:
    base = dict(
        mass_cases={"nominal": aes.examples.goland_aileron()},
        points=(FlightPoint(0.0, 100.0, "V_C", "nominal"),),
        loads=LOADS,
        controls=(CONTROL,),
        sensors=("tip_twist",),
        controller=static_gain([[3e4]], [CONTROL], sensors=["tip_twist"], sample_rate=1000.0),
        elements=6,
        n_gradients=5,
        turbulence=False,
        sensor_filter=None,
    )
    base.update(kw)
    return GustLoadsStudy(**base)


def test_vd_halves_every_open_loop_load():
    st = _study(
        controller=None,
        controls=(),
        sensors=(),
        points=(
            FlightPoint(3000.0, 90.0, "V_C", "nominal"),
            FlightPoint(3000.0, 90.0, "V_D", "nominal"),
        ),
    )
    res = run_gust_loads(st)
    t = res.table.set_index(["point", "load"])
    for name in LOADS:
        vc, vd = t.loc[(0, name)], t.loc[(1, name)]
        assert vd["discrete_max"] == pytest.approx(0.5 * vc["discrete_max"], rel=1e-9)
        assert vd["max_gradient_m"] == pytest.approx(vc["max_gradient_m"], rel=1e-9)
    assert res.loops == ["open"]
    with pytest.raises(InputError, match="needs both loops"):
        _ = res.alleviation


def test_tas_and_f_g_follow_the_rule():
    w = {"mlw": 56000.0, "mzfw": 49000.0, "mtow": 70000.0, "z_mo": 12500.0}
    st = _study(f_g=None, weights=w, points=(FlightPoint(6000.0, 120.0, "V_C", "nominal"),))
    p = st.points[0]
    assert p.tas == pytest.approx(120.0 * math.sqrt(1.225 / isa(6000.0).density), rel=1e-9)
    ft = 0.3048
    r1, r2, z = w["mlw"] / w["mtow"], w["mzfw"] / w["mtow"], w["z_mo"] / ft
    fg0 = 0.5 * ((1 - z / 250000.0) + math.sqrt(r2 * math.tan(math.pi * r1 / 4)))
    expect = fg0 + (1 - fg0) * (6000.0 / ft) / z
    assert st.alleviation_factor(6000.0) == pytest.approx(expect, rel=1e-12)
    with pytest.raises(InputError, match="needs 'z_mo'"):
        _study(f_g=None, weights={"mlw": 1.0, "mzfw": 1.0, "mtow": 1.0})


def test_a_state_feedback_gain_is_carried_to_another_altitude_in_its_own_basis():
    sc = load_scenario(ROOT / "scenarios" / "goland_aileron_lqr.toml")
    st = _study(
        controller=sc.controller,
        sensors=(),
        outputs=("tip_disp",),
        design_speed_factor=1.1,
        points=(FlightPoint(4000.0, 100.0, "V_C", "nominal"),),
    )
    ctrl, s_ref = design_point(st)
    p = st.points[0]
    loop = st.loop("nominal", p.density)
    plant = loop.plant(p.tas)
    s_alt = loop.plant_builder.state_scaling
    assert not np.array_equal(s_alt, s_ref)  # the balancing differs with the density
    fixed = in_state_basis(plant, s_alt, s_ref)
    got = np.sort_complex(np.linalg.eigvals(closed_loop_matrix(fixed, ctrl, sampled=False)[0]))
    # by hand: physical states, x_ref = x_phys / s_ref
    A, B, _, _ = loop.plant_builder.matrices(p.tas, balanced=False)
    G = ctrl.K @ pad_state_map(ctrl.state_map, A.shape[0])
    b = B[:, list(loop.plant_builder.input_labels).index(CONTROL)][:, None]
    ref = np.sort_complex(np.linalg.eigvals(A - b @ (G / s_ref[None, :])))
    scale = np.abs(ref).max()
    assert np.abs(got - ref).max() < 1e-8 * scale
    wrong = np.sort_complex(np.linalg.eigvals(closed_loop_matrix(plant, ctrl, sampled=False)[0]))
    assert np.abs(wrong - ref).max() > 1e-3 * scale  # without the basis change it is wrong
    # the transfer functions do not change
    w = np.array([1.0, 30.0, 300.0])
    h0 = plant(1j * w[0])
    assert np.allclose(fixed(1j * w[0]), h0, rtol=1e-9, atol=1e-12 * np.abs(h0).max())


def test_alleviation_against_separate_searches():
    st = _study(points=(FlightPoint(0.0, 100.0, "V_C", "nominal"),))
    res = run_gust_loads(st)
    p = st.points[0]
    loop = st.loop("nominal", p.density)
    plant = loop.plant(p.tas)
    plant.density = p.density
    ol = tuned_gust_loads(plant, 0.0, n_gradients=5)
    assert st.delay is True  # the study's default: the loop as flown (issue 38)
    cl = tuned_gust_loads(plant, 0.0, n_gradients=5, controller=st.controller, delay=True)
    a = res.alleviation.set_index("load")
    for name in LOADS:
        o = max(abs(ol.extremes[name].maximum), abs(ol.extremes[name].minimum))
        c = max(abs(cl.extremes[name].maximum), abs(cl.extremes[name].minimum))
        assert a.loc[name, "discrete_alleviation_pct"] == pytest.approx(100 * (1 - c / o), abs=1e-9)
        assert bool(a.loc[name, "raised"]) == (c > o * (1 + RAISE_TOLERANCE))
    lines = res.raised_loads()
    assert len(lines) == int(a["raised"].sum())
    assert all("the loop raises" in x for x in lines)
    assert CONTROL in res.loads  # the actuator's hinge moment is a load of the closed loop


def test_unstable_loops_become_notes_not_loads():
    st = _study(
        controller=static_gain([[-5e6]], [CONTROL], sensors=["tip_twist"], sample_rate=1000.0),
        points=(FlightPoint(0.0, 150.0, "V_C", "nominal"),),  # above V_f = 137 m/s
    )
    pl = evaluate_point(st, st.points[0])
    assert not pl.open_loop_stable and pl.discrete == {}
    assert any("open loop unstable" in n for n in pl.notes)
    assert any("closed loop" in n and "unstable" in n for n in pl.notes)


def test_bad_studies_are_one_line():
    with pytest.raises(InputError, match="mass_case = 'heavy'"):
        _study(points=(FlightPoint(0.0, 100.0, "V_C", "heavy"),))
    with pytest.raises(InputError, match="speed_name"):
        FlightPoint(0.0, 100.0, "VC")
    with pytest.raises(InputError, match="controls"):
        _study(controls=())


@pytest.mark.slow
def test_dask_gives_the_serial_result():
    st = _study(
        points=(
            FlightPoint(0.0, 100.0, "V_C", "nominal"),
            FlightPoint(3000.0, 100.0, "V_C", "nominal"),
            FlightPoint(0.0, 110.0, "V_D", "nominal"),
        )
    )
    serial = run_gust_loads(st)
    dask = run_gust_loads(st, workers=2)
    cols = ["discrete_max", "discrete_min", "max_gradient_m", "limit"]
    a, b = serial.table[cols].to_numpy(), dask.table[cols].to_numpy()
    assert np.array_equal(a, b)


def test_a_point_without_any_loop_is_kept_with_its_reasons():
    st = _study(
        controller=static_gain([[-5e6]], [CONTROL], sensors=["tip_twist"], sample_rate=1000.0),
        points=(
            FlightPoint(0.0, 100.0, "V_C", "nominal"),
            FlightPoint(0.0, 150.0, "V_C", "nominal"),  # both loops unstable
        ),
    )
    res = run_gust_loads(st)
    assert {r["point"] for r in res.records} == {0}  # the closed loop is unstable at 100 too
    [sk] = res.settings["skipped_points"]
    assert sk["point"] == 1 and any("open loop unstable" in n for n in sk["notes"])
    text = res.summary()
    assert "NO LOADS at point 1" in text
    assert text.count("closed loop at 100 m/s TAS is unstable") == 1  # one note per point


def test_a_state_feedback_object_acts_in_the_design_points_basis():
    """The designed LQR given as an object gives the loads of its spec at another altitude."""
    sc = load_scenario(ROOT / "scenarios" / "goland_aileron_lqr.toml")
    kw = dict(
        sensors=(),
        outputs=("tip_disp",),
        design_speed_factor=1.1,
        points=(FlightPoint(6000.0, 90.0, "V_C", "nominal"),),
        n_gradients=4,
    )
    spec = _study(controller=sc.controller, **kw)
    ctrl, _ = design_point(spec)
    obj = _study(controller=ctrl, limits=sc.controller.limits, **kw)
    a, b = run_gust_loads(spec).table, run_gust_loads(obj).table
    assert np.allclose(a["discrete_max"], b["discrete_max"], rtol=1e-9)


def test_swept_wing_under_strip_gusts_says_the_spanwise_delay_is_missing():
    """Issue 38: the strip model's gust reaches every strip at once; on a swept wing the
    report says the spanwise delay is left out (and a straight wing's report does not)."""
    swept = aes.examples.goland_swept(np.deg2rad(30.0))
    res = run_gust_loads(
        _study(
            controller=None,
            controls=(),
            sensors=(),
            mass_cases={"nominal": aes.examples.goland_aileron(), "swept": swept},
            points=(
                FlightPoint(0.0, 100.0, "V_C", "nominal"),
                FlightPoint(0.0, 100.0, "V_C", "swept"),
            ),
        )
    )
    (w,) = res.settings["warnings"]
    assert w.startswith("mass case swept: a swept wing") and "spanwise delay" in w
    assert f"WARNING: {w}" in res.summary()
    straight = run_gust_loads(_study(controller=None, controls=(), sensors=()))
    assert straight.settings["warnings"] == []


def test_the_command_applied_has_its_turbulence_a_bar():
    """Issue 38: the actuator's hinge moment gets an A-bar like every load. With the static gain
    u = -K tip_twist, the command at each sample is K times the sampled twist: its A-bar must be
    K times the twist's (the same stationary process), which checks that the command row is the
    command applied."""
    st = _study(turbulence=True)
    pl = evaluate_point(st, st.points[0])
    ab = pl.turbulence["closed"].a_bar
    assert ab[CONTROL] == pytest.approx(3e4 * ab["tip_twist"], rel=1e-9)
    assert "open" not in pl.turbulence or CONTROL not in pl.turbulence["open"].a_bar
    rec = run_gust_loads(st).record(0, "closed")["loads"][CONTROL]
    assert rec["turbulence"] == pytest.approx(pl.u_sigma * ab[CONTROL], rel=1e-12)


def test_u_sigma_is_interpolated_between_vc_and_vd():
    """CS-25.341(b)(3)(ii)-(iii): U_sigma halves at V_D and is linear between V_C and V_D
    (90 ft/s x F_g at sea level at V_C). The discrete gusts between are those of V_C."""
    pts = (
        FlightPoint(0.0, 100.0, "V_C", "nominal"),
        FlightPoint(0.0, 112.5, "", "nominal"),
        FlightPoint(0.0, 125.0, "V_D", "nominal"),
    )
    st = _study(
        controller=None, controls=(), sensors=(), points=pts, v_c=100.0, v_d=125.0, turbulence=False
    )  # U_sigma is the point's whether or not the turbulence is computed
    done = [evaluate_point(st, p) for p in pts]
    ft = 0.3048
    u = [d.u_sigma for d in done]
    assert u == pytest.approx([90 * ft, 0.75 * 90 * ft, 0.5 * 90 * ft], rel=1e-12)
    vc, mid = done[0], done[1]
    assert any("U_sigma x 0.75" in n for n in mid.notes)
    tas = pts[1].tas / pts[0].tas  # same gust velocities (V_C), the wing faster
    assert mid.discrete["open"].amplitudes == pytest.approx(vc.discrete["open"].amplitudes)
    assert tas > 1
    with pytest.raises(InputError, match="v_d = 90 m/s EAS: must exceed v_c = 100"):
        _study(controller=None, controls=(), sensors=(), v_c=100.0, v_d=90.0)
    with pytest.raises(InputError, match="V_C = 110 m/s EAS"):
        _study(controller=None, controls=(), sensors=(), v_c=110.0, v_d=130.0)
    with pytest.raises(InputError, match="beyond v_d"):
        _study(
            controller=None,
            controls=(),
            sensors=(),
            v_c=90.0,
            v_d=100.0,
            points=(FlightPoint(0.0, 120.0, "", "nominal"),),
        )
