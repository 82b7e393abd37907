"""Named cases for the stability engine's edges: past divergence, low density, round-off in the
divergence, sliver elements, soft flaps, a search that cannot go on.

Reference data: ``tests/data/reference_cases.json`` (cases ``typical_section_Fung`` and
``hale_patil_hodges_cesnik``, source and confidence in that file).
"""

import dataclasses

import numpy as np
import pytest
import scipy.linalg as sla
from conftest import reference

import aeroservo as aes
from aeroservo.stability import pk_flutter
from aeroservo.stability.modal import modal_basis
from aeroservo.system import TypicalSection

FUNG = reference("typical_section_Fung")
HALE = reference("hale_patil_hodges_cesnik")


def fung_section(wagner="rt_jones") -> TypicalSection:
    p = FUNG["inputs"]
    return TypicalSection.from_nondimensional(
        semichord=p["b_m"],
        a=p["a"],
        mu=p["mu"],
        x_alpha=p["x_alpha"],
        r_alpha2=p["r_alpha"] ** 2,
        omega_h=p["omega_h_rad_s"],
        omega_alpha=p["omega_alpha_rad_s"],
        density=1.225,
        wagner=wagner,
    )


def hale_wing(aileron: bool = False) -> aes.Wing:
    p = HALE["inputs"]
    b = 0.5 * p["chord_m"]
    seg = aes.Segment(
        0.0,
        p["semi_span_m"],
        b,
        2 * p["elastic_axis_frac_chord"] - 1,  # a = 0: mid-chord
        p["mass_kg_per_m"],
        0.0,  # CG on the elastic axis
        p["I_alpha_kg_m"],
        p["EI_flap_N_m2"],
        p["GJ_N_m2"],
    )
    surfaces = ()
    if aileron:  # aeroservo's own choice: an aileron on the outer quarter span
        surfaces = (
            aes.ControlSurface(
                "aileron", 12.0, 16.0, 0.6, 0.002, 0.0005, GJ=10.0, hinge_stiffness=20.0
            ),
        )
    return aes.Wing(p["semi_span_m"], (seg,), surfaces, name="HALE")


def bw() -> float:
    p = FUNG["inputs"]
    return p["b_m"] * p["omega_alpha_rad_s"]


def test_fung_section_default_range_passes_divergence():
    """Fung's section: the default range (1.2 x divergence) used to crash past divergence."""
    r = aes.flutter_boundary(fung_section(), 1.225)
    assert r.complete and r.v_max > r.divergence_speed
    exp = FUNG["expected"]
    tol = FUNG["tolerance"]["rel_same_model"]
    assert r.flutter_speed / bw() == pytest.approx(
        exp["RTJones"]["U_F_over_b_omega_alpha"], rel=tol
    )
    assert r.divergence_speed / bw() == pytest.approx(
        exp["divergence"]["U_D_over_b_omega_alpha"], rel=tol
    )
    kinds = [c.kind for c in r.crossings]
    assert "divergence" in kinds and kinds[0] == "onset"


def test_fung_section_pk_exact():
    r = pk_flutter(fung_section(), 1.225)
    exp = FUNG["expected"]["exact_Theodorsen"]
    assert r.flutter_speed / bw() == pytest.approx(exp["U_F_over_b_omega_alpha"], rel=2e-3)


def test_flutter_above_divergence_is_found():
    """A section whose divergence comes first: flutter above it is still found and agrees with
    the dense eigenvalues (a complex pair crossing, not the divergent real root)."""
    sec = TypicalSection.from_nondimensional(
        semichord=0.5,
        a=0.2,
        mu=5,
        x_alpha=0.05,
        r_alpha2=0.25,
        omega_h=55.0,
        omega_alpha=60.0,
        density=1.225,
    )
    r = aes.flutter_boundary(sec, 1.225, v_max=150.0)
    assert r.complete
    vd, vf = r.divergence_speed, r.flutter_speed
    assert vd is not None and vf is not None and vd < vf

    def max_osc(v):
        ev = sla.eigvals(sec.system(1.225).state_matrix(v))
        return ev[ev.imag > 1e-6 * np.abs(ev)].real.max()

    assert max_osc(vf * (1 - 1e-5)) < 0 < max_osc(vf * (1 + 1e-5))


@pytest.mark.parametrize("density, key", [(0.0889, "strip_theory_this_model_C")])
def test_hale_wing(density, key):
    """Patil-Hodges-Cesnik HALE wing at 20 km, strip-theory values of this model [C]."""
    m = aes.AeroelasticModel(hale_wing(), 16)
    r = aes.flutter_boundary(m, density)
    exp = HALE["expected"][key]
    tol = HALE["tolerance"]["rel_same_model"]
    assert r.flutter_speed == pytest.approx(exp["jones_td_flutter_speed_m_s"], rel=tol)
    assert r.divergence_speed == pytest.approx(exp["divergence_speed_m_s"], rel=tol)
    pk = pk_flutter(m, density)
    assert pk.flutter_speed == pytest.approx(exp["pk_exact_flutter_speed_m_s"], rel=tol)
    assert pk.flutter_frequency == pytest.approx(exp["pk_exact_frequency_hz"], rel=tol)
    pub = HALE["expected"]["published"]
    assert r.flutter_speed == pytest.approx(
        pub["flutter_speed_m_s"], rel=HALE["tolerance"]["rel_published"]
    )


