"""Loads along the span (issue 38, item 6): shear, bending moment and torque at any node.

The toolkit takes them as the reactions of the part of the wing outboard of a node, clamped
there (the rows of that node in the assembly of the outboard elements, as it takes the root
loads). The references here are force summations written in the test, with their own field
interpolation (cubic Hermite bending, linear twist, as in seed eq. 6-7) and quadrature:

* inertial loads: in a free vibration of the wing in vacuo at omega, the d'Alembert loads per
  unit span are ``omega^2 (m w - S_a phi)`` (up) and ``omega^2 (I_a phi - S_a w)`` (nose-up
  about the elastic axis), with ``S_a = m x_alpha b``; a store adds its own (Bisplinghoff,
  Ashley and Halfman, *Aeroelasticity*, 1955, sec. 9-3: the loads at a station are the
  integrated inertial and aerodynamic loads outboard of it);
* aerodynamic loads: steady strip theory on the flexible wing in a uniform gust,
  ``L' = 2 pi rho V b (w_g + V phi(y))`` at the quarter chord, with the wing's own twist
  ``phi(y)`` (the model's twist sensors), so that ``V(x) = int_x^l L'``,
  ``M(x) = int_x^l (y - x) L'`` and ``T(x) = int_x^l (1/2 + a) b L'``.

Both references are exact for the fields of the element (the twist is linear, the bending
cubic), so the tolerances are those of rounding (1e-9 relative).
"""

from __future__ import annotations

import control
import numpy as np
import pytest
import scipy.linalg as sla

import aeroservo as aes
from aeroservo.linear.signals import station_output
from aeroservo.studies.gust.study import FlightPoint, GustLoadsStudy

QUANTITIES = ("shear", "bending_moment", "torque")


def _hermite(xi: np.ndarray, length: float) -> np.ndarray:
    """Cubic Hermite shape functions of (w1, w1', w2, w2') at local points xi in [0, 1]."""
    return np.stack(
        [
            1 - 3 * xi**2 + 2 * xi**3,
            length * (xi - 2 * xi**2 + xi**3),
            3 * xi**2 - 2 * xi**3,
            length * (-(xi**2) + xi**3),
        ],
        axis=-1,
    )


def _fields(model, q: np.ndarray, n_gauss: int = 6):
    """Gauss points y, weights and the fields w(y), phi(y) of the nodal vector q."""
    mesh = model.mesh
    xg, wg = np.polynomial.legendre.leggauss(n_gauss)
    xi = 0.5 * (xg + 1)
    ys, ws, w, phi = [], [], [], []
    full = np.r_[q, 0.0]  # index -1 (a clamped unknown) reads 0

    def at(idx):
        return full[np.where(idx >= 0, idx, -1)]

    for e in range(mesh.n_elements):
        x0, x1 = mesh.nodes[e], mesh.nodes[e + 1]
        length = x1 - x0
        nodal_w = at(
            np.array([mesh.dof_w[e], mesh.dof_theta[e], mesh.dof_w[e + 1], mesh.dof_theta[e + 1]])
        )
        nodal_phi = at(np.array([mesh.dof_phi[e], mesh.dof_phi[e + 1]]))
        ys.append(x0 + xi * length)
        ws.append(0.5 * wg * length)
        w.append(_hermite(xi, length) @ nodal_w)
        phi.append((1 - xi) * nodal_phi[0] + xi * nodal_phi[1])
    return (np.concatenate(a) for a in (ys, ws, w, phi))


def _summed(y, wts, force, torque, x):
    """Shear, bending moment and torque at x of distributed loads (force up, torque nose-up)."""
    out = y > x
    f, t, arm = force[out] * wts[out], torque[out] * wts[out], y[out] - x
    return np.array([f.sum(), (f * arm).sum(), t.sum()])


def _wing_with_store():
    base = aes.examples.goland()
    store = aes.ConcentratedMass(station=4.7, mass=40.0, offset=-0.2, inertia=3.0, name="store")
    return aes.Wing(base.span, base.segments, masses=[store], name="Goland + store")


@pytest.mark.parametrize("store", [False, True], ids=["clean", "store"])
@pytest.mark.parametrize("stations", [(), (1.0, 3.3, 5.05)], ids=["nodes", "load_stations"])
def test_inertial_loads_of_a_vacuum_mode_equal_the_force_summation(store, stations):
    wing = _wing_with_store() if store else aes.examples.goland()
    model = aes.AeroelasticModel(wing, 12, load_stations=stations)
    am = model.matrices
    w2, shapes = sla.eigh(am.Ks.toarray(), am.Ms.toarray())
    seg = wing.segments[0]
    m, b = seg.mass, seg.semichord
    s_a, i_a = m * seg.x_alpha * b, seg.inertia
    for mode in range(4):
        q, om2 = shapes[:, mode], w2[mode]
        y, wts, w, phi = _fields(model, q)
        force = om2 * (m * w - s_a * phi)
        torque = om2 * (i_a * phi - s_a * w)
        cut = -(am.cuts.Ks - om2 * am.cuts.Ms) @ q  # the load carried: minus the reaction
        for j, x in enumerate(model.mesh.nodes):
            ref = _summed(y, wts, force, torque, x)
            for pm in wing.masses:
                if pm.station > x:  # the store's own d'Alembert loads, at its CG
                    wm, pm_phi = _point_fields(model, q, pm.station)
                    f = om2 * pm.mass * (wm - pm.offset * pm_phi)
                    ref += np.array(
                        [
                            f,
                            f * (pm.station - x),
                            om2
                            * (
                                (pm.inertia + pm.mass * pm.offset**2) * pm_phi
                                - pm.mass * pm.offset * wm
                            ),
                        ]
                    )
            scale = np.abs(ref).max() + np.abs(cut).max()
            np.testing.assert_allclose(
                cut[3 * j : 3 * j + 3],
                ref,
                atol=1e-9 * scale,
                err_msg=f"mode {mode + 1}, node {j} at {x:g} m",
            )


