"""Swept wings by the modified strip theory (issue 27, item 2; docs/sweep.md).

Independent references, written here and not taken from the code under test:

* Divergence of a uniform (or cranked) swept cantilever, strip theory with the effective
  incidence ``phi - tan(Lambda) w'`` (the closed form's assumptions: Diederich & Budiansky,
  NACA TN 1680 (1948); Bisplinghoff, Ashley & Halfman, "Aeroelasticity" (1955), sec. 8-4;
  Hodges & Pierce, "Introduction to Structural Dynamics and Aeroelasticity" (2011), ch. 4), with
  section properties normal to the elastic axis and y along it:

      GJ phi'' + e q c a0 cos^2(Lambda) (phi - tan(Lambda) w') = 0
      EI w''''  =  q c a0 cos^2(Lambda) (phi - tan(Lambda) w')

  phi(0) = w(0) = w'(0) = 0, phi'(l) = w''(l) = w'''(l) = 0; a0 = 2 pi, c = 2 b and
  e = b (a + 1/2) the distance of the aerodynamic centre (quarter chord) ahead of the elastic
  axis. Solved exactly by the transfer matrix expm(A l) of the first-order system and a root of
  the determinant of the free-end conditions (no discretization). Its two classical limits are
  checked: pure torsion, ``q e c a0 l^2 / GJ = pi^2 / 4``, and the bending divergence of a
  forward-swept wing with the elastic axis at the quarter chord,
  ``q c a0 l^3 sin(Lambda) cos(Lambda) / EI = -6.33`` (Diederich & Budiansky).
* The tip deflection of a cranked cantilever under a tip force, by the unit-load method.
"""

from __future__ import annotations

import tomllib
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg as sla
import scipy.optimize as so

from aeroservo.errors import InputError
from aeroservo.files.wing_file import load_wing, wing_from_dict, wing_toml
from aeroservo.stability.boundary import flutter_boundary
from aeroservo.stability.divergence import divergence_speeds
from aeroservo.structure.examples import goland, goland_aileron, goland_swept
from aeroservo.structure.wing import Segment, Wing
from aeroservo.system import swept_assembly
from aeroservo.system.aeroelastic import AeroelasticModel

RHO = 1.225
A0 = 2 * np.pi


# -- the independent reference ----------------------------------------------------------------


def _segment_matrix(k: float, t: float, e: float, EI: float, GJ: float) -> np.ndarray:
    """First-order system of ``y = [phi, phi', w, w', w'', w''']`` on a uniform swept piece,
    ``k = q c a0 cos^2(Lambda)``, ``t = tan(Lambda)``."""
    A = np.zeros((6, 6))
    A[0, 1] = A[2, 3] = A[3, 4] = A[4, 5] = 1.0
    A[1, 0], A[1, 3] = -e * k / GJ, e * k * t / GJ
    A[5, 0], A[5, 3] = k / EI, -k * t / EI
    return A


def _crank(d: float, s1: dict, s2: dict) -> np.ndarray:
    """``y`` across a crank where the sweep grows by ``d``: w and the shear EI w''' continuous;
    the rotation vector (w' about the in-plane normal, phi about the axis) and the moment vector
    (EI w'', GJ phi') turn by d."""
    c, s = np.cos(d), np.sin(d)
    J = np.zeros((6, 6))
    J[2, 2] = 1.0
    J[3, 3], J[3, 0] = c, -s  # w'
    J[0, 3], J[0, 0] = s, c  # phi
    J[4, 4], J[4, 1] = c * s1["EI"] / s2["EI"], -s * s1["GJ"] / s2["EI"]  # EI w''
    J[1, 4], J[1, 1] = s * s1["EI"] / s2["GJ"], c * s1["GJ"] / s2["GJ"]  # GJ phi'
    J[5, 5] = s1["EI"] / s2["EI"]
    return J


def _free_end_det(q: float, pieces: list[dict]) -> float:
    P = np.eye(6)
    for i, p in enumerate(pieces):
        if i:
            P = _crank(p["sweep"] - pieces[i - 1]["sweep"], pieces[i - 1], p) @ P
        lam = p["sweep"]
        k = q * 2 * p["b"] * A0 * np.cos(lam) ** 2
        A = _segment_matrix(k, np.tan(lam), p["b"] * (p["a"] + 0.5), p["EI"], p["GJ"])
        P = sla.expm(A * p["length"]) @ P
    free = [1, 4, 5]  # phi'(0), w''(0), w'''(0) unknown; phi', w'', w''' vanish at the tip
    return float(np.linalg.det(P[np.ix_(free, free)]))


