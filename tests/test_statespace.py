"""State-space export: poles, signs, frequency response, controllability, reduced models,
discretization, files and python-control interoperability."""

import numpy as np
import pytest

import aeroservo as aes
from aeroservo.files import export_mat, export_npz
from aeroservo.linear import (
    StateSpaceBuilder,
    balanced_truncation,
    compare_frequency_response,
    discretize,
    modal_controllability,
    statespace,
)
from aeroservo.linear.output_rows import sensor_row

RHO = 1.225


@pytest.fixture(scope="module")
def vf(aileron10):
    return aes.flutter_boundary(aileron10, RHO, exact_branches=True)


def low_frequency_gain(sys, out, inp, omega=1e-7):
    """Steady-state gain from the frequency response at a very low frequency."""
    i, j = sys.output_labels.index(out), sys.input_labels.index(inp)
    g = np.asarray(sys.C) @ np.linalg.solve(
        1j * omega * np.eye(sys.nstates) - np.asarray(sys.A), np.asarray(sys.B)
    ) + np.asarray(sys.D)
    assert abs(g[i, j].imag) < 1e-4 * abs(g[i, j].real)
    return g[i, j].real


def test_named_signals_and_defaults(aileron10):
    sys = statespace(aileron10, 100.0, RHO)
    assert sys.input_labels == ["aileron_hinge_moment", "gust"]
    assert sys.output_labels == ["tip_le_accel", "tip_te_accel", "tip_twist"]
    assert sys.state_labels[:3] == ["w_1", "theta_1", "phi_1"]
    assert sys.nstates == 2 * 35 + 2 * 11 + 2  # structure, Wagner lags, Kussner (one semichord)
    assert sys.speed == 100.0 and sys.density == RHO
    assert (
        sys.signal_units["aileron_hinge_moment"] == "N m"
        and sys.signal_units["tip_le_accel"] == "m/s^2"
    )


def test_poles_equal_flutter_eigenvalues(aileron10, vf):
    """Acceptance: poles of the export equal the flutter-analysis eigenvalues (1e-8 relative)."""
    for i in (5, 12, 20):
        poles = statespace(aileron10, vf.speeds[i], RHO).poles()
        for lam in vf.eigenvalues[i]:
            assert np.min(np.abs(poles - lam)) < 1e-8 * abs(lam)


def test_unstable_just_above_flutter(aileron10, vf):
    v = vf.flutter_speed
    assert statespace(aileron10, v * (1 - 1e-4), RHO).poles().real.max() < 0
    assert statespace(aileron10, v * (1 + 1e-4), RHO).poles().real.max() > 0


def test_sign_flap_down_raises_tip_and_lift():
    """Acceptance: a steady trailing-edge-down deflection increases lift and raises the tip
    (60 m/s, well below aileron reversal)."""
    sys = statespace(
        aes.examples.goland_aileron(),
        60.0,
        RHO,
        inputs=["aileron_command"],
        outputs=["tip_disp", "root_shear", "aileron_deflection"],
    )
    assert low_frequency_gain(sys, "aileron_deflection", "aileron_command") > 0
    assert low_frequency_gain(sys, "root_shear", "aileron_command") > 0
    assert low_frequency_gain(sys, "tip_disp", "aileron_command") > 0


def test_sign_hinge_moment_and_static_solution_at_rest():
    """Acceptance: at V = 0 a positive hinge moment deflects the trailing edge down, and the steady
    state equals the static solution. Closed form with no distributed hinge spring: the actuators
    alone hold the surface, so delta = H / sum(k_act) and delta = command, uniformly."""
    wing = aes.examples.goland_aileron(hinge_stiffness=0.0)
    k_tot = sum(a.stiffness for a in wing.control_surfaces[0].actuators)
    sys = statespace(
        wing,
        0.0,
        RHO,
        inputs=["aileron_hinge_moment", "aileron_command"],
        outputs=["aileron_deflection", "tip_disp", "aileron_actuator_moment"],
    )
    assert low_frequency_gain(sys, "aileron_deflection", "aileron_hinge_moment") == pytest.approx(
        1 / k_tot, rel=1e-8
    )
    assert low_frequency_gain(sys, "aileron_deflection", "aileron_command") == pytest.approx(
        1.0, rel=1e-8
    )
    assert abs(low_frequency_gain(sys, "tip_disp", "aileron_command")) < 1e-12
    # the actuators carry no load once the surface sits at the command
    assert abs(low_frequency_gain(sys, "aileron_actuator_moment", "aileron_command")) < 1e-6 * k_tot


