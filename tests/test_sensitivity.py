"""Analytic flutter and divergence sensitivities against central finite differences.

Every analytic derivative (eigenvalue derivatives at the crossing, matrix derivatives from the
element integrals) is compared with a central difference of the speed computed by the engine
itself at a tight tolerance (rtol 1e-12, relative step 2e-5; see FLOOR and DIV_STEP), on the
Goland wing (its geometry as in reference case ``goland_clean_flutter_strip_sea_level``), the
Goland wing with its aileron, the HALE wing (reference case ``hale_patil_hodges_cesnik`` at its
20 km density, 0.0889 kg/m^3) with and without an aileron, and one randomized wing of each class
of the stability corpus (``tests/wing_corpus.py``). Agreement: 1e-4 relative on normalized
derivatives ``p / V dV/dp``.
"""

from __future__ import annotations

import functools

import numpy as np
import pytest
from test_stability_named import HALE, hale_wing
from wing_corpus import CLASSES, case_name, shared_corpus

import aeroservo as aes
from aeroservo.aero.atmosphere import isa
from aeroservo.errors import InputError
from aeroservo.stability.divergence import divergence_speed
from aeroservo.stability.result import Crossing
from aeroservo.stability.sensitivity import flutter_sensitivities, parameter_values
from aeroservo.structure.examples import goland, goland_aileron
from aeroservo.studies.optimize import with_parameters
from aeroservo.system.assembly import assemble
from aeroservo.system.damping import StructuralDamping, damping_derivatives, damping_matrix
from aeroservo.system.derivatives import matrix_derivative, station_on_node
from aeroservo.system.first_order import pencil_blocks
from aeroservo.system.pencil_forms import pencil_form, static_form

TOL = 1e-4
STEP = 2e-5
RTOL = 1e-12
DIV_STEP = 1e-2
FLOOR = 1e-6
"""Absolute floor on normalized derivatives: 40 x the noise of a central difference (engine
error about RTOL relative, over 2 STEP), about 1e-5 of the usual O(0.1-1) values. The step
keeps the truncation error below 3e-5 relative on the most curved case (flutter past
divergence, ``divergence_critical_01``: 8e-4 with a step of 1e-4, 8e-6 with 1e-5)."""


def perturbed(wing: aes.Wing, name: str, h: float) -> aes.Wing:
    """The wing with parameter ``name`` (wing-file name) moved by ``h``."""
    return with_parameters(wing, {name: parameter_values(wing)[name][3] + h})


def _moved(model, density, name, value, h):
    """(model, density) with parameter ``name`` moved by ``h``."""
    if name == "density":
        return model, density + h
    return aes.AeroelasticModel(perturbed(model.wing, name, h), model.n_elements), density


def central(model, density, name, value, v_max):
    """Central differences of (V_f, f_f, V_d) in parameter ``name``. The divergence speed is
    a direct solve, precise to about 1e-10 relative only: its step is DIV_STEP, with Richardson
    extrapolation from half the step (the truncation error of the parameters entering the
    aerodynamics nonlinearly, e.g. 3e-4 for ``a`` at one step, drops below 1e-6)."""
    h = STEP * (abs(value) or 1.0)
    # a parameter at zero sits on its lower bound (a hinge spring of 0): one-sided, 2nd order
    stencil = ((1.0, 0.5), (-1.0, -0.5)) if value else ((0.0, -1.5), (1.0, 2.0), (2.0, -0.5))
    runs = [
        aes.flutter_boundary(*_moved(model, density, name, value, o * h), rtol=RTOL, v_max=v_max)
        for o, _ in stencil
    ]

    def d(attr):
        vals = [getattr(r, attr) for r in runs]
        if any(v is None for v in vals):
            return None
        return sum(w * v for (_, w), v in zip(stencil, vals, strict=True)) / h

    dd = None
    if runs[0].divergence_speed is not None:

        def div(hd):
            vals = [
                divergence_speed(mm.system(rho))
                for mm, rho in (_moved(model, density, name, value, o * hd) for o, _ in stencil)
            ]
            if any(v is None for v in vals):
                return None
            return sum(w * v for (_, w), v in zip(stencil, vals, strict=True)) / hd

        hd = DIV_STEP * (abs(value) or 1.0)
        big, small = div(hd), div(hd / 2)  # Richardson: the nonlinear parameters (a, b, c)
        dd = None if big is None or small is None else (4 * small - big) / 3
    return d("flutter_speed"), d("flutter_frequency"), dd


