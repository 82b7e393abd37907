"""The consumers of a doublet-lattice (DLM) model (issue 36, point 1: every consumer works with
either aerodynamic model): state space with the gust and the root loads, modal truncation of a
design model, closed-loop design and simulation, the check of the rational-function onsets
against the tabulated forces, finite-difference sensitivities and the Mach-matched point.

Independent references computed here: the box loads of PanelAero's steady vortex lattice summed
by hand (root loads of a rigid wing in a steady gust), the sampled closed loop built from the
plant's matrices (scipy's zero-order hold), central differences of whole boundaries with a
different step, the p-k with the tabulated forces (:func:`aeroservo.stability.pk.pk_flutter`).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import scipy.linalg as sla

import aeroservo as aes
from aeroservo.aero.atmosphere import isa
from aeroservo.aero.dlm import aics
from aeroservo.design import Bryson, lqr_controller, state_map
from aeroservo.errors import InputError
from aeroservo.linear.models import tip_deflection_state
from aeroservo.linear.state_space import StateSpaceBuilder
from aeroservo.simulate import simulate
from aeroservo.stability.matched import flutter_at
from aeroservo.stability.parameters import with_parameters
from aeroservo.stability.pk import pk_flutter

pytest.importorskip(
    "panelaero",
    reason="PanelAero is not installed (pip install 'aeroservo[dlm]'): doublet-lattice tests skip",
)

RHO = 1.225
HM = "aileron_hinge_moment"


def _stiff(wing, factor: float):
    segs = tuple(dataclasses.replace(s, EI=s.EI * factor, GJ=s.GJ * factor) for s in wing.segments)
    return dataclasses.replace(wing, segments=segs)


@pytest.fixture(scope="module")
def stiff_dlm():
    """Goland's wing 10^4 times stiffer (its deformation in a steady gust is 10^-4 of the
    flexible wing's), coarse lattice."""
    wing = _stiff(aes.examples.goland(), 1e4)
    return aes.AeroelasticModel(wing, n_elements=10, aero=aes.DoubletLattice(chordwise=4))


@pytest.mark.parametrize("speed", [60.0, 150.0])
def test_root_loads_of_a_steady_gust_are_the_sum_of_the_box_loads(stiff_dlm, speed):
    """Steady gust w_g on a (nearly) rigid wing: the state space's DC gain from the gust to the
    root shear, bending moment and torque equals the sum over the boxes of PanelAero's steady
    vortex-lattice loads for a uniform normalwash w_g / V (computed here from the AICs, with
    the moment arms of the load points). This checks the gust column's sign and scale, the
    lag-only gust fit at k = 0 and the root loads by force summation (with the modal model's
    elastic forces at the root the shear was 7 % low)."""
    m = stiff_dlm
    ss = StateSpaceBuilder(
        m, RHO, ["gust"], ["root_shear", "root_bending_moment", "root_torque"]
    ).at(speed)
    dc = np.ravel(ss.dcgain())
    lat = m.dlm.grid.lattice
    dcp = (aics(lat, 0.0, np.zeros(1))[0] @ np.ones(lat.n_boxes)).real / speed  # per m/s
    force = 0.5 * RHO * speed**2 * dcp * lat.areas  # N per m/s of gust, up
    x, y = lat.load_points[:, 0], lat.load_points[:, 1]  # spanwise; aft of the root's axis
    expected = np.array([force.sum(), (force * x).sum(), -(force * y).sum()])
    assert force.sum() > 0
    np.testing.assert_allclose(dc, expected, rtol=2e-4)