def test_sign_gust_raises_tip():
    for gust in ("kussner", "upwash"):
        sys = statespace(
            aes.examples.goland(), 80.0, RHO, inputs=["gust"], outputs=["tip_disp"], gust=gust
        )
        assert low_frequency_gain(sys, "tip_disp", "gust") > 0


def _direct_response(model, w, V, rows, f):
    """Second-order frequency-domain solve with the lag states eliminated term by term."""
    am, wag = model.matrices, model.wagner
    d = lambda m: m.toarray()  # noqa: E731
    scale = 1 - sum(wag.A)
    M = d(am.Ms) + RHO * d(am.Mnc)
    Ca = d(am.Cnc) - scale * d(am.Pd)
    Ka = d(am.Knc) - scale * d(am.Pq)
    Z = -w * w * M + 1j * w * RHO * V * Ca + d(am.Ks) + RHO * V * V * Ka
    for a, b in zip(wag.A, wag.b, strict=True):
        lag = np.linalg.solve(
            1j * w * d(am.Mz1) + V * b * d(am.Lz1), V * d(am.E1) + 1j * w * d(am.F1)
        )
        Z -= RHO * V * V * a * b * d(am.W1) @ lag
    return np.array([r @ np.linalg.solve(Z, f) for r in rows])


def _output_cancellation(sys, w):
    """(|C||x| + |D||u|) / |y| at ``w``: how much the output sum C x + D u cancels."""
    A, B, C, D = (np.asarray(m) for m in (sys.A, sys.B, sys.C, sys.D))
    x = np.linalg.solve(1j * w * np.eye(A.shape[0]) - A, B[:, 0])
    y = C @ x + D[:, 0]
    return float(((np.abs(C) @ np.abs(x)) + np.abs(D[:, 0])).max() / np.abs(y).max())


@pytest.mark.parametrize("kind", ["displacement", "acceleration"])
def test_frequency_response_matches_direct_solve(aileron10, kind):
    """Acceptance (issue 14): tip responses to the hinge moment from the balanced state space,
    evaluated by python-control (``sys(s)`` and ``frequency_response``, slycot's tb05ad when
    installed), equal an independent second-order frequency-domain solve to 1e-9 of the
    response. Displacements: 1e-9 at every frequency (the physical realization misses it by up
    to 1.6e-7, and failed 1e-6 on some BLAS). Accelerations: an acceleration output is a sum
    C x + D u that cancels at low frequency (the quasi-static balance), by a factor measured
    here from the model; its rounding, eps times that factor, is added to the tolerance, so the
    test holds on any BLAS (the tolerance stays under 1.5e-9 from 70 rad/s up)."""

    from aeroservo.linear.output_rows import hinge_moment_vector

    V = 110.0
    suffix = {"displacement": "disp", "acceleration": "accel"}[kind]
    names = [f"tip_le_{suffix}", f"tip_te_{suffix}"]
    rows = [
        sensor_row(aileron10, aes.Sensor("le", kind, 6.096, -1.0)),
        sensor_row(aileron10, aes.Sensor("te", kind, 6.096, 1.0)),
    ]
    f = hinge_moment_vector(aileron10, 0)
    sys = statespace(aileron10, V, RHO, inputs=["aileron_hinge_moment"], outputs=names)
    assert np.abs(sys.A).max() < 1e6  # the physical realization reaches 1.4e10
    eps = np.finfo(float).eps
    for w in (2.0, 5.0, 45.0, 70.0, 140.0, 400.0):
        direct = _direct_response(aileron10, w, V, rows, f)
        if kind == "acceleration":
            direct = -w * w * direct
            tol = 1e-9 + 10 * eps * _output_cancellation(sys, w)
        else:
            tol = 1e-9
        ss = np.asarray(sys(1j * w))[:, 0]
        fr = sys.frequency_response([w]).complex[:, 0, 0]
        err = max(np.abs(ss - direct).max(), np.abs(fr - direct).max()) / np.abs(direct).max()
        assert err < tol, (w, err, tol)
        if w >= 70.0:
            assert tol < 1.5e-9


