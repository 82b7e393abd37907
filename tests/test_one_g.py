"""1 g loads (issue 38, item 6): the wing's weight (``load_factor`` input) and its static
aeroelastic trim to carry its share of the airplane's weight.

References written here (steady strip theory, CS-25.321 / 25.341: gust loads are increments on
the 1 g level-flight loads):

* the weight alone on a stiff wing (no aerodynamic relief): shear ``-g m (l - x)``, bending
  ``-g m (l - x)^2 / 2``, torque ``+g m x_alpha b (l - x)`` (the weight acts at the CG, aft of
  the elastic axis: nose-up);
* a stiff wing trimmed to lift L: uniform lift ``L / l`` at the quarter chord against the
  weight: shear ``(L / l - g m)(l - x)``, and so on;
* the flexible wing: lift ``2 pi rho V^2 b (alpha + phi(y))`` with the wing's own twist (its
  twist sensors) and the weight, integrated outboard of every node, exact for the element's
  linear twist; the aerodynamic lift (root shear + weight) equals L.
"""

from __future__ import annotations

import control
import numpy as np
import pytest

import aeroservo as aes
from aeroservo.linear.signals import station_output
from aeroservo.studies.gust.one_g import one_g_loads, wing_weight
from aeroservo.studies.gust.run import run_gust_loads
from aeroservo.studies.gust.study import FlightPoint, GustLoadsStudy

G = 9.80665
Q = ("shear", "bending_moment", "torque")


def _stiff():
    return aes.examples.goland(GJ=0.99e6 * 1e4, EI=9.77e6 * 1e4)


def _station_loads(model):
    return [station_output(q, x) for x in model.mesh.nodes for q in Q]


def test_weight_of_a_stiff_wing_is_the_closed_form():
    wing = _stiff()
    model = aes.AeroelasticModel(wing, 10, load_stations=[2.0])
    seg, span = wing.segments[0], wing.span
    outs = _station_loads(model)
    sys = aes.statespace(model, 100.0, 1.225, inputs=["load_factor"], outputs=outs)
    got = np.asarray(control.dcgain(sys)).ravel()
    assert wing_weight(model) == pytest.approx(G * seg.mass * span, rel=1e-12)
    for j, x in enumerate(model.mesh.nodes):
        arm = span - x
        ref = [
            -G * seg.mass * arm,
            -G * seg.mass * arm**2 / 2,
            G * seg.mass * seg.x_alpha * seg.semichord * arm,
        ]
        # the 1e4-times-stiffer wing still twists under its weight: 2e-5 of aerodynamic relief
        np.testing.assert_allclose(got[3 * j : 3 * j + 3], ref, rtol=1e-4, atol=1e-4 * G * 218)


def test_stiff_wing_trimmed_to_its_lift_is_the_closed_form():
    wing = _stiff()
    model = aes.AeroelasticModel(wing, 10)
    seg, span = wing.segments[0], wing.span
    rho, v, lift = 1.225, 120.0, 4.0e4
    loads = _station_loads(model)
    got, trim = one_g_loads(model, rho, v, loads, lift)
    alpha = (lift) / (2 * np.pi * rho * v**2 * seg.semichord * span)
    assert trim["alpha_rad"] == pytest.approx(alpha, rel=1e-4)
    assert trim["weight_N"] == pytest.approx(G * seg.mass * span, rel=1e-12)
    per_span = lift / span - G * seg.mass
    for x in model.mesh.nodes:
        arm = span - x
        ref = {
            "shear": per_span * arm,
            "bending_moment": per_span * arm**2 / 2,
            "torque": (
                (0.5 + seg.a) * seg.semichord * lift / span
                + G * seg.mass * seg.x_alpha * seg.semichord
            )
            * arm,
        }
        for q in Q:
            assert got[station_output(q, x)] == pytest.approx(
                ref[q], rel=1e-4, abs=1e-6 * lift * span
            ), (q, x)