def _point_fields(model, q, x):
    """w and phi at station x from the test's own interpolation."""
    mesh = model.mesh
    e = min(int(np.searchsorted(mesh.nodes, x, side="right")) - 1, mesh.n_elements - 1)
    x0, x1 = mesh.nodes[e], mesh.nodes[e + 1]
    xi = np.array([(x - x0) / (x1 - x0)])
    full = np.r_[q, 0.0]

    def at(idx):
        return full[np.where(idx >= 0, idx, -1)]

    nodal_w = at(
        np.array([mesh.dof_w[e], mesh.dof_theta[e], mesh.dof_w[e + 1], mesh.dof_theta[e + 1]])
    )
    nodal_phi = at(np.array([mesh.dof_phi[e], mesh.dof_phi[e + 1]]))
    return float(_hermite(xi, x1 - x0)[0] @ nodal_w), float(
        (1 - xi[0]) * nodal_phi[0] + xi[0] * nodal_phi[1]
    )


@pytest.mark.parametrize("stations", [(), (1.0, 3.3, 5.05)], ids=["nodes", "load_stations"])
def test_steady_gust_loads_equal_the_integrated_strip_lift(stations):
    v, rho = 120.0, 1.225
    wing = aes.examples.goland()
    model = aes.AeroelasticModel(wing, 10, load_stations=stations)
    seg = wing.segments[0]
    b, a = seg.semichord, seg.a
    nodes = model.mesh.nodes
    outs = [station_output(q, x) for x in nodes for q in QUANTITIES]
    y_probe, wts, _, _ = _fields(model, np.zeros(model.n_dofs), n_gauss=2)
    twist = [aes.Sensor(f"twist_{i}", "twist", float(yy)) for i, yy in enumerate(y_probe)]
    sys = aes.statespace(model, v, rho, inputs=["gust"], outputs=outs + twist)
    gain = np.asarray(control.dcgain(sys)).ravel()  # per m/s of gust
    loads, phi = gain[: len(outs)], gain[len(outs) :]
    lift = 2 * np.pi * rho * v * b * (1.0 + v * phi)
    assert phi.max() > 1e-4  # the wing twists: not a rigid-wing check
    for j, x in enumerate(nodes):
        ref = _summed(y_probe, wts, lift, (0.5 + a) * b * lift, x)
        np.testing.assert_allclose(
            loads[3 * j : 3 * j + 3],
            ref,
            rtol=1e-9,
            atol=1e-9 * ref.max(),
            err_msg=f"node {j} at {x:g} m",
        )


def test_station_at_the_root_is_the_root_and_the_tip_carries_nothing():
    wing = aes.examples.goland_aileron()
    model = aes.AeroelasticModel(wing, 10, load_stations=[2.5])
    root = ["root_shear", "root_bending_moment", "root_torque"]
    at0 = [station_output(q, 0.0) for q in QUANTITIES]
    tip = [station_output(q, wing.span) for q in QUANTITIES]
    sys = aes.statespace(
        model,
        120.0,
        1.225,
        inputs=["aileron_hinge_moment", "gust"],
        outputs=root + at0 + tip + [station_output("shear", 2.5)],
    )
    for mat in (sys.C, sys.D):
        mat = np.asarray(mat)
        np.testing.assert_array_equal(mat[:3], mat[3:6])
        assert np.abs(mat[6:9]).max() == 0.0
    assert "shear_at_2500mm" in sys.output_labels


def test_station_names_and_errors():
    model = aes.AeroelasticModel(aes.examples.goland(), 10)
    assert station_output("bending_moment", 2.5) == "bending_moment_at_2500mm"
    with pytest.raises(aes.InputError, match=r"no mesh node at 2\.5 m .*load_stations=\[2\.5\]"):
        aes.statespace(model, 100.0, 1.225, inputs=["gust"], outputs=["shear_at_2500mm"])
    with pytest.raises(aes.InputError, match="whole millimetres"):
        aes.statespace(model, 100.0, 1.225, inputs=["gust"], outputs=["shear_at_2.5mm"])
    with pytest.raises(aes.InputError, match="whole millimetres"):
        aes.statespace(model, 100.0, 1.225, inputs=["gust"], outputs=["torque_at_9000mm"])
    with pytest.raises(aes.InputError, match="load_stations"):
        aes.AeroelasticModel(aes.examples.goland(), 10, load_stations=[7.0])
    dlm = aes.AeroelasticModel(aes.examples.goland(), 10, aero="dlm", load_stations=[3.048])
    with pytest.raises(aes.InputError, match="strip model"):
        aes.statespace(dlm, 100.0, 1.225, inputs=["gust"], outputs=["shear_at_3048mm"])