def test_root_loads_by_force_summation():
    """Steady gust response of the clean wing: root shear, bending moment and torque from the
    FE root reactions equal the integrals of the strip lift 2 pi rho V b (V phi + w_g) and of its
    moment 2 pi rho V b^2 (a + 1/2)(V phi + w_g) (force summation)."""
    wing = aes.examples.goland()
    m = aes.AeroelasticModel(wing, 20)
    V = 90.0
    sys = statespace(
        m, V, RHO, inputs=["gust"], outputs=["root_shear", "root_bending_moment", "root_torque"]
    )
    seg = wing.segments[0]
    b, a = seg.semichord, seg.a
    system = m.system(RHO)
    f = RHO * V * m.matrices.Gw * b  # steady circulatory gust load per unit w_g (C = 1)
    q = np.linalg.solve(system.Ks.toarray() + RHO * V * V * system.K_static, f)
    phi = m.nodal_fields(q)["phi"]
    x = m.mesh.nodes
    xg, wg = np.polynomial.legendre.leggauss(3)
    shear = moment = torque = 0.0
    for e in range(m.mesh.n_elements):
        h = x[e + 1] - x[e]
        xs = x[e] + (xg + 1) / 2 * h
        ph = phi[e] + (phi[e + 1] - phi[e]) * (xs - x[e]) / h
        lift = 2 * np.pi * RHO * V * b * (V * ph + 1.0)
        shear += np.sum(wg * h / 2 * lift)
        moment += np.sum(wg * h / 2 * lift * xs)
        torque += np.sum(wg * h / 2 * lift * b * (a + 0.5))
    for name, ref in (
        ("root_shear", shear),
        ("root_bending_moment", moment),
        ("root_torque", torque),
    ):
        assert low_frequency_gain(sys, name, "gust") == pytest.approx(ref, rel=1e-6), name


def test_inputs_and_outputs_reach_the_flutter_mode(aileron10, vf):
    """Acceptance: at the flutter speed the flutter mode is controllable from every input and
    observable from every default output. Scale-invariant PBH index (see modal_controllability):
    round-off level is ~1e-16 and a zero column gives 0; tolerance 1e-10."""
    sys = statespace(
        aileron10, vf.flutter_speed, RHO, inputs=["aileron_hinge_moment", "aileron_command", "gust"]
    )
    assert np.all(np.linalg.norm(sys.B, axis=0) > 0) and np.all(np.linalg.norm(sys.C, axis=1) > 0)
    idx = modal_controllability(sys, 2j * np.pi * vf.flutter_frequency)
    assert abs(idx["eigenvalue"].real) < 1e-6
    for name, value in {**idx["inputs"], **idx["outputs"]}.items():
        assert value > 1e-10, name
    # the index does see a missing input
    import control

    broken = control.ss(sys.A, np.c_[sys.B[:, :1], np.zeros(sys.nstates)], sys.C, np.zeros((3, 2)))
    assert modal_controllability(broken, idx["eigenvalue"])["inputs"]["u[1]"] == 0.0


@pytest.mark.parametrize("n_modes", [6, 8, 10])
def test_modal_truncation(aileron10, vf, n_modes):
    """Acceptance: 6-10 structural modes (lag states complete) reproduce the flutter speed within
    1 % and the hinge-moment-to-tip-acceleration response within 5 % of its peak up to 3x the
    flutter frequency (measured: 1.1 % / 2.7 % / 2.8 % at 0.9 V_f)."""
    b = StateSpaceBuilder(
        aileron10,
        RHO,
        inputs=["aileron_hinge_moment"],
        outputs=["tip_le_accel", "tip_te_accel"],
        n_modes=n_modes,
    )
    red = aes.flutter_boundary(b.system)
    assert red.flutter_speed == pytest.approx(vf.flutter_speed, rel=1e-2)
    full = statespace(
        aileron10,
        0.9 * vf.flutter_speed,
        RHO,
        inputs=["aileron_hinge_moment"],
        outputs=["tip_le_accel", "tip_te_accel"],
    )
    omega = np.linspace(1.0, 3 * 2 * np.pi * vf.flutter_frequency, 200)
    cmp = compare_frequency_response(full, b.at(0.9 * vf.flutter_speed), omega)
    assert cmp.max_error < 0.05
    assert b.at(100.0).nstates == 2 * n_modes + 22


@pytest.mark.parametrize("speed_factor", [0.9, 1.05])
def test_balanced_truncation_respects_its_bound(aileron10, vf, speed_factor):
    """The error measured on an independent dense grid never exceeds the reported bound of
    each channel, in its physical units (unstable modes kept)."""
    full = statespace(
        aileron10,
        speed_factor * vf.flutter_speed,
        RHO,
        outputs=["tip_twist", "tip_le_disp"],
        n_modes=8,
    )
    omega = np.linspace(1.0, 3 * 2 * np.pi * vf.flutter_frequency, 300)
    for order in (10, 16):
        bt = balanced_truncation(full, order)
        assert bt.system.nstates == order
        assert bt.n_unstable == (2 if speed_factor > 1 else 0)
        cmp = compare_frequency_response(full, bt.system, omega)
        for a, out in enumerate(full.output_labels):
            for b, inp in enumerate(full.input_labels):
                err = np.abs(cmp.full[a, b] - cmp.reduced[a, b]).max()
                peak = np.abs(cmp.full[a, b]).max()
                assert err <= bt.channel_bounds[out, inp] * (1 + 1e-6) + 1e-9 * peak
    assert np.all(np.diff(bt.hsv) <= 0)