def two_surfaces() -> aes.Wing:
    """Goland with an inboard flap (no actuator) and the aileron, whose actuators are moved off
    the mesh nodes: an actuator of the second surface (the review found its stiffness
    derivative put on the first surface's flap)."""
    from dataclasses import replace

    w0 = goland_aileron()
    ail = w0.control_surfaces[0]
    inner = replace(ail, name="inner", start=0.5, end=2.5, actuators=())
    acts = tuple(replace(a, station=a.station + 0.2) for a in ail.actuators)
    return replace(w0, control_surfaces=(inner, replace(ail, actuators=acts)))


NAMED = {
    "goland": (goland, 1.225),
    "goland_aileron": (goland_aileron, 1.225),
    "two_surfaces": (two_surfaces, 1.225),
    "hale": (hale_wing, HALE["inputs"]["density_kg_m3"]),
    "hale_aileron": (lambda: hale_wing(True), HALE["inputs"]["density_kg_m3"]),
}
"""The named wings and their densities [kg/m^3]."""

CASES = [*NAMED, *(case_name(klass, 0) for klass in CLASSES if klass != "hale")]
"""The named wings, then the first wing of each corpus class but ``hale`` (all the others have
a control surface or several segments); names known at collection, wings built on first use."""


@functools.cache
def named_case(name: str) -> tuple[aes.AeroelasticModel, float, float | None]:
    """``(model, density [kg/m^3], v_max [m/s] or None)`` of a case of ``CASES``."""
    if name in NAMED:
        wing, density = NAMED[name]
        return aes.AeroelasticModel(wing()), density, None
    (c,) = (c for c in shared_corpus() if c.name == name)
    return c.model, c.density, c.v_max


def _check(got, ref, value, base, what):
    """Normalized derivatives ``p / V dV/dp`` agree within TOL relative, or within FLOOR where
    the parameter barely moves the speed (there the central difference is noise: the engine's
    relative error rtol over the relative step)."""
    if ref is None:
        return
    scale = (abs(value) or 1.0) / base
    n_got, n_ref = got * scale, ref * scale
    assert abs(n_got - n_ref) <= TOL * abs(n_ref) + FLOOR, (
        f"{what}: analytic {got:.8g}, central {ref:.8g} (normalized {n_got:.6g}, {n_ref:.6g})"
    )


FAST_CASES = ("goland", "goland_aileron", "hale")
"""The cases ``make test-fast`` runs; the others (the corpus wings: building the corpus takes
about 20 s) are marked slow."""


@pytest.mark.parametrize(
    "name", [n if n in FAST_CASES else pytest.param(n, marks=pytest.mark.slow) for n in CASES]
)
def test_against_central_differences(name):
    model, density, v_max = named_case(name)
    s = flutter_sensitivities(model, density, rtol=RTOL, v_max=v_max)
    assert s.flutter_speed is not None or s.divergence_speed is not None
    if s.non_differentiable:
        pytest.skip(s.non_differentiable)
    params = list(s.values)
    rng = np.random.default_rng(len(name))
    if len(params) > 10:  # a fixed random subset keeps the test short; always the density and
        # the parameters that enter the aerodynamics (a, semichord, hinge line, actuator station)
        aero = [p for p in params if p.rsplit(".", 1)[-1] in ("a", "semichord", "hinge", "station")]
        aero = list(rng.choice(aero, min(3, len(aero)), replace=False))
        rest = [p for p in params[:-1] if p not in aero]
        params = [*aero, *rng.choice(rest, 6, replace=False), "density"]
    for p in params:
        if p in s.undefined:  # an actuator on a mesh node: test_station_on_a_node_...
            continue
        dv, df, dd = central(model, density, p, s.values[p], v_max)
        x = s.values[p]
        if s.flutter_speed is not None:
            _check(s.d_flutter_speed[p], dv, x, s.flutter_speed, f"{name} dV_f/d{p}")
            _check(s.d_flutter_frequency[p], df, x, s.flutter_frequency, f"{name} df_f/d{p}")
        if s.divergence_speed is not None:
            _check(s.d_divergence_speed[p], dd, x, s.divergence_speed, f"{name} dV_d/d{p}")