def test_gust_loads_study_reports_the_stations():
    study = GustLoadsStudy(
        mass_cases={"nominal": aes.examples.goland()},
        points=(FlightPoint(0.0, 100.0, "V_C", "nominal"),),
        loads=("root_bending_moment",),
        load_stations=(3.0, 1.5),
        n_gradients=5,
        turbulence=True,
    )
    assert study.load_stations == (1.5, 3.0)
    assert study.loads[:4] == (
        "root_bending_moment",
        "shear_at_1500mm",
        "bending_moment_at_1500mm",
        "torque_at_1500mm",
    )
    from aeroservo.studies.gust.point import evaluate_point

    res = evaluate_point(study, study.points[0])
    ext = res.discrete["open"].extremes
    # bending falls outboard; the root's is the largest
    bm = [
        ext[n].maximum
        for n in ("root_bending_moment", "bending_moment_at_1500mm", "bending_moment_at_3000mm")
    ]
    assert bm[0] > bm[1] > bm[2] > 0
    assert set(res.turbulence["open"].a_bar) >= set(study.loads)


def test_rigid_ratio_is_near_one_for_a_stiff_wing_and_above_for_goland():
    """The rigid-wing column (Pratt and Walker, NACA TR 1206, without the airplane's gust
    alleviation factor: the wing is clamped): a wing 1e4 times stiffer gives the quasi-static
    strip load less the Kussner lag in the longest gust (0.7 %, as the root check of
    docs/gust-loads.md), the Goland wing its aeroelastic amplification (1.14-1.20)."""
    from aeroservo.studies.gust.rigid_wing import rigid_gust_loads
    from aeroservo.studies.gust.run import run_gust_loads

    loads = ("root_shear", "root_bending_moment", "root_torque", "tip_le_accel")
    ratios = {}
    for name, w in (
        ("stiff", aes.examples.goland(GJ=0.99e6 * 1e4, EI=9.77e6 * 1e4)),
        ("goland", aes.examples.goland()),
    ):
        st = GustLoadsStudy(
            mass_cases={"nominal": w},
            points=(FlightPoint(0.0, 100.0, "V_C", "nominal"),),
            loads=loads,
            load_stations=(3.0,),
            n_gradients=8,
            turbulence=False,
        )
        t = run_gust_loads(st).table.set_index("load")["rigid_ratio"]
        assert np.isnan(t["tip_le_accel"])
        ratios[name] = t.drop("tip_le_accel")
    assert ratios["stiff"].between(0.99, 1.0).all(), ratios["stiff"]
    assert ratios["goland"].between(1.1, 1.25).all(), ratios["goland"]
    # the closed form by hand: a uniform wing, lift per span 2 pi rho V b U
    w = aes.examples.goland()
    seg, span = w.segments[0], w.span
    lift = 2 * np.pi * 1.2 * 150.0 * seg.semichord * 10.0
    got = rigid_gust_loads(
        w,
        ["shear_at_2000mm", "bending_moment_at_2000mm", "torque_at_2000mm", "root_torque"],
        1.2,
        150.0,
        10.0,
    )
    arm = span - 2.0
    assert got == pytest.approx(
        {
            "shear_at_2000mm": lift * arm,
            "bending_moment_at_2000mm": lift * arm**2 / 2,
            "torque_at_2000mm": lift * (0.5 + seg.a) * seg.semichord * arm,
            "root_torque": lift * (0.5 + seg.a) * seg.semichord * span,
        },
        rel=1e-12,
    )
    assert rigid_gust_loads(aes.examples.goland_swept(), ["root_shear"], 1.2, 150.0, 10.0) == {}


def test_station_names_round_to_the_millimetre():
    """A station off the millimetre grid is found by its rounded name (0.5 mm at most), and two
    stations that would share a name are refused."""
    model = aes.AeroelasticModel(aes.examples.goland(), 10, load_stations=[1.2195, 3.0004])
    names = [station_output("shear", 1.2195), station_output("torque", 3.0004)]
    assert names == ["shear_at_1220mm", "torque_at_3000mm"]
    sys = aes.statespace(model, 100.0, 1.225, inputs=["gust"], outputs=names)
    assert list(sys.output_labels) == names
    with pytest.raises(aes.InputError, match="closer than 2 mm"):
        GustLoadsStudy(
            mass_cases={"nominal": aes.examples.goland()},
            points=(FlightPoint(0.0, 100.0, "V_C", "nominal"),),
            loads=("root_shear",),
            load_stations=(2.0, 2.0015),
        )