def test_balanced_truncation_scales_signals(aileron10, vf):
    """Issue 14: with metres, radians, m/s^2, N m and m/s mixed, the unscaled truncation's bound
    (2e-4, dominated by the gust channels) passed a tip-twist / hinge-moment channel with a
    1.2 % error. Scaled by nominal magnitudes, every channel of the same order is within
    0.1 %, and each measured channel error is within that channel's own bound."""
    full = statespace(aileron10, 0.9 * vf.flutter_speed, RHO, n_modes=8)
    bt = balanced_truncation(full, 20)
    unscaled = balanced_truncation(full, 20, input_scale=[1.0, 1.0], output_scale=[1.0] * 3)
    assert (
        unscaled.error_bound < 1e-3 < unscaled.channel_errors["tip_twist", "aileron_hinge_moment"]
    )
    assert bt.max_channel_error < 1e-3
    for key, err in bt.channel_errors.items():
        assert err <= bt.relative_bound(*key) * (1 + 1e-6) + 1e-9
    # default scales: every input's largest scaled peak gain and every output's is one
    scaled = {
        k: v * bt.input_scale[k[1]] / bt.output_scale[k[0]] for k, v in bt.channel_peaks.items()
    }
    for name in full.output_labels:
        assert max(v for k, v in scaled.items() if k[0] == name) == pytest.approx(1.0, rel=1e-6)
    for name in full.input_labels:
        assert max(v for k, v in scaled.items() if k[1] == name) == pytest.approx(1.0, rel=1e-6)
    given = balanced_truncation(full, 20, input_scale={"aileron_hinge_moment": 100.0, "gust": 1.0})
    assert given.input_scale == {"aileron_hinge_moment": 100.0, "gust": 1.0}
    with pytest.raises(aes.InputError, match="input_scale: unknown signal 'hinge'"):
        balanced_truncation(full, 20, input_scale={"hinge": 1.0, "gust": 1.0})
    with pytest.raises(aes.InputError, match="output_scale: need 3 positive"):
        balanced_truncation(full, 20, output_scale=[1.0, -1.0, 1.0])


def test_discretization(aileron10):
    sys = statespace(aileron10, 100.0, RHO)
    dsys = discretize(sys, 1000.0)
    assert (
        dsys.dt == pytest.approx(1e-3)
        and dsys.input_labels == sys.input_labels
        and dsys.speed == 100.0
    )
    zc = np.sort_complex(np.exp(sys.poles() * 1e-3))
    np.testing.assert_allclose(np.sort_complex(dsys.poles()), zc, atol=1e-9)


def test_export_roundtrip(tmp_path, aileron10):
    from scipy.io import loadmat

    sys = statespace(aileron10, 120.0, RHO, outputs=["tip_twist", "root_bending_moment"])
    export_mat(sys, tmp_path / "g.mat")
    export_npz(sys, tmp_path / "g.npz")
    mat = loadmat(tmp_path / "g.mat")
    npz = np.load(tmp_path / "g.npz")
    for key in "ABCD":
        np.testing.assert_array_equal(mat[key], np.asarray(getattr(sys, key)))
        np.testing.assert_array_equal(npz[key], np.asarray(getattr(sys, key)))
    assert mat["speed"].item() == 120.0 and float(npz["density"]) == RHO
    assert [str(np.squeeze(x)) for x in mat["output_names"].ravel()] == [
        "tip_twist",
        "root_bending_moment",
    ]
    assert list(npz["input_names"]) == sys.input_labels
    np.testing.assert_array_equal(npz["state_scaling"], sys.state_scaling)
    np.testing.assert_array_equal(mat["state_scaling"].ravel(), sys.state_scaling)
    # the physical realization is the balanced one undone by its scaling
    phys = statespace(aileron10, 120.0, RHO, outputs=["tip_twist"], balanced=False)
    s = npz["state_scaling"]
    np.testing.assert_allclose(
        npz["A"], np.asarray(phys.A) * s[None, :] / s[:, None], rtol=1e-15, atol=0
    )
    assert sorted(p.name for p in tmp_path.iterdir()) == ["g.mat", "g.npz"]