def off_node_aileron() -> aes.Wing:
    """Goland with aileron, the actuators moved off the 10-element mesh nodes (0.61 m apart)."""
    wing = goland_aileron()
    names = [n for n in parameter_values(wing) if n.endswith("station")]
    return with_parameters(wing, {n: parameter_values(wing)[n][3] + 0.2 for n in names})


LINEAR = ("mass", "x_alpha", "inertia", "EI", "GJ", "static_moment", "hinge_stiffness", "stiffness")
FIELDS = ("Ms", "Ks", "Mnc", "Cnc", "Knc", "Pq", "Pd", "Lz1", "E1", "F1", "W1")


@pytest.mark.parametrize(
    "wing_name,name",
    [("aileron", n) for n in parameter_values(goland_aileron())]
    + [("two", n) for n in parameter_values(two_surfaces()) if "control_surfaces[1]" in n],
)
def test_matrix_derivatives_against_differences_of_the_assembly(wing_name, name):
    """Every matrix derivative (complex step of the section coefficients, element integrals)
    against differences of two full assemblies: the slope for the parameters the matrices are
    linear in, a central difference (relative step 1e-5, truncation ~1e-10) for the others."""
    wing = off_node_aileron() if wing_name == "aileron" else two_surfaces()
    model = aes.AeroelasticModel(wing)
    owner, idx, key, value = parameter_values(wing)[name]
    d = matrix_derivative(wing, model.mesh, owner, idx, key)
    linear = key in LINEAR or (owner == "surface" and key in ("inertia", "GJ"))
    h = (0.01 if linear else 1e-5) * abs(value)
    lo = assemble(wing if linear else perturbed(wing, name, -h), model.mesh)
    hi = assemble(perturbed(wing, name, h), model.mesh)
    for f in FIELDS:
        slope = ((getattr(hi, f) - getattr(lo, f)) / (h if linear else 2 * h)).toarray()
        got = getattr(d, f).toarray()
        tol = (1e-10 if linear else 1e-7) * max(abs(slope).max(), abs(got).max(), 1e-300)
        np.testing.assert_allclose(got, slope, atol=tol, rtol=0, err_msg=f"{name}: {f}")


@pytest.mark.parametrize("j", [0, 1])
def test_station_on_a_node_has_two_one_sided_derivatives(j):
    """An actuator on a mesh node: each side's derivative is that side's one-sided difference,
    the two differ (a kink of the discretized model), and the result names it."""
    wing = goland_aileron()
    model = aes.AeroelasticModel(wing)
    assert station_on_node(wing, model.mesh, 0, j)
    name = f"control_surfaces[0].actuators[{j}].station"
    x0, h = parameter_values(wing)[name][3], 1e-6
    k0 = assemble(wing, model.mesh).Ks
    for side in (1, -1):
        d = matrix_derivative(wing, model.mesh, "actuator", (0, j), "station", side=side)
        k1 = assemble(with_parameters(wing, {name: x0 + side * h}), model.mesh).Ks
        one_sided = ((k1 - k0) / (side * h)).toarray()
        np.testing.assert_allclose(d.Ks.toarray(), one_sided, atol=1e-5 * abs(one_sided).max())
    s = flutter_sensitivities(model, 1.225, [name, "density"])
    assert name not in s.d_flutter_speed and "kink" in s.undefined[name]
    assert "inboard" in s.undefined[name] and "outboard" in s.undefined[name]