def reference_divergence_q(pieces: list[dict], q_hi: float) -> float | None:
    """Lowest divergence dynamic pressure [Pa] below q_hi (None if none)."""
    qs = np.geomspace(q_hi * 1e-4, q_hi, 600)
    d = np.array([_free_end_det(q, pieces) for q in qs])
    i = np.flatnonzero(np.sign(d[:-1]) != np.sign(d[1:]))
    if i.size == 0:
        return None
    return so.brentq(_free_end_det, qs[i[0]], qs[i[0] + 1], args=(pieces,), xtol=1e-14, rtol=1e-13)


def test_reference_reproduces_the_classical_limits():
    # pure torsion: q e c a0 l^2 / GJ = pi^2 / 4
    p = {"b": 0.5, "a": 0.0, "EI": 1.0, "GJ": 1.0, "length": 1.0, "sweep": 0.0}
    q = reference_divergence_q([p], 10.0)
    assert q * 0.25 * 1.0 * A0 == pytest.approx(np.pi**2 / 4, rel=1e-10)
    # forward sweep, elastic axis at the quarter chord: q c a0 l^3 sin cos / EI = -6.33 (D & B)
    p = {"b": 0.5, "a": -0.5, "EI": 1.0, "GJ": 1.0, "length": 1.0, "sweep": -np.pi / 4}
    q = reference_divergence_q([p], 100.0)
    assert q * A0 * np.sin(p["sweep"]) * np.cos(p["sweep"]) == pytest.approx(-6.33, abs=5e-3)


# -- wings --------------------------------------------------------------------------------------


def _swept(wing: Wing, sweep: float) -> Wing:
    return replace(wing, segments=tuple(replace(s, sweep=sweep) for s in wing.segments))


def _pieces(wing: Wing) -> list[dict]:
    return [
        {"b": s.semichord, "a": s.a, "EI": s.EI, "GJ": s.GJ, "length": s.end - s.start}
        | {"sweep": s.sweep}
        for s in wing.segments
    ]


def _q_div(wing: Wing, n: int, terms: str = "classical") -> float | None:
    v = divergence_speeds(AeroelasticModel(wing, n, sweep_terms=terms).system(RHO))
    return 0.5 * RHO * v[0] ** 2 if v.size else None


def _uniform(a: float = -0.2, **kw) -> Wing:
    seg = Segment(0.0, 6.0, 0.9, a, 35.0, 0.2, 8.6, 9.8e6, 1.0e6, **kw)
    return Wing(span=6.0, segments=(seg,))


# -- zero sweep: today's model to the last bit ---------------------------------------------------


def _arrays(model: AeroelasticModel) -> dict:
    am = model.matrices
    out = {k: getattr(am, k).toarray() for k in ("Ms", "Ks", "Mnc", "Cnc", "Knc", "Lz1", "E1")}
    out.update({k: getattr(am, k).toarray() for k in ("F1", "W1", "Mz1")})
    for i, g in enumerate(am.circ_groups):
        out.update({f"Pq{i}": g.Pq.toarray(), f"Pd{i}": g.Pd.toarray(), f"Gw{i}": g.Gw})
        out[f"b{i}"] = np.array(g.b)
    for k, m in am.root.__dict__.items():
        if hasattr(m, "toarray"):
            out[f"root {k}"] = m.toarray()
    s = model.system(RHO)
    out.update(A0=s.A0.toarray(), A1=s.A1.toarray(), A2=s.A2.toarray(), E=s.E.toarray())
    out["K_static"] = s.K_static
    out["flutter"] = np.array([c.speed for c in flutter_boundary(model, RHO).crossings])
    return out


@pytest.mark.parametrize("make", [goland, goland_aileron], ids=["goland", "goland_aileron"])
@pytest.mark.parametrize("terms", ["full", "classical"])
def test_zero_sweep_is_bit_for_bit(make, terms, monkeypatch):
    """The modified-strip path at zero sweep (forced) gives exactly the unswept arrays and
    flutter speeds (==, not approx): cos 0 = 1 and sin 0 = 0 enter as exact factors."""
    plain = _arrays(AeroelasticModel(make(), 12))
    explicit = _arrays(AeroelasticModel(_swept(make(), 0.0), 12, sweep_terms=terms))
    monkeypatch.setattr(swept_assembly, "_is_swept", lambda sweep: True)
    forced = _arrays(AeroelasticModel(make(), 12, sweep_terms=terms))
    assert plain.keys() == forced.keys() == explicit.keys()
    for k in plain:
        assert plain[k].shape == forced[k].shape
        assert np.array_equal(plain[k], forced[k]), k
        assert np.array_equal(plain[k], explicit[k]), k
    assert plain["flutter"].size >= 2  # flutter and divergence were found and compared


# -- divergence against the closed form ---------------------------------------------------------