@pytest.mark.slow
def test_design_model_maps_to_the_plant(aileron_dlm):
    """state_map of a DLM model: a plant state made of the design model's modes only (their
    displacements, rates and Roger lag states) gives the same tip displacement in both."""
    ins, outs = [HM, "gust"], ["tip_disp", "tip_twist", "modal_2"]
    pb = StateSpaceBuilder(aileron_dlm, RHO, ins, outs)
    db = StateSpaceBuilder(aileron_dlm, RHO, ins, outs, n_modes=8)
    T = state_map(pb, db)
    assert T.shape == (db.n_states, pb.n_states)
    P, D = pb.at(150.0), db.at(150.0)
    rng = np.random.default_rng(3)
    n_a = aileron_dlm.dlm.n_a
    x = np.zeros(pb.n_states)
    x[:8] = rng.normal(size=8)  # physical modal coordinates of the kept modes
    x = x / pb.state_scaling
    yp = np.asarray(P.C) @ x
    yd = np.asarray(D.C) @ (T @ x)
    np.testing.assert_allclose(yd, yp, rtol=1e-10, atol=1e-12 * np.abs(yp).max())
    # lag states of the kept modes map one to one (Roger: root-major, one per mode)
    lags = aileron_dlm.aero.lags
    assert np.count_nonzero(T[16 : 16 + 8 * lags, 2 * n_a : 2 * n_a + lags * n_a]) == 8 * lags


def test_lqr_on_the_dlm_plant_stabilizes_the_sampled_loop(aileron_dlm):
    """LQR designed on an 8-mode DLM model at 1.1 V_f stabilizes the full DLM plant: the
    sampled closed loop built here (zero-order hold of the plant, u = -K x) has spectral
    radius < 1, the open loop's is > 1; the simulated tip motion decays."""
    vf = aes.flutter_boundary(aileron_dlm, RHO).flutter_speed
    v = 1.1 * vf
    ins, outs = [HM, "gust"], ["tip_le_accel", "tip_te_accel", "tip_twist", "tip_disp"]
    pb = StateSpaceBuilder(aileron_dlm, RHO, ins, outs)
    db = StateSpaceBuilder(aileron_dlm, RHO, ins, outs, n_modes=8)
    bryson = Bryson(outputs={"tip_disp": 0.05, "tip_twist": 0.02}, inputs={HM: 500.0})
    K = lqr_controller(db.at(v), [HM], bryson=bryson, state_map=state_map(pb, db))
    P = pb.at(v)
    A, B = np.asarray(P.A), np.asarray(P.B)[:, [0]]
    n = A.shape[0]
    Md = sla.expm(np.block([[A, B], [np.zeros((1, n + 1))]]) * K.dt)
    Ad, Bd = Md[:n, :n], Md[:n, n:]
    assert np.abs(np.linalg.eigvals(Ad)).max() > 1.0
    assert np.abs(np.linalg.eigvals(Ad - Bd @ K.gain)).max() < 1.0
    x0 = tip_deflection_state(pb, 0.01)
    r = simulate(P, K, duration=2.0, x0=x0)
    tip = r.outputs["tip_disp"]
    assert np.abs(tip[-200:]).max() < 0.05 * np.abs(tip[:200]).max()


@pytest.mark.slow
def test_rfa_onsets_are_checked_against_the_tabulated_forces(goland_dlm):
    """Default settings: the time-domain onset is within 0.5 % of the p-k with the tabulated
    GAFs and the check's own estimate agrees with the p-k sweep to 0.1 %."""
    r = aes.flutter_boundary(goland_dlm, RHO)
    pk = pk_flutter(goland_dlm, RHO, boundary=r)
    rec = r.info["rfa_check"][0]
    assert rec["speed"] == pytest.approx(r.flutter_speed)
    assert rec["pk_speed"] == pytest.approx(pk.flutter_speed, rel=1e-3)
    assert abs(r.flutter_speed / pk.flutter_speed - 1) < 5e-3
    assert not [w for w in r.warnings if "onset" in w]
    assert r.compressibility == "dlm"
    assert "doublet lattice at Mach 0" in r.summary()