@pytest.mark.parametrize("mach", [0.0, 0.5])
def test_pencil_forms_equal_the_assembled_pencil(mach):
    """``pencil_form`` and ``static_form`` (block contractions) against the pencil assembled
    by ``pencil_blocks`` from the same matrix derivatives, with random complex vectors."""
    wing = off_node_aileron()
    model = aes.AeroelasticModel(wing, damping=StructuralDamping.structural(0.03))
    d_structure, _ = damping_derivatives(model.damping, model.matrices.Ms, model.matrices.Ks)
    table = parameter_values(wing)
    rng = np.random.default_rng(7)
    n = model.n_states
    x, y = (rng.standard_normal(n) + 1j * rng.standard_normal(n) for _ in range(2))
    speed, lam, rho = 120.0, -3.0 + 70j, 1.1
    base = pencil_blocks(model.matrices, model.wagner, rho, mach)
    lag = base["Lam"].toarray()
    for name in ("segments[0].a", "segments[0].semichord", "control_surfaces[0].hinge"):
        owner, idx, key, _ = table[name]
        dam = matrix_derivative(wing, model.mesh, owner, idx, key)
        from dataclasses import replace

        dam = replace(dam, Cs=d_structure(dam.Ms, dam.Ks))
        b = pencil_blocks(dam, model.wagner, rho, mach, constant=False)
        ref = y.conj() @ ((b["A0"] + speed * b["A1"] + speed**2 * b["A2"] - lam * b["E"]) @ x)
        got = pencil_form(dam, model.wagner, rho, mach, y, x, speed, lam)
        assert abs(got - ref) <= 1e-12 * max(abs(ref), 1.0), name
        u, q = x.real[: model.n_dofs], y.real[: model.n_dofs]
        av = np.linalg.solve(lag, base["Ez"] @ q)
        bv = np.linalg.solve(lag.T, base["Dz"].T @ u)
        k_st = b["Ka"] - b["Dz"] @ np.linalg.solve(lag, base["Ez"].toarray())
        k_st = k_st + base["Dz"] @ np.linalg.solve(
            lag, b["Lam"] @ np.linalg.solve(lag, base["Ez"].toarray())
        )
        k_st = k_st - base["Dz"] @ np.linalg.solve(lag, b["Ez"].toarray())
        ref_s = u @ k_st @ q
        got_s = static_form(dam, model.wagner, mach, u, q, av, bv)
        assert abs(got_s - ref_s) <= 1e-10 * max(abs(ref_s), 1.0), name


@pytest.mark.parametrize(
    "damping",
    [
        StructuralDamping.structural(0.03),
        StructuralDamping.modal(0.02),
        StructuralDamping.modal([0.01, 0.02, 0.04]),
        StructuralDamping.rayleigh(0.5, 1e-4),
    ],
    ids=["g", "zeta", "zetas", "rayleigh"],
)
def test_damping_derivatives_against_central_differences(damping):
    """d Cs for a move of (Ms, Ks) (the mass and inertia of the wing and the GJ of the
    aileron together) and for the damping's own parameters, against central differences of
    ``damping_matrix`` (relative step 1e-6; a random move would excite the mesh's highest modes,
    7e9 rad^2/s^2 and closely spaced, whose central differences have a truncation of 1e-5)."""
    wing = goland_aileron()
    model = aes.AeroelasticModel(wing)
    Ms, Ks = model.matrices.Ms.toarray(), model.matrices.Ks.toarray()
    table = parameter_values(wing)
    dm, dk = np.zeros_like(Ms), np.zeros_like(Ks)
    for name in ("segments[0].mass", "segments[0].inertia", "control_surfaces[0].GJ"):
        owner, idx, key, value = table[name]
        d = matrix_derivative(wing, model.mesh, owner, idx, key)
        dm += value * d.Ms.toarray()
        dk += value * d.Ks.toarray()
    d_structure, d_own = damping_derivatives(damping, Ms, Ks)
    h = 1e-6
    ref = (
        damping_matrix(damping, Ms + h * dm, Ks + h * dk)
        - damping_matrix(damping, Ms - h * dm, Ks - h * dk)
    ) / (2 * h)
    got = d_structure(dm, dk)
    scale = abs(ref).max()
    np.testing.assert_allclose(got.toarray(), ref.toarray(), atol=1e-6 * scale)
    for name, value in damping.to_dict().items():
        if name == "kind":
            continue
        values = value if isinstance(value, list) else [value]
        for i, v in enumerate(values):
            key = f"damping.{name}" + (
                f"[{i}]" if isinstance(value, list) and len(value) > 1 else ""
            )

            def moved(t, name=name, i=i):
                d = damping.to_dict()
                if isinstance(d[name], list):
                    d[name][i] += t
                else:
                    d[name] += t
                kw = {k: tuple(v) if isinstance(v, list) else v for k, v in d.items()}
                kw = {("ratios" if k == "ratio" else k): v for k, v in kw.items()}
                return damping_matrix(StructuralDamping(**kw), Ms, Ks)

            hh = 1e-6 * v
            ref = ((moved(hh) - moved(-hh)) / (2 * hh)).toarray()
            np.testing.assert_allclose(d_own(key).toarray(), ref, atol=1e-6 * abs(ref).max())