@pytest.mark.parametrize("deg", [-30.0, -15.0, -5.0, 5.0, 15.0, 25.0])
def test_divergence_matches_the_closed_form(deg):
    """Classical terms (the closed form's assumptions), forward and backward sweep. The lag
    fields are linear per element and the bending slope w' quadratic: its projection converges
    as h^2, so 80 elements agree to about 1e-4 (checked: the error falls 4x per halving)."""
    wing = _swept(_uniform(), np.deg2rad(deg))
    ref = reference_divergence_q(_pieces(wing), 1e7)
    assert ref is not None
    q40, q80 = _q_div(wing, 40), _q_div(wing, 80)
    assert q80 == pytest.approx(ref, rel=3e-4)
    assert abs(q80 - ref) < 0.4 * abs(q40 - ref) + 1e-9 * ref  # converging, second order


def test_cranked_divergence_matches_the_closed_form():
    """A cranked wing (unswept inboard, swept back outboard, different stiffnesses): the crank
    turns bending slope into twist; reference with the crank's transfer matrix."""
    inner = Segment(0.0, 2.5, 0.9, -0.2, 35.0, 0.2, 8.6, 1.6e7, 1.5e6)
    outer = Segment(2.5, 6.0, 0.7, -0.25, 30.0, 0.2, 6.0, 8.0e6, 0.8e6, sweep=np.deg2rad(-20))
    wing = Wing(span=6.0, segments=(inner, outer))
    ref = reference_divergence_q(_pieces(wing), 1e7)
    assert _q_div(wing, 80) == pytest.approx(ref, rel=3e-4)
    # without the crank's coupling (the same sweep everywhere) the answer is another one
    straight = Wing(span=6.0, segments=(replace(inner, sweep=outer.sweep), outer))
    assert abs(_q_div(straight, 80) / ref - 1) > 0.02


def test_cranked_tip_deflection_by_the_unit_load_method():
    """Static tip deflection of a cranked cantilever under a unit tip force: bending and
    torsion of the inboard piece both contribute (moment of the force about the inboard axes)."""
    l1, l2, d = 2.5, 3.5, np.deg2rad(35.0)
    EI1, GJ1, EI2, GJ2 = 1.6e7, 1.5e6, 8.0e6, 0.8e6
    inner = Segment(0.0, l1, 0.9, -0.2, 35.0, 0.2, 8.6, EI1, GJ1)
    outer = Segment(l1, l1 + l2, 0.7, -0.25, 30.0, 0.2, 6.0, EI2, GJ2, sweep=d)
    model = AeroelasticModel(Wing(span=l1 + l2, segments=(inner, outer)), 6)
    f = np.zeros(model.n_dofs)
    f[model.mesh.dof_w[-1]] = 1.0
    q = np.linalg.solve(model.matrices.Ks.toarray(), f)
    # unit-load method: outboard piece a cantilever of length l2; on the inboard piece at
    # distance u from the crank, the tip lies l2 cos d + u along its axis and l2 sin d aft
    w_ref = l2**3 / (3 * EI2) + ((l2 * np.cos(d)) ** 2 * l1 + l2 * np.cos(d) * l1**2) / EI1
    w_ref += l1**3 / (3 * EI1) + (l2 * np.sin(d)) ** 2 * l1 / GJ1
    assert q[model.mesh.dof_w[-1]] == pytest.approx(w_ref, rel=1e-9)


# -- trends on a randomized set -----------------------------------------------------------------


def test_sweep_back_raises_and_forward_sweep_lowers_divergence():
    """Random uniform wings with a divergence (elastic axis aft of the quarter chord). The
    bending-torsion coupling is first order in the sweep, the cos^2 of the normal flow second
    order, so the trend holds for moderate sweep; a wing much stiffer in bending than in torsion
    can diverge later again at large forward sweep (docs/sweep.md)."""
    rng = np.random.default_rng(27)
    for _ in range(6):
        b = rng.uniform(0.4, 1.2)
        seg = Segment(
            0.0,
            rng.uniform(4.0, 10.0),
            b,
            rng.uniform(-0.45, -0.05),  # elastic axis aft of the quarter chord: divergence
            rng.uniform(20.0, 60.0),
            0.1,
            rng.uniform(4.0, 12.0),
            rng.uniform(3e6, 3e7),
            rng.uniform(5e5, 3e6),
        )
        wing = Wing(span=seg.end, segments=(seg,))
        for terms in ("classical", "full"):
            q0 = _q_div(wing, 20, terms)
            for deg in rng.uniform(3.0, 15.0, 2):  # first order in the sweep: the coupling
                lam = np.deg2rad(deg)
                back = _q_div(_swept(wing, lam), 20, terms)
                fwd = _q_div(_swept(wing, -lam), 20, terms)
                assert back is None or back > q0, (terms, deg)
                assert fwd < q0, (terms, deg)