def test_hale_with_aileron_at_sea_level_does_not_crash():
    """The issue's example: sea level, --v-max 40, aileron on the outer quarter (it used to fail
    near 32.2 m/s). Every crossing agrees with the dense eigenvalues."""
    m = aes.AeroelasticModel(hale_wing(aileron=True), 16)
    r = aes.flutter_boundary(m, 1.225, v_max=40.0)
    assert r.complete and r.warnings == []
    for c in r.crossings:
        ev_lo = sla.eigvals(m.state_matrix(c.speed * (1 - 1e-5), 1.225))
        ev_hi = sla.eigvals(m.state_matrix(c.speed * (1 + 1e-5), 1.225))
        if c.kind == "divergence":
            real = [ev[np.abs(ev.imag) <= 1e-9 * np.abs(ev)].real for ev in (ev_lo, ev_hi)]
            assert np.sum(real[0] > 0) != np.sum(real[1] > 0)
        else:
            osc = [np.sum(ev[ev.imag > 1e-6 * np.abs(ev)].real > 0) for ev in (ev_lo, ev_hi)]
            assert osc[1] - osc[0] == (1 if c.kind == "onset" else -1)


def test_no_divergence_with_elastic_axis_ahead_of_quarter_chord():
    """Round-off must not report a divergence (it used to give ~1e9 m/s and an absurd range)."""
    seg = aes.Segment(0, 6, 0.5, -0.6, 30, 0.3, 5, 1e6, 1e5)
    m = aes.AeroelasticModel(aes.Wing(6, (seg,)), 10)
    assert aes.divergence_speed(m.system(1.225)) is None
    r = aes.flutter_boundary(m, 1.225)
    assert r.divergence_speed is None and r.complete
    assert r.v_max < 1e3  # 4 b omega_2, printed:
    assert f"0 .. {r.v_max:.4g} m/s" in r.summary()
    assert r.to_dict()["searched_range"] == [0.0, r.v_max]
    pk = pk_flutter(m, 1.225)
    assert pk.divergence_speed is None and pk.v_max < 1e3


@pytest.mark.parametrize("gap", [1e-3, 3e-9])
def test_surface_ending_just_short_of_the_tip(gap):
    """An aileron 1 mm (or a few nm) short of the tip: the edge is merged with the tip (a warning
    says so), no sliver element, the same answer as the aileron ending at the tip."""
    wing = aes.examples.goland_aileron()
    cs = wing.control_surfaces[0]
    short = dataclasses.replace(
        wing, control_surfaces=(dataclasses.replace(cs, end=wing.span - gap),)
    )
    m_ref = aes.AeroelasticModel(wing, 10)
    m = aes.AeroelasticModel(short, 10)
    assert np.diff(m.mesh.nodes).min() > 0.1
    r, r_ref = aes.flutter_boundary(m, 1.225), aes.flutter_boundary(m_ref, 1.225)
    assert r.flutter_speed == pytest.approx(r_ref.flutter_speed, rel=1e-9)
    if gap > 1e-6:
        assert any("moved to 6.096 m" in w for w in r.warnings)


def test_segment_edge_a_few_nanometres_from_the_tip():
    base = aes.examples.goland().segments[0]
    a = dataclasses.replace(base, end=6.096 - 4e-9, name="a")
    b = dataclasses.replace(base, start=6.096 - 4e-9, end=6.096, name="b")
    m = aes.AeroelasticModel(aes.Wing(6.096, (a, b)), 10)
    assert m.mesh.n_elements == 10 and np.diff(m.mesh.nodes).min() > 0.5
    r = aes.flutter_boundary(m, 1.225)
    assert r.flutter_speed == pytest.approx(137.839, rel=1e-4)


def test_mode_rule_covers_soft_flaps():
    """Soft flaps: the modes kept cover the flap modes and the bending/torsion modes around
    them, whatever the count (the old fixed 8 lowest modes missed a 2nd-bending/flap flutter)."""
    wing = aes.examples.goland_aileron(actuator_stiffness=300.0, hinge_stiffness=50.0)
    m = aes.AeroelasticModel(wing, 10)
    basis = modal_basis(m)
    flap = [f for f, lab in zip(basis.frequencies, basis.labels, strict=True) if "flap" in lab]
    assert flap and basis.frequencies.max() >= 2 * flap[0] * 0.9
    assert any("2nd bending" in lab for lab in basis.labels)


def test_result_when_the_search_cannot_go_on(monkeypatch, capsys):
    """A sweep that cannot continue returns what it found below, with searched_up_to and a
    warning; the command line exits 0 and prints the warning on stderr."""
    import aeroservo.stability.boundary as boundary
    from aeroservo import cli

    m = aes.AeroelasticModel(aes.examples.goland(), 10)
    r_full = aes.flutter_boundary(m, 1.225)
    real = boundary.sweep_branches

    def stops_at_200(system, lam0, X0, v_max, *, forced=(), **kw):
        """The sweep as it ends when dense eig returns non-finite values above 200 m/s."""
        br = real(system, lam0, X0, 200.0, forced=[v for v in forced if v < 200.0], **kw)
        br.stopped = "non-finite eigenvalues at 201 m/s"
        return br

    monkeypatch.setattr(boundary, "sweep_branches", stops_at_200)
    r = aes.flutter_boundary(m, 1.225)
    assert not r.complete and r.searched_up_to == pytest.approx(200.0)
    assert r.flutter_speed == pytest.approx(r_full.flutter_speed, rel=1e-9)
    assert [c.kind for c in r.crossings] == ["onset"]  # divergence (253 m/s) not reached
    assert any("search stopped" in w for w in r.warnings)
    assert r.to_dict()["searched_range"] == [0.0, r.searched_up_to]
    assert "stopped early" in r.summary()
    assert cli.main(["flutter", "goland", "--json"]) == 0
    out = capsys.readouterr()
    assert "aeroservo: warning: search stopped" in out.err