@pytest.mark.parametrize("store", [False, True], ids=["clean", "store"])
def test_flexible_wing_trim_equals_the_integrated_strip_loads(store):
    base = aes.examples.goland()
    masses = (
        [aes.ConcentratedMass(station=4.5, mass=40.0, offset=-0.2, inertia=2.0, name="store")]
        if store
        else []
    )
    wing = aes.Wing(base.span, base.segments, masses=masses)
    model = aes.AeroelasticModel(wing, 10, load_stations=[4.5] if store else [])
    seg, span = wing.segments[0], wing.span
    b, a, m, xa = seg.semichord, seg.a, seg.mass, seg.x_alpha
    rho, v, lift = 1.225, 110.0, 3.0e4
    nodes = model.mesh.nodes
    xg, wg = np.polynomial.legendre.leggauss(2)
    ys = np.concatenate(
        [lo + 0.5 * (xg + 1) * (hi - lo) for lo, hi in zip(nodes[:-1], nodes[1:], strict=True)]
    )
    ws = np.concatenate(
        [0.5 * wg * (hi - lo) for lo, hi in zip(nodes[:-1], nodes[1:], strict=True)]
    )
    twist = [aes.Sensor(f"phi{i}", "twist", float(y)) for i, y in enumerate(ys)]
    store_twist = [aes.Sensor("phi_store", "twist", 4.5)]
    loads = _station_loads(model)
    got, trim = one_g_loads(model, rho, v, loads + twist + store_twist, lift)
    phi = np.array([got[s] for s in twist])
    assert np.abs(phi).max() > 1e-4  # the wing twists under lift and weight
    alpha = trim["alpha_rad"]
    lift_y = 2 * np.pi * rho * v**2 * b * (alpha + phi)
    # the aerodynamic lift is the trim's: root shear plus the weight
    weight = G * (m * span + sum(pm.mass for pm in masses))
    assert trim["weight_N"] == pytest.approx(weight, rel=1e-12)
    assert float(np.sum(lift_y * ws)) == pytest.approx(lift, rel=1e-9)
    assert got["shear_at_0mm"] + weight == pytest.approx(lift, rel=1e-9)
    for x in nodes:
        out = ys > x
        f = (lift_y - G * m) * ws
        t = ((0.5 + a) * b * lift_y + G * m * xa * b) * ws
        ref = np.array([f[out].sum(), (f * (ys - x))[out].sum(), t[out].sum()])
        for pm in masses:
            # the store's weight at its CG, ahead of the axis; a mass on the wing box exactly
            # at a station is outboard of it (the element it lies on starts there)
            if pm.station >= x - 1e-12 and x < span:
                wgt = G * pm.mass
                ref += [-wgt, -wgt * (pm.station - x), wgt * pm.offset]
        have = np.array([got[station_output(q, x)] for q in Q])
        np.testing.assert_allclose(
            have, ref, rtol=1e-9, atol=1e-9 * lift * span, err_msg=f"station {x:g} m"
        )


def test_study_adds_the_1g_loads_to_the_increments():
    study = GustLoadsStudy(
        mass_cases={"nominal": aes.examples.goland()},
        points=(FlightPoint(0.0, 100.0, "V_C", "nominal"),),
        loads=("root_shear", "root_bending_moment", "tip_le_accel"),
        aircraft_mass={"nominal": 7000.0},
        n_gradients=5,
    )
    res = run_gust_loads(study)
    t = res.table.set_index("load")
    lift = 0.5 * 7000.0 * G
    rec = res.record(0, "open")
    assert rec["trim"]["lift_N"] == pytest.approx(lift, rel=1e-12)
    assert t.loc["root_shear", "one_g"] == pytest.approx(lift - rec["trim"]["weight_N"], rel=1e-9)
    for n in ("root_shear", "root_bending_moment"):
        row = t.loc[n]
        up = max(row["discrete_max"], row["turbulence"])
        down = min(row["discrete_min"], -row["turbulence"])
        assert row["total_max"] == pytest.approx(row["one_g"] + up, rel=1e-12)
        assert row["total_min"] == pytest.approx(row["one_g"] + down, rel=1e-12)
    assert t.loc["tip_le_accel", "one_g"] == 0.0  # steady flight: no acceleration
    with pytest.raises(aes.InputError, match="aircraft_mass: 'heavy' is not a mass case"):
        GustLoadsStudy(
            mass_cases={"nominal": aes.examples.goland()},
            points=study.points,
            loads=("root_shear",),
            aircraft_mass={"heavy": 1.0},
        )


def test_no_trim_beyond_divergence():
    model = aes.AeroelasticModel(aes.examples.goland(), 10)
    with (
        pytest.raises(aes.InputError, match="lift effectiveness"),
        pytest.warns(UserWarning, match="Mach 0.779"),  # the model's own advice, kept
    ):
        one_g_loads(model, 1.225, 265.0, ["root_shear"], 3e4)  # divergence 252 m/s
    dlm = aes.AeroelasticModel(aes.examples.goland(), 10, aero="dlm")
    with pytest.raises(aes.InputError, match="strip model only"):
        aes.statespace(dlm, 100.0, 1.225, inputs=["load_factor"], outputs=["root_shear"])