def _damping_with(damping: StructuralDamping, name: str, value: float) -> StructuralDamping:
    """The damping with its parameter ``name`` (``damping.g``, ``damping.ratio[1]``) set."""
    from dataclasses import replace

    key = name.split(".")[1]
    if key.startswith("ratio"):
        r = list(damping.ratios)
        r[int(key[6:-1]) if "[" in key else 0] = value
        return replace(damping, ratios=tuple(r))
    return replace(damping, **{key: value})


def _analysis(wing, damping, flight: dict, name: str | None = None, value: float = 0.0):
    """The engine's boundary with one parameter (wing, damping or flight) set to ``value``."""
    from dataclasses import replace

    from aeroservo.stability.matched import flutter_at

    flight = dict(flight)
    if name is not None and name.startswith("damping."):
        damping = _damping_with(damping, name, value)
    elif name in ("density", "altitude", "mach"):
        if name == "altitude":
            flight["atmosphere"] = isa(value)
        elif name == "density" and "atmosphere" in flight:
            flight["atmosphere"] = replace(flight["atmosphere"], density=value)
        else:
            flight[name] = value
    elif name is not None:
        wing = with_parameters(wing, {name: value})
    model = aes.AeroelasticModel(wing, damping=damping)
    if "atmosphere" in flight:
        atm = flight.pop("atmosphere")
        return flutter_at(model, atm, rtol=RTOL, **flight)
    return aes.flutter_boundary(model, flight.pop("density"), rtol=RTOL, **flight)


G, ZETAS, RAYLEIGH = (
    StructuralDamping.structural(0.03),
    StructuralDamping.modal([0.01, 0.02, 0.04]),
    StructuralDamping.rayleigh(0.5, 1e-4),
)
PG = {"atmosphere": isa(3000.0), "compressibility": "prandtl-glauert"}
FLIGHT = [
    ("g", G, {"density": 1.225}, ["damping.g", "segments[0].a", "control_surfaces[0].hinge"]),
    ("zetas", ZETAS, {"density": 1.225}, ["damping.ratio[1]", "segments[0].semichord"]),
    ("rayleigh", RAYLEIGH, {"density": 1.225}, ["damping.beta", "control_surfaces[0].GJ"]),
    ("mach", None, {"density": 1.225, "mach": 0.4}, ["mach", "segments[0].a", "density"]),
    ("altitude", None, {"atmosphere": isa(3000.0)}, ["altitude", "segments[0].GJ"]),
    ("matched", None, PG, ["altitude", "segments[0].a", "density", "segments[0].EI"]),
    ("matched_g", G, PG, ["damping.g", "altitude", "control_surfaces[0].hinge"]),
]


@pytest.mark.parametrize(
    "damping,flight,names", [c[1:] for c in FLIGHT], ids=[c[0] for c in FLIGHT]
)
def test_damping_and_flight_against_central_differences(damping, flight, names):
    """Damped models (structural g, modal ratios, Rayleigh), a fixed Mach number, a standard
    atmosphere, and the Prandtl-Glauert correction at the matched Mach number (total derivative
    in the speed): analytic derivatives of V_f, f_f and V_d against central differences of the
    engine's own analyses (Goland with aileron)."""
    wing = goland_aileron()
    model = aes.AeroelasticModel(wing, damping=damping)
    kw = {k: v for k, v in flight.items() if k != "density"}
    s = flutter_sensitivities(model, flight.get("density"), names, rtol=RTOL, **kw)
    assert s.matched == ("compressibility" in flight) and s.non_differentiable is None
    for name in names:
        x = s.values[name]
        h = 1.0 if name == "altitude" else STEP * abs(x)
        p, m = (_analysis(wing, damping, flight, name, x + t) for t in (h, -h))
        for attr, d in (
            ("flutter_speed", s.d_flutter_speed),
            ("flutter_frequency", s.d_flutter_frequency),
            ("divergence_speed", s.d_divergence_speed),
        ):
            ref = (getattr(p, attr) - getattr(m, attr)) / (2 * h)
            _check(d[name], ref, x, getattr(s, attr), f"{name} d{attr}")