# -- the gradient terms, the example, the files, bad input --------------------------------------


def test_twist_gradient_terms_move_a_swept_goland_by_several_percent():
    """docs/sweep.md quotes these numbers (20 elements, sea level)."""
    wing = goland_swept(np.deg2rad(15.0))
    full, classical = (AeroelasticModel(wing, 20, sweep_terms=t) for t in ("full", "classical"))
    v_div = [divergence_speeds(m.system(RHO))[0] for m in (full, classical)]
    v_f = [flutter_boundary(m, RHO).flutter_speed for m in (full, classical)]
    assert 0.02 < 1 - v_div[0] / v_div[1] < 0.08  # the twist gradient lowers it (sweep-back)
    assert 0.003 < abs(v_f[0] / v_f[1] - 1) < 0.05


def test_shipped_swept_example_and_round_trip(tmp_path):
    wing, _ = load_wing(Path(__file__).parents[1] / "scenarios" / "goland_swept.toml")
    builtin = goland_swept().segments[0]
    assert wing.segments == (replace(builtin, name=wing.segments[0].name),)
    back = wing_from_dict(tomllib.loads(wing_toml(wing))["wing"])
    assert back.segments[0].sweep == wing.segments[0].sweep == np.pi / 6
    deg = wing_from_dict(
        {"span": 6.0, "segments": [_table(_uniform()) | {"sweep_deg": -20.0}]}
    ).segments[0]
    assert deg.sweep == np.deg2rad(-20.0)


def _table(wing: Wing) -> dict:
    s = wing.segments[0]
    keys = ("start", "end", "semichord", "a", "mass", "x_alpha", "inertia", "EI", "GJ")
    return {k: getattr(s, k) for k in keys}


@pytest.mark.parametrize(
    "extra, match",
    [
        ({"sweep": 1.2}, r"sweep = 1.2 rad \(68.75 deg\): allowed range .*normal to the elastic"),
        ({"sweep": -30.0}, r"sweep = -30 rad .*unit error"),
        ({"sweep_deg": 61.0}, r"sweep_deg = 61 deg: allowed range is \[-60, 60\] deg"),
        ({"sweep": 0.1, "sweep_deg": 5.0}, r"give sweep \[rad\] or sweep_deg"),
        ({"sweep": "30"}, r"sweep = '30'"),
    ],
)
def test_bad_sweep_is_one_clear_line(extra, match):
    with pytest.raises(InputError, match=match) as exc:
        wing_from_dict({"span": 6.0, "segments": [_table(_uniform()) | extra]})
    assert "\n" not in str(exc.value) and "segments[0]" in str(exc.value)


def test_sweep_limit_in_python():
    with pytest.raises(InputError, match="modified strip method"):
        _uniform(sweep=-np.deg2rad(65.0))
    assert _uniform(sweep=-1.0472).segments[0].sweep == -np.pi / 3  # 60 deg to 4 decimals: accepted
    with pytest.raises(InputError, match="sweep_terms"):
        AeroelasticModel(_uniform(), 4, sweep_terms="all")


def test_sensitivities_of_a_cranked_swept_wing_match_central_differences():
    """The analytic derivatives (system/derivatives.py) carry the swept strips and the crank."""
    from aeroservo.stability.sensitivity import flutter_sensitivities

    inner = Segment(0.0, 2.5, 0.9, -0.2, 35.0, 0.2, 8.6, 1.6e7, 1.5e6)
    outer = Segment(2.5, 6.0, 0.8, -0.25, 30.0, 0.2, 6.0, 8.0e6, 0.8e6, sweep=np.deg2rad(25))

    def model(**kw):
        return AeroelasticModel(Wing(span=6.0, segments=(inner, replace(outer, **kw))), 16)

    names = ["segments[1].GJ", "segments[1].a"]
    s = flutter_sensitivities(model(), RHO, names)
    for key, h in (("GJ", 1e2), ("a", 1e-5)):
        v = getattr(outer, key)
        r = [flutter_boundary(model(**{key: v + d}), RHO, rtol=1e-11) for d in (h, -h)]
        fd_flutter = (r[0].flutter_speed - r[1].flutter_speed) / (2 * h)
        div = [divergence_speeds(model(**{key: v + d}).system(RHO))[0] for d in (h, -h)]
        assert s.d_flutter_speed[f"segments[1].{key}"] == pytest.approx(fd_flutter, rel=1e-6)
        assert s.d_divergence_speed[f"segments[1].{key}"] == pytest.approx(
            (div[0] - div[1]) / (2 * h), rel=1e-6
        )