def test_family_reuses_the_assembly(aileron10, monkeypatch):
    import aeroservo.system.aeroelastic as mod

    speeds = np.linspace(60, 160, 6)
    fam = aes.statespace_family(aileron10, speeds, RHO)
    monkeypatch.setattr(mod, "assemble", lambda *a, **k: (_ for _ in ()).throw(AssertionError))
    for v, s in zip(speeds, fam, strict=True):
        np.testing.assert_array_equal(s.A, statespace(aileron10, v, RHO).A)


def test_servo_dynamics_add_states(aileron10):
    base = statespace(aileron10, 100.0, RHO, inputs=["aileron_command"])
    for order, extra in ((1, 1), (2, 2)):
        s = statespace(
            aileron10,
            100.0,
            RHO,
            inputs=["aileron_command"],
            servo=aes.Servo(order, 2 * np.pi * 30, 0.7),
        )
        assert s.nstates == base.nstates + extra
        # the servo passes low frequencies unchanged
        assert low_frequency_gain(s, "tip_twist", "aileron_command") == pytest.approx(
            low_frequency_gain(base, "tip_twist", "aileron_command"), rel=1e-6
        )


def test_python_control_interoperability(aileron10, vf):
    import control

    v = 1.1 * vf.flutter_speed
    sys = statespace(
        aileron10, v, RHO, inputs=["aileron_hinge_moment"], outputs=["tip_le_accel", "tip_twist"]
    )
    K, _, E = control.lqr(sys, np.eye(sys.nstates), np.eye(1) * 1e-6)
    assert E.real.max() < 0
    t = np.linspace(0, 0.2, 201)
    plant = statespace(aileron10, 100.0, RHO)
    resp = control.forced_response(
        plant, t, np.zeros((2, t.size)), X0=np.r_[1e-3, np.zeros(plant.nstates - 1)]
    )
    assert resp.outputs.shape == (3, t.size)
    # (a static gain on the accelerometer would be an algebraic loop: accelerations have a
    # direct feedthrough from the hinge moment)
    ctrl = control.ss(
        np.zeros((0, 0)),
        np.zeros((0, 1)),
        np.zeros((1, 0)),
        [[-1.0]],
        inputs=["tip_twist"],
        outputs=["aileron_hinge_moment"],
        name="k",
    )
    gusty = statespace(
        aileron10, v, RHO, inputs=["aileron_hinge_moment", "gust"], outputs=["tip_twist"]
    )
    cl = control.interconnect([gusty, ctrl], inputs=["gust"], outputs=["tip_twist"])
    assert cl.nstates == gusty.nstates and cl.input_labels == ["gust"]
    mag = control.frequency_response(sys, np.array([10.0, 40.0, 70.0])).magnitude
    assert mag.shape == (2, 1, 3)


@pytest.mark.parametrize(
    "kw,match",
    [
        ({"inputs": ["elevator_hinge_moment"]}, "unknown; this wing offers"),
        ({"outputs": ["tip_pressure"]}, "unknown sensor"),
        ({"outputs": [aes.Sensor("far", "acceleration", 9.0)]}, "outside the wing"),
        ({"outputs": ["tip_twist", "tip_twist"]}, "appears twice"),
        ({"outputs": ["modal_99"]}, "mode number"),
        ({"gust": "frozen"}, "gust = 'frozen'"),
        ({"servo": "fast", "inputs": ["aileron_command"]}, "expected a Servo"),
    ],
)
def test_bad_signals(aileron10, kw, match):
    with pytest.raises(aes.InputError, match=match):
        statespace(aileron10, 100.0, RHO, **kw)


@pytest.mark.parametrize(
    "args,match", [((1, 0.0), "bandwidth"), ((3, 10.0), "order"), ((2, 10.0, -1.0), "damping")]
)
def test_bad_servo(args, match):
    with pytest.raises(aes.InputError, match=match):
        aes.Servo(*args)


def test_command_needs_actuators():
    from aeroservo.structure import ControlSurface, Segment, Wing

    seg = Segment(0, 4, 0.5, -0.3, 10, 0.1, 1.0, 1e6, 1e5)
    wing = Wing(4, [seg], [ControlSurface("flap", 2, 4, 0.5, 0.05, 0.02, hinge_stiffness=50.0)])
    with pytest.raises(aes.InputError, match="has no actuators"):
        statespace(wing, 50.0, RHO, inputs=["flap_command"])
    s = statespace(
        wing,
        50.0,
        RHO,
        inputs=["flap_hinge_moment"],
        outputs=["flap_deflection", "flap_aero_hinge_moment", "modal_2"],
    )
    assert s.noutputs == 3