def test_one_boundary_for_all_parameters(monkeypatch):
    """All derivatives cost one flutter boundary (never one per parameter)."""
    import aeroservo.stability.boundary as boundary

    calls = []
    original = boundary.flutter_boundary
    monkeypatch.setattr(
        boundary, "flutter_boundary", lambda *a, **k: calls.append(1) or original(*a, **k)
    )
    s = flutter_sensitivities(aes.AeroelasticModel(goland_aileron()), 1.225)
    assert len(s.values) == len(parameter_values(goland_aileron())) + 1
    assert set(s.d_flutter_speed) | set(s.undefined) == set(s.values)
    assert len(s.undefined) == 2  # the two actuators sit on mesh nodes
    assert len(calls) == 1


def test_mode_switch_is_reported_not_differentiated():
    """Two branches going unstable at nearly the same speed: no derivative, a reason."""
    model = aes.AeroelasticModel(goland())
    r = aes.flutter_boundary(model, 1.225)
    f = r.flutter
    other = Crossing(f.speed * (1 + 1e-4), f.frequency * 2, f.mode + 1, "onset")
    r.crossings = sorted([*r.crossings, other], key=lambda c: c.speed)
    s = flutter_sensitivities(model, 1.225, result=r)
    assert s.non_differentiable and "mode switch" in s.non_differentiable
    assert s.d_flutter_speed == {} and s.to_dict()["non_differentiable"]


def test_normalized_and_dict():
    s = flutter_sensitivities(aes.AeroelasticModel(goland()), 1.225, ["segments[0].GJ", "density"])
    n = s.normalized()
    assert set(n) == {"segments[0].GJ", "density"}
    assert n["segments[0].GJ"] == pytest.approx(
        0.99e6 * s.d_flutter_speed["segments[0].GJ"] / s.flutter_speed
    )
    d = s.to_dict()
    assert d["d_flutter_speed"].keys() == n.keys() and d["units"]


@pytest.mark.parametrize(
    "kwargs,fragment",
    [
        ({"parameters": ["segments[3].GJ"]}, "'segments[3].GJ' is not a parameter"),
        ({"parameters": "density"}, "expected a list"),
        ({"density": None}, "density = None"),
        ({"density": None, "atmosphere": isa(3000.0), "mach": 0.5}, "mach with an atmosphere"),
        ({"atmosphere": isa(3000.0)}, "density and atmosphere"),
        ({"compressibility": "prandtl-glauert"}, "needs the speed of sound"),
    ],
)
def test_bad_arguments(kwargs, fragment):
    kw = {"density": 1.225, **kwargs}
    with pytest.raises(InputError, match=fragment.replace("[", r"\[").replace("]", r"\]")):
        flutter_sensitivities(aes.AeroelasticModel(goland()), **kw)
    with pytest.raises(InputError, match="expected an aeroservo.AeroelasticModel"):
        flutter_sensitivities(goland(), 1.225)


# -- the command line ---------------------------------------------------------------------------
def test_cli_json_and_plot(tmp_path, capsys):
    import json

    from aeroservo.cli import main

    png = tmp_path / "s.png"
    assert main(["sensitivity", "goland_aileron", "--json", "--plot", str(png)]) == 0
    out = json.loads(capsys.readouterr().out)
    ref = flutter_sensitivities(aes.AeroelasticModel(goland_aileron()), 1.225)
    assert out["d_flutter_speed"].keys() == ref.d_flutter_speed.keys()
    for k, v in ref.d_flutter_speed.items():
        assert out["d_flutter_speed"][k] == pytest.approx(v, rel=1e-6)
    assert "control_surfaces[0].actuators[1].stiffness" in out["normalized_flutter_speed"]
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert main(["sensitivity", "goland"]) == 0
    assert "segments[0].GJ" in capsys.readouterr().out


@pytest.mark.parametrize(
    "argv,fragment",
    [
        (["sensitivity", "goland", "--plot", "s.foo"], "'foo'"),
        (["sensitivity", "goland", "--density", "9"], "--density"),
        (["sensitivity", "goland", "--top", "0"], "--top = 0"),
        (["sensitivity", "goland", "--compressibility", "prandtl-glauert"], "speed of sound"),
    ],
)
def test_cli_bad_input(argv, fragment, tmp_path, monkeypatch, capsys):
    from aeroservo.cli import main

    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and fragment in err[0]
    assert list(tmp_path.iterdir()) == []