@pytest.mark.slow
def test_a_spurious_rfa_onset_is_flagged(goland_dlm):
    """Six lag roots over k <= 2 couple into instabilities at 0.3-1.3 kHz from 29 m/s that the
    tabulated forces do not have (measured): each is reported as not confirmed, and the
    physical onset's difference from the p-k is stated."""
    m = aes.AeroelasticModel(
        aes.examples.goland(), n_elements=10, aero=aes.DoubletLattice(k_max=2.0, lags=6)
    )
    r = aes.flutter_boundary(m, RHO)
    assert r.flutter_speed < 60.0
    notes = [w for w in r.warnings if "not confirmed by the tabulated" in w]
    assert len(notes) >= 1 and f"{r.flutter_speed:.5g} m/s" in notes[0]
    assert any("fit error" in w for w in r.warnings)


def test_finite_difference_sensitivities_of_a_dlm_model(goland_dlm):
    """dV_f/dGJ of the DLM model (central differences, h = 1e-4 GJ) against differences of
    whole boundaries taken here with a 100 x larger step (the O(h^2) error of V_f(GJ) is small:
    the two agree to 1e-3)."""
    s = aes.flutter_sensitivities(goland_dlm, RHO, parameters=["segments[0].GJ"])
    assert s.method == "finite differences"
    assert s.to_dict()["method"] == "finite differences"
    gj = goland_dlm.wing.segments[0].GJ
    h = 1e-2 * gj

    def vf(value):
        wing = with_parameters(goland_dlm.wing, {"segments[0].GJ": value})
        return aes.flutter_boundary(
            aes.AeroelasticModel(wing, n_elements=10, aero="dlm"), RHO, rtol=1e-10
        ).flutter_speed

    fd = (vf(gj + h) - vf(gj - h)) / (2 * h)
    assert s.d_flutter_speed["segments[0].GJ"] == pytest.approx(fd, rel=1e-3)


def test_dlm_state_space_refusals(goland_dlm):
    with pytest.raises(InputError, match=r"mach = 1\b|Mach"):
        StateSpaceBuilder(goland_dlm, RHO, ["gust"], ["tip_disp"], mach=1.0)
    with pytest.raises(InputError, match="gust = 'upwash': not used with aero = 'dlm'"):
        StateSpaceBuilder(goland_dlm, RHO, ["gust"], ["tip_disp"], gust="upwash")
    with pytest.raises(InputError, match=r"n_modes = 500: allowed range is \[1, 20\]"):
        StateSpaceBuilder(goland_dlm, RHO, ["gust"], ["tip_disp"], n_modes=500)


@pytest.mark.slow
def test_mach_matched_dlm_flutter(goland_dlm):
    """At 3000 m the Mach-matched DLM flutter point has V_f / a = M to 1e-6, and a boundary
    at that fixed Mach number finds the same speed (the AICs are computed per Mach number)."""
    atm = isa(3000.0)
    r = flutter_at(goland_dlm, atm, compressibility="matched")
    assert r.compressibility == "dlm"
    assert abs(r.flutter_speed / atm.speed_of_sound - r.mach) < 1e-6
    fixed = aes.flutter_boundary(goland_dlm, atm.density, mach=r.mach)
    assert fixed.flutter_speed == pytest.approx(r.flutter_speed, rel=1e-6)


def test_an_onset_beyond_the_tabulated_frequencies_is_flagged():
    """Reduced frequencies tabulated only up to 0.3 while Goland flutters at k = 0.41 (on the
    span-averaged semichord): the onset is found (from the fit's extrapolation) and the warning
    names its reduced frequency and the range to tabulate."""
    k_set = aes.DoubletLattice(reduced_frequencies=[0.05, 0.1, 0.15, 0.2, 0.25, 0.3])
    m = aes.AeroelasticModel(aes.examples.goland(), n_elements=10, aero=k_set)
    r = aes.flutter_boundary(m, RHO)
    k = 2 * np.pi * r.flutter.frequency * m.dlm.b_ref / r.flutter_speed
    assert k == pytest.approx(0.41, abs=0.01)
    assert any(f"k = {k:.3g}, above the tabulated k <= 0.3" in w for w in r.warnings)