# -- closed loop: central differences of a trade case (documented as such) -----------------------
def test_closed_loop_case_sensitivities():
    """The shipped trade study's middle case (LQR, Bryson 500 N m): derivatives of the
    closed-loop flutter speed by central differences with two steps agree (1e-3 relative),
    so the step is in the flat region between truncation and boundary noise."""
    from conftest import ROOT

    from aeroservo.files import load_scenario
    from aeroservo.studies.runs import study_from_scenario
    from aeroservo.studies.trade.sensitivity import case_sensitivities

    study = study_from_scenario(load_scenario(ROOT / "scenarios" / "trade_aileron.toml"))
    case = {"aileron_start": 0.6, "aileron_chord": 0.2, "bryson_hinge_moment": 500.0}
    a = case_sensitivities(study, case, ["aileron_chord", "bryson_hinge_moment"], rel_step=1e-3)
    b = case_sensitivities(study, case, ["aileron_chord", "bryson_hinge_moment"], rel_step=3e-4)
    assert a.case["closed_loop_flutter_speed"] > a.case["open_loop_flutter_speed"]
    da, db = a.derivatives["closed_loop_flutter_speed"], b.derivatives["closed_loop_flutter_speed"]
    assert set(da) == {"aileron_chord", "bryson_hinge_moment"} and not a.unavailable
    for k in da:
        assert da[k] == pytest.approx(db[k], rel=1e-3)
    assert "finite differences" in a.to_dict()["method"]
    with pytest.raises(InputError, match="'hinge_stiffness' is not a parameter"):
        case_sensitivities(study, case, ["hinge_stiffness"])


@pytest.mark.parametrize("compressibility", [None, "prandtl-glauert"])
def test_altitude_at_a_layer_top_has_two_one_sided_derivatives(compressibility):
    """At 11 km (tropopause) the lapse rate changes: no altitude derivative, but the one-sided
    ones below and above, each equal to the one-sided difference of the engine's analyses."""
    from aeroservo.stability.matched import flutter_at

    model = aes.AeroelasticModel(goland_aileron())
    s = flutter_sensitivities(
        model,
        atmosphere=isa(11000.0),
        compressibility=compressibility,
        rtol=RTOL,
        parameters=["altitude", "density"],
    )
    assert "altitude" not in s.d_flutter_speed and "density" in s.d_flutter_speed
    why = s.undefined["altitude"]
    assert "layer" in why and "below" in why and "above" in why
    v = {
        h: flutter_at(model, isa(h), compressibility=compressibility, rtol=RTOL).flutter_speed
        for h in (10999.0, 11000.0, 11001.0)
    }
    got = [float(t.split()[0]) for t in why.split("dV_f/dp = ")[1].split(";")[0].split(", ")]
    for g, ref in zip(got, (v[11000.0] - v[10999.0], v[11001.0] - v[11000.0]), strict=True):
        assert g == pytest.approx(ref, rel=1e-3)  # one-sided differences: O(h) truncation
    assert got[1] > 1.1 * got[0]


def test_actuator_at_a_surface_end_is_one_sided():
    """A station on its surface's end can only move inwards: one inward derivative, named."""
    wing = goland_aileron()
    name = "control_surfaces[0].actuators[1].station"
    wing = with_parameters(wing, {name: wing.control_surfaces[0].end})
    s = flutter_sensitivities(aes.AeroelasticModel(wing), 1.225, [name])
    assert "end of its control surface" in s.undefined[name] and "inward" in s.undefined[name]
    assert "outboard" not in s.undefined[name]


@pytest.mark.slow
def test_damped_modes_at_rest_on_an_exact_eigenvalue():
    """Rayleigh damping on a corpus wing where the Rayleigh-quotient iteration lands on the
    eigenvalue exactly (a singular solve, found by review): the pair is returned."""
    case = {c.name: c for c in shared_corpus()}["two_flaps_04"]
    a = case.model.wing.segments[0].a
    wing = with_parameters(case.model.wing, {"segments[0].a": a - 1e-5 * abs(a)})
    damping = StructuralDamping.rayleigh(0.200002, 1e-4)
    model = aes.AeroelasticModel(wing, n_elements=case.model.n_elements, damping=damping)
    lam, X = model.system(case.density).modes_at_rest(6)
    assert np.all(np.isfinite(lam)) and np.all(lam.real < 0)
    s = flutter_sensitivities(model, case.density, ["density"], v_max=case.v_max)
    assert s.flutter_speed is None or "density" in s.d_flutter_speed
