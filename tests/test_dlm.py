"""Validation of the doublet-lattice aerodynamic model (issue 36, section "Validation").

Every reference is computed here, independently of the code under test (``dlm_reference.py``
next to this file imports nothing from aeroservo), or read from a public source named in the
test. Figures measured when these tests were written are quoted in the docstrings; the test
output (``-s``) prints the current ones.

Sources
-------
* Helmbold's lift slope: USAF DATCOM section 4.1.3.2; Prandtl's lifting line by Glauert's
  series (Glauert 1926); the horseshoe vortex lattice (Katz and Plotkin, Low-Speed
  Aerodynamics, section 12.3).
* Theodorsen (1935), NACA Report 496, in the form of Bisplinghoff, Ashley and Halfman (1955).
* The 15-degree swept wing, model D of NASA TN D-1824 (as the NASTRAN-95 demonstration
  problem cites it; its authors are not verified here): NASTRAN-95 demonstration problem D10-02 (``nasa/NASTRAN-95``: ``inp/d10021a.inp``, ``inp/d10021a.txt``,
  ``demoout/d10021a.out`` and ``demoout/d10023a.out``) and MSC's test problem pt145
  (``SteveDoyle2/pyNastran``: ``models/aero/pt145.bdf``). It is not in
  ``shared/reference`` (neither ``README.md`` nor ``cases.json`` has it).
* Goland's wing at sea level, rho = 1.225 kg/m^3 (``shared/reference`` case
  ``goland_clean_flutter_strip_sea_level`` for the strip model's family of results).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

pytest.importorskip(
    "panelaero",
    reason="PanelAero is not installed (pip install 'aeroservo[dlm]'): doublet-lattice tests skip",
)

import dlm_reference as ref  # noqa: E402

import aeroservo as aes  # noqa: E402
from aeroservo.aero import dlm as dlm_module  # noqa: E402
from aeroservo.aero.dlm import aics  # noqa: E402
from aeroservo.aero.dlm_settings import DoubletLattice, as_aero  # noqa: E402
from aeroservo.aero.lattice import strip_lattice  # noqa: E402
from aeroservo.aero.rfa import fit_minimum_state, fit_roger, lag_roots  # noqa: E402
from aeroservo.errors import InputError  # noqa: E402
from aeroservo.stability.boundary import flutter_boundary  # noqa: E402
from aeroservo.stability.pk import pk_flutter  # noqa: E402
from aeroservo.structure.wing import Segment, Wing  # noqa: E402
from aeroservo.system.panel_grid import panel_grid  # noqa: E402

SEA_LEVEL = 1.225  # kg/m^3: Goland's flutter results of shared/reference section 1.3


@pytest.fixture(scope="module", autouse=True)
def _aic_cache(tmp_path_factory):
    """The AIC disk cache of this module in a fresh temporary folder."""
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("AEROSERVO_CACHE", str(tmp_path_factory.mktemp("aic-cache")))
        yield


def rectangle(aspect_ratio, chordwise, spanwise, *, sweep=0.0, cosine=False, symmetric=True):
    """A half wing of chord 1 and span ``aspect_ratio / 2`` (full-span aspect ratio as given),
    untapered, swept by ``sweep`` [rad] (all chord lines), boxes of equal chord; spanwise
    strips of equal width or, with ``cosine``, denser towards the tip. Returns the lattice and
    the half wing's area."""
    s = 0.5 * aspect_ratio
    if cosine:
        x = s * np.sin(np.linspace(0.0, 0.5 * np.pi, spanwise + 1))
    else:
        x = np.linspace(0.0, s, spanwise + 1)
    edges = np.column_stack([x[:-1], x[1:]])
    lat = strip_lattice(
        edges,
        edges * np.tan(sweep),
        np.ones_like(edges),
        [np.linspace(0.0, 1.0, chordwise + 1)] * spanwise,
        symmetric=symmetric,
    )
    return lat, s


def lift_slope(lat, area):
    """``CL_alpha = sum(dcp A) / S`` of the steady vortex lattice at w/V = 1 rad, Mach 0."""
    q = aics(lat, 0.0, np.zeros(1))[0]
    dcp = q @ np.ones(lat.n_boxes)
    assert np.abs(dcp.imag).max() == 0.0
    return float((dcp.real * lat.areas).sum() / area)


def flutter_pair(model, density, mach=0.0, v_max=None):
    """The time-domain (RFA) and the frequency-domain p-k flutter results of one model."""
    rfa = flutter_boundary(model, density, mach=mach, v_max=v_max)
    pk = pk_flutter(model, density, boundary=rfa, mach=mach, v_max=v_max)
    assert rfa.flutter is not None and pk.flutter is not None
    return rfa, pk


# --------------------------------------------------------------------------------------------
# 1. Lattice geometry
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("chordwise", [6, 8])
def test_aileron_lattice_geometry(chordwise):
    """Boxes of goland_aileron(): their areas add up to the planform (span x chord), each strip
    has ``chordwise`` boxes, and the aileron's hinge line (80 % chord, y = b (c - a) aft of the
    elastic axis) and its spanwise ends (60 % span, tip) are box edges, with every box aft of
    the hinge belonging to the aileron."""
    wing = aes.examples.goland_aileron()
    seg, cs = wing.segments[0], wing.control_surfaces[0]
    grid = panel_grid(wing, DoubletLattice(chordwise=chordwise))
    lat = grid.lattice
    chord = 2 * seg.semichord
    assert lat.areas.sum() == pytest.approx(wing.span * chord, rel=1e-12)
    assert np.all(np.bincount(lat.strip) == chordwise)
    # strips tile [0, span] and the aileron's ends are strip edges
    x0, x1 = lat.corners[:, 0, 0], lat.corners[:, 3, 0]
    edges = np.unique(np.round(np.concatenate([x0, x1]), 12))
    assert edges[0] == 0.0 and edges[-1] == pytest.approx(wing.span)
    assert np.min(np.abs(edges - cs.start)) < 1e-9 and np.min(np.abs(edges - cs.end)) < 1e-9
    # the hinge line is a chordwise box edge inside the aileron's strips
    y_hinge = seg.semichord * (cs.hinge - seg.a)  # aft of the elastic axis (x axis: y = 0)
    y_le = -seg.semichord * (1 + seg.a)
    on = grid.surface == 0
    mid = 0.5 * (x0 + x1)
    inside = (mid > cs.start) & (mid < cs.end)
    assert np.array_equal(on, inside & (lat.corners[:, 0, 1] >= y_hinge - 1e-9))
    assert np.allclose(lat.corners[on][:, [0, 3], 1].min(axis=0), y_hinge, atol=1e-9)
    wing_boxes = inside & ~on
    assert np.allclose(lat.corners[wing_boxes][:, [1, 2], 1].max(axis=0), y_hinge, atol=1e-9)
    assert np.all(lat.corners[on, :, 1] >= y_hinge - 1e-9)
    # at least 2 boxes on the surface, leading and trailing edges where the section says
    assert np.all(np.bincount(lat.strip[on])[np.unique(lat.strip[on])] >= 2)
    assert np.allclose(lat.corners[lat.row == 0][:, [0, 3], 1], y_le, atol=1e-12)
    assert np.allclose(lat.corners[:, [1, 2], 1].max(), y_le + chord, atol=1e-12)
    # load (1/4) and downwash (3/4) points of each box
    c = lat.corners
    front = 0.5 * (c[:, 0] + c[:, 3])
    back = 0.5 * (c[:, 1] + c[:, 2])
    assert np.allclose(lat.load_points, front + 0.25 * (back - front), atol=1e-12)
    assert np.allclose(lat.downwash_points, front + 0.75 * (back - front), atol=1e-12)


def test_swept_lattice_geometry():
    """goland_swept() (30 deg, span 6.096 m along the elastic axis, sections normal to it):
    streamwise strips from x = 0 to the axis' tip x = L cos(sweep), leading edge on the line
    y = x tan(sweep) - b (1 + a) / cos(sweep), streamwise chord 2 b / cos(sweep); the area of
    the parallelogram is 2 b L whatever the sweep."""
    wing = aes.examples.goland_swept()
    seg = wing.segments[0]
    sweep, b = seg.sweep, seg.semichord
    lat = panel_grid(wing, DoubletLattice()).lattice
    assert lat.areas.sum() == pytest.approx(2 * b * wing.span, rel=1e-12)
    assert lat.corners[:, :, 0].max() == pytest.approx(wing.span * np.cos(sweep), rel=1e-12)
    assert np.all(np.bincount(lat.strip) == DoubletLattice().chordwise)
    c = lat.corners[lat.row == 0]
    x = c[:, [0, 3], 0]
    assert np.allclose(c[:, [0, 3], 1], x * np.tan(sweep) - b * (1 + seg.a) / np.cos(sweep))
    assert np.allclose(lat.chords * np.bincount(lat.strip)[lat.strip], 2 * b / np.cos(sweep))


# --------------------------------------------------------------------------------------------
# 2. Steady vortex lattice: lift-curve slopes
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "aspect_ratio, chordwise, spanwise, sweep_deg, cosine, symmetric",
    [
        (1.0, 4, 8, 0.0, False, True),
        (6.0, 4, 12, 0.0, True, True),
        (5.0, 1, 4, 45.0, False, True),
        (2.0, 8, 16, 30.0, False, True),
        (2.0, 3, 10, 30.0, False, False),
    ],
)
def test_vlm_matches_independent_horseshoe_lattice(
    aspect_ratio, chordwise, spanwise, sweep_deg, cosine, symmetric
):
    """The steady AICs (PanelAero's VLM through aeroservo's lattice, mirror and sign
    conventions) equal a horseshoe vortex lattice written here from Katz and Plotkin 12.3 (bound
    vortex on the 1/4-chord line, trailing legs to infinity, collocation at 3/4 chord),
    box by box (measured: 1e-15 relative; 1e-10 on the 256-box one)."""
    lat, _ = rectangle(
        aspect_ratio,
        chordwise,
        spanwise,
        sweep=np.radians(sweep_deg),
        cosine=cosine,
        symmetric=symmetric,
    )
    dcp = (aics(lat, 0.0, np.zeros(1))[0] @ np.ones(lat.n_boxes)).real
    expected = ref.horseshoe_vlm(lat.corners, symmetric)
    assert np.abs(dcp - expected).max() <= 1e-8 * np.abs(expected).max()


def test_lift_slope_low_aspect_ratio_helmbold():
    """AR 1 rectangle: Helmbold (DATCOM 4.1.3.2) gives 1.4833/rad, which lifting-surface
    results confirm to ~1.5 % at this aspect ratio. The vortex lattice converges to first
    order in the strip count (8 chordwise boxes; measured 16/32/64 strips: 1.5018, 1.4808,
    1.4702, Richardson extrapolation 1.4597, 1.6 % below Helmbold). Both the finest grid and the
    extrapolated value are within 2 %."""
    values = [lift_slope(*rectangle(1.0, 8, n)) for n in (16, 32, 64)]
    d1, d2 = values[0] - values[1], values[1] - values[2]
    assert d1 > 0 and d2 > 0 and d2 / d1 == pytest.approx(0.5, abs=0.1)  # first order
    extrapolated = values[2] - d2
    helmbold = ref.helmbold(1.0)
    print(f"\nAR 1: VLM {values} extrapolated {extrapolated:.4f}, Helmbold {helmbold:.4f}")
    assert values[2] == pytest.approx(helmbold, rel=0.02)
    assert extrapolated == pytest.approx(helmbold, rel=0.02)


@pytest.mark.slow
def test_lift_slope_high_aspect_ratio_lifting_line():
    """Rectangles of AR 6, 20, 40, 100 (cosine strip spacing, 4-8 chordwise boxes) against
    Prandtl's lifting line by Glauert's series (a0 = 2 pi) coded in ``dlm_reference``.

    What holds: lifting-line theory is the high-aspect-ratio limit of lifting-surface theory;
    for a rectangle it over-predicts the slope by an amount that decays slowly with the aspect
    ratio (the tip, where the chord does not vanish, is a lifting-surface region). Measured
    VLM vs lifting line: AR 6 4.240 vs 4.530 (-6.4 %, the converged VLM is ~4.21, -7 %),
    AR 20 5.444 vs 5.544 (-1.8 %), AR 40 5.803 vs 5.856 (-0.9 %), AR 100 6.061 vs 6.082
    (-0.4 %). So the 2 % of the issue holds from AR ~20 on (asserted for 40 and 100), the gap
    shrinks monotonically, and at AR 6 the lifting line is *not* a 2 % reference (Helmbold,
    4.529, is no better there)."""
    cases = [(6.0, 8, 48), (20.0, 4, 80), (40.0, 4, 160), (100.0, 4, 200)]
    gaps = []
    for ar, nc, ns in cases:
        vlm = lift_slope(*rectangle(ar, nc, ns, cosine=True))
        llt = ref.lifting_line_rectangular(ar)
        gaps.append(vlm / llt - 1.0)
        print(f"\nAR {ar:g}: VLM {vlm:.4f}, lifting line {llt:.4f} ({100 * gaps[-1]:+.2f} %)")
    assert all(g < 0 for g in gaps)
    assert all(abs(a) > abs(b) for a, b in zip(gaps, gaps[1:], strict=False))
    assert abs(gaps[2]) < 0.02 and abs(gaps[3]) < 0.02
    assert -0.08 < gaps[0] < -0.05  # AR 6: the lifting surface's known deficit (see above)


def test_lift_slope_swept_helmbold():
    """Untapered wings swept 30 and 45 deg (all chord lines) vs Helmbold with the half-chord
    sweep, 8 chordwise boxes, 32-48 strips.

    What holds (measured): at AR 2 and 45 deg Helmbold's value is within 2 % (VLM 2.291 vs
    2.300, -0.4 %); at AR 6 Helmbold is 4.8-5.4 % above the VLM, swept or not (the same
    deficit as the unswept AR 6 above), but its *sweep correction*, CLa(sweep) / CLa(0), is
    within 2 % of the VLM's (30 deg: 0.9125 vs 0.9038, +1.0 %; 45 deg: 0.7892 vs 0.7767,
    +1.6 %)."""
    vlm = lift_slope(*rectangle(2.0, 8, 32, sweep=np.radians(45.0)))
    assert vlm == pytest.approx(ref.helmbold(2.0, np.radians(45.0)), rel=0.02)
    flat = lift_slope(*rectangle(6.0, 8, 48))
    for deg in (30.0, 45.0):
        swept = lift_slope(*rectangle(6.0, 8, 48, sweep=np.radians(deg)))
        h_ratio = ref.helmbold(6.0, np.radians(deg)) / ref.helmbold(6.0)
        print(
            f"\nAR 6, {deg:g} deg: VLM {swept:.4f} (Helmbold "
            f"{ref.helmbold(6.0, np.radians(deg)):.4f}); ratio to unswept VLM "
            f"{swept / flat:.4f}, Helmbold {h_ratio:.4f}"
        )
        assert swept / flat == pytest.approx(h_ratio, rel=0.02)
        assert swept < ref.helmbold(6.0, np.radians(deg))


# --------------------------------------------------------------------------------------------
# 3. The two-dimensional limit
# --------------------------------------------------------------------------------------------

THEODORSEN_K = (0.1, 0.3, 0.5, 1.0)


def _ar40_lattice(chordwise: int):
    """Symmetric half of an AR 40 rectangle, chord 1 (b = 0.5), 16 strips growing
    geometrically from 0.25 chord at the root (the mid-span of the whole wing) to the tip."""
    from scipy.optimize import brentq

    span, n, w0 = 20.0, 16, 0.25
    r = brentq(lambda r: w0 * (r**n - 1) / (r - 1) - span, 1.0 + 1e-9, 3.0)
    x = np.concatenate([[0.0], np.cumsum(w0 * r ** np.arange(n))])
    x[-1] = span
    edges = np.column_stack([x[:-1], x[1:]])
    return strip_lattice(
        edges,
        np.zeros_like(edges),
        np.ones_like(edges),
        [np.linspace(0.0, 1.0, chordwise + 1)] * n,
        symmetric=True,
    )


def _midspan_errors(chordwise: int) -> dict:
    """Relative errors of the mid-span section's lift and moment (about mid-chord) against
    Theodorsen, for plunge and pitch, at THEODORSEN_K (on the semichord b = 0.5)."""
    b = 0.5
    lat = _ar40_lattice(chordwise)
    km = np.asarray(THEODORSEN_K) / b  # omega / V [1/m]
    q = aics(lat, 0.0, km)
    root = lat.strip == 0
    width = lat.widths[root][0]
    y_dw = lat.downwash_points[:, 1] - b  # from mid-chord, aft
    y_ld = lat.load_points[:, 1] - b
    out = {"L_h": [], "M_h": [], "L_alpha": [], "M_alpha": []}
    for i, k in enumerate(THEODORSEN_K):
        th = ref.theodorsen_loads(k, a=0.0)
        # normalwash (angle of attack) of h = b (down) and alpha = 1 rad nose up about mid-chord
        washes = {"h": 1j * km[i] * b * np.ones(lat.n_boxes), "alpha": 1.0 + 1j * km[i] * y_dw}
        for name, wash in washes.items():
            force = (q[i] @ wash) * lat.areas  # up, per unit dynamic pressure
            lift = force[root].sum() / width
            moment = -(force[root] * y_ld[root]).sum() / width  # nose up about mid-chord
            # Theodorsen's loads are for b = 1: lift scales with b, moment with b^2
            out[f"L_{name}"].append(abs(lift / (b * th[f"L_{name}"]) - 1))
            out[f"M_{name}"].append(abs(moment / (b * b * th[f"M_{name}"]) - 1))
    return {key: np.array(v) for key, v in out.items()}


@pytest.fixture(scope="module")
def midspan_12():
    return _midspan_errors(12)


def test_two_dimensional_limit_theodorsen(midspan_12):
    """AR 40 rectangle (12 chordwise x 16 strips, mirrored), harmonic plunge and pitch about
    mid-chord: the mid-span section's lift and moment against Theodorsen's closed form
    (Hankel functions) at k = 0.1, 0.3, 0.5, 1 on the semichord.

    Measured errors (plunge / pitch): lift 0.6/0.6, 0.5/0.5, 0.4/0.4, 0.7/1.8 %; moment
    0.9/0.9, 1.4/1.5, 1.9/2.2, 3.9/4.7 %. The lift's remaining 0.5 % at low k is the finite
    span's (downwash of the trailing vortices 20 chords away); the moment error grows with k
    and falls as 1 / chordwise boxes (next test): it is the chordwise discretization's
    (Theodorsen's pressure has a square-root singularity at the leading edge that boxes of
    finite chord smear aft of the quarter chord)."""
    e = midspan_12
    for key in e:
        print(
            f"\n{key}: "
            + ", ".join(
                f"k={k:g} {100 * v:.2f} %" for k, v in zip(THEODORSEN_K, e[key], strict=True)
            )
        )
    low = slice(0, 3)  # k <= 0.5
    assert e["L_h"][low].max() < 0.01 and e["L_alpha"][low].max() < 0.01
    assert e["L_h"][3] < 0.025 and e["L_alpha"][3] < 0.025
    assert e["M_h"][low].max() < 0.025 and e["M_alpha"][low].max() < 0.025
    assert e["M_h"][3] < 0.06 and e["M_alpha"][3] < 0.06


def test_two_dimensional_limit_moment_error_is_chordwise_discretization(midspan_12):
    """Halving the chordwise boxes (12 -> 6) about doubles the moment error at k = 1 (measured
    x2.25 plunge, x2.32 pitch): first-order convergence in the box chord, i.e. the discretization's error,
    not a modelling one."""
    coarse = _midspan_errors(6)
    for key in ("M_h", "M_alpha"):
        ratio = coarse[key][3] / midspan_12[key][3]
        print(
            f"\n{key} at k = 1: 6 boxes {100 * coarse[key][3]:.2f} %, 12 boxes "
            f"{100 * midspan_12[key][3]:.2f} % (x{ratio:.2f})"
        )
        assert 1.5 < ratio < 2.6


@pytest.mark.slow
def test_high_aspect_ratio_flutter_approaches_strip_theory():
    """Goland's section on spans of 3.33 (Goland), 10 and 20 chords, stiffnesses scaled so that
    the in-vacuo frequencies stay Goland's (EI x s^4, GJ x s^2): the DLM p-k flutter speed over
    the strip model's (exact-Theodorsen p-k), rho = 1.225. Measured: 1.136 (default grid),
    1.023 (4 x 30 boxes), 0.998 (4 x 40; 1.012 with 6 x 60): the 3-D excess vanishes with the
    aspect ratio, to within the grid's ~1.5 % at AR 20."""
    base = aes.examples.goland()
    s0 = base.segments[0]
    ratios = []
    for scale, dlm in (
        (1.0, "dlm"),
        (3.0, DoubletLattice(chordwise=4, spanwise=30)),
        (6.0, DoubletLattice(chordwise=4, spanwise=40)),
    ):
        span = base.span * scale
        seg = replace(s0, end=span, EI=s0.EI * scale**4, GJ=s0.GJ * scale**2)
        wing = Wing(span=span, segments=(seg,), name=f"goland x{scale:g}")
        strip = pk_flutter(aes.AeroelasticModel(wing, n_elements=10), SEA_LEVEL)
        _, pk = flutter_pair(aes.AeroelasticModel(wing, n_elements=10, aero=dlm), SEA_LEVEL)
        ratios.append(pk.flutter_speed / strip.flutter_speed)
        print(
            f"\nspan/chord {3.333 * scale:.1f}: strip {strip.flutter_speed:.2f} m/s, DLM "
            f"{pk.flutter_speed:.2f} m/s, ratio {ratios[-1]:.4f}"
        )
    assert ratios[0] > ratios[1] > 1.0
    assert abs(ratios[0] - 1) > 0.1
    assert abs(ratios[1] - 1) < 0.05
    assert abs(ratios[2] - 1) < 0.025


# --------------------------------------------------------------------------------------------
# 4. Time-domain RFA vs frequency-domain p-k, same DLM forces
# --------------------------------------------------------------------------------------------

RFA_PK_TOL = 0.005


def _check_rfa_vs_pk(model, name):
    fit = model.dlm_fit(0.0).summary()
    rfa, pk = flutter_pair(model, SEA_LEVEL)
    d = rfa.flutter_speed / pk.flutter_speed - 1
    print(
        f"\n{name}: RFA {rfa.flutter_speed:.3f} m/s {rfa.flutter.frequency:.3f} Hz, p-k "
        f"{pk.flutter_speed:.3f} m/s {pk.flutter.frequency:.3f} Hz ({100 * d:+.3f} %), fit error "
        f"{fit['max_error']:.4f}, {model.dlm.n_boxes} boxes, {fit['lag_states']} lag states"
    )
    assert abs(d) < RFA_PK_TOL
    assert rfa.flutter.frequency == pytest.approx(pk.flutter.frequency, rel=0.01)
    assert fit["max_error"] < 0.05  # below the warning bound (RFA_WARN)
    return d, fit["max_error"]


@pytest.mark.parametrize("name", ["goland", "goland_aileron", "goland_swept", "goland_store"])
@pytest.mark.slow
def test_rfa_flutter_matches_pk(name, request):
    """The time-domain search on the RFA state space vs the p-k on the exact (interpolated) DLM
    forces, rho = 1.225, Mach 0, default settings: within 0.5 %. Measured (RFA / p-k, fit
    error): goland 156.39 / 156.09 m/s (+0.19 %, 0.016), goland_aileron 158.05 / 157.75
    (+0.19 %, 0.028), goland_swept 180.23 / 179.88 (+0.20 %, 0.017), goland_store
    145.75 / 145.43 (+0.22 %, 0.015). The RFA is consistently ~0.2 % high: the fit's residual
    at the flutter k, not noise."""
    fixtures = {"goland": "goland_dlm", "goland_aileron": "aileron_dlm"}
    if name in fixtures:
        model = request.getfixturevalue(fixtures[name])
    else:
        wing = getattr(aes.examples, name)()
        model = aes.AeroelasticModel(wing, n_elements=10, aero="dlm")
    _check_rfa_vs_pk(model, name)


def _random_wings(n: int, seed: int = 20260036) -> list[Wing]:
    """Goland-like wings: GJ, EI, mass (inertia with it: same radius of gyration), x_alpha, a
    and span each scaled by a factor in [0.7, 1.3]."""
    rng = np.random.default_rng(seed)
    s0 = aes.examples.goland().segments[0]
    wings = []
    for i in range(n):
        f = rng.uniform(0.7, 1.3, 6)
        span = s0.end * f[5]
        seg = replace(
            s0,
            end=span,
            GJ=s0.GJ * f[0],
            EI=s0.EI * f[1],
            mass=s0.mass * f[2],
            inertia=s0.inertia * f[2],
            x_alpha=s0.x_alpha * f[3],
            a=s0.a * f[4],
            name=f"random{i}",
        )
        wings.append(Wing(span=span, segments=(seg,), name=f"random Goland-like {i}"))
    return wings


@pytest.mark.slow
def test_rfa_flutter_matches_pk_random_wings():
    """Three random Goland-like wings (seed 20260036), same check. Measured: +0.24 %, +0.15 %,
    +0.18 % with fit errors 0.018, 0.018, 0.016 (every one within 0.5 %, no tolerance tied to
    the fit error was needed)."""
    for wing in _random_wings(3):
        _check_rfa_vs_pk(aes.AeroelasticModel(wing, n_elements=10, aero="dlm"), wing.name)


# --------------------------------------------------------------------------------------------
# 5. A published DLM flutter case: the 15-degree swept wing of NASA TN D-1824
# --------------------------------------------------------------------------------------------

IN = 0.0254  # m
PT145 = {
    # NASTRAN-95 inp/d10021a.inp and pyNastran models/aero/pt145.bdf, converted to SI:
    # grids along the elastic axis 0 .. 5.72 in in a system turned 15 deg aft;
    # PBAR A 7.175e-2 in^2, I 9.83e-6 in^4, J 36.8e-6 in^4; MAT1 E 10.4e6 psi, G 3.9e6 psi,
    # rho 2.61e-4 lbf s^2/in^4; CMASS2 2.8e-6 lbf s^2 in per 0.572 in on the axis' rotation;
    # CAERO1 streamwise chord 2.0706 in, mid-chord on the axis; AERO RHOREF 1.145e-7
    # lbf s^2/in^4 x density ratio 0.967; Mach 0.45; AERO SYMXZ = 0 (no symmetry plane).
    "span": 5.72 * IN,  # 0.145288 m along the elastic axis
    "sweep": np.radians(15.0),
    "semichord": 1.0 * IN,  # 2 in normal to the axis (2.0706 in streamwise)
    "EI": 10.4e6 * 9.83e-6 * 4.448222 * IN**2,  # 0.29339 N m^2
    "GJ": 3.9e6 * 36.8e-6 * 4.448222 * IN**2,  # 0.41188 N m^2
    "mass": 2.61e-4 * 7.175e-2 * 4.448222 / IN * 1.0 / IN,  # 0.129116 kg/m
    "inertia": 2.8e-6 * 4.448222 * IN / (0.572 * IN),  # 2.1775e-5 kg m about the axis
    "density": 0.967 * 1.145e-7 * 4.448222 / IN / IN**3,  # 1.1833 kg/m^3
    "mach": 0.45,
}


def _interpolated_crossing(v, g, f):
    """Linear interpolation of the g = 0 crossing between two rows of a V-g table."""
    t = -g[0] / (g[1] - g[0])
    return v[0] + t * (v[1] - v[0]), f[0] + t * (f[1] - f[0])


# COSMIC NASTRAN PK (demoout/d10023a.out, point 2): V [in/s], g, f [Hz] at the sign change
COSMIC_PK = _interpolated_crossing(
    (5980.0, 6100.0), (-1.4726860e-2, 2.7509496e-2), (141.72658, 135.91321)
)
COSMIC_PK = (COSMIC_PK[0] * IN, COSMIC_PK[1])  # 152.95 m/s, 139.7 Hz
MSC_KE = (152.5, 140.1)  # MSC Nastran pt145, KE method (as quoted in the brief; not re-read)
WIND_TUNNEL = (5980.0 * IN, 121.0)  # TN D-1824 via NASTRAN-95 inp/d10021a.txt (151.9 m/s)


def pt145_wing() -> Wing:
    p = PT145
    seg = Segment(
        start=0.0,
        end=p["span"],
        semichord=p["semichord"],
        a=0.0,
        mass=p["mass"],
        x_alpha=0.0,
        inertia=p["inertia"],
        EI=p["EI"],
        GJ=p["GJ"],
        name="tn_d1824_model_d",
        sweep=p["sweep"],
    )
    return Wing(span=p["span"], segments=(seg,), name="15-deg swept wing (TN D-1824 model D)")


def test_pt145_structure():
    """SI conversion of the deck (the brief's 0.145288 m, 0.29339 N m^2, 0.41188 N m^2,
    0.129116 kg/m, 2.1775e-5 kg m, 1.1833 kg/m^3) and the natural frequencies against
    NASTRAN-95's eigenvalue table (demoout/d10021a.out: 39.96, 236.41, 250.44 Hz) and the
    uniform-cantilever formulas (39.96, 236.66 Hz). Measured: 39.962, 236.90 (+0.2 %: NASTRAN lumps the torsional
    inertia at the grids, half at the tip), 250.44 Hz."""
    p = PT145
    assert p["span"] == pytest.approx(0.145288, rel=1e-6)
    assert p["EI"] == pytest.approx(0.29339, rel=1e-4)
    assert p["GJ"] == pytest.approx(0.41188, rel=1e-4)
    assert p["mass"] == pytest.approx(0.129116, rel=1e-4)
    assert p["inertia"] == pytest.approx(2.1775e-5, rel=1e-4)
    assert p["density"] == pytest.approx(1.1833, rel=1e-3)
    modes = aes.AeroelasticModel(pt145_wing(), n_elements=10).natural_modes(3)
    print(f"\npt145 natural frequencies {modes.frequencies} Hz, {modes.labels}")
    assert modes.labels == ["1st bending", "1st torsion", "2nd bending"]
    assert np.allclose(modes.frequencies, [39.96152, 236.4137, 250.4423], rtol=0.005)
    L = p["span"]
    f_b = 1.875104**2 / (2 * np.pi) * np.sqrt(p["EI"] / (p["mass"] * L**4))
    f_t = 1 / (4 * L) * np.sqrt(p["GJ"] / p["inertia"])
    assert modes.frequencies[0] == pytest.approx(f_b, rel=1e-3)
    assert modes.frequencies[1] == pytest.approx(f_t, rel=2e-3)  # 10 linear elements: +0.1 %


def _pt145(**settings):
    model = aes.AeroelasticModel(
        pt145_wing(), n_elements=10, aero=DoubletLattice(symmetric=False, **settings)
    )
    # the default speed range (4 b omega_2 = 151 m/s here) ends below this wing's flutter
    return flutter_pair(model, PT145["density"], mach=PT145["mach"], v_max=250.0)


def test_pt145_nastran_layout_reproduces_published_dlm():
    """Same aerodynamic model as the Nastran decks: 4 chordwise x 6 spanwise equal boxes
    (CAERO1 NCHORD 4, NSPAN 6), 3 modes (PARAM LMODES 3), isolated wing, Mach 0.45,
    rho = 1.1833. With the parabolic kernel (COSMIC's): p-k 153.82 m/s at 139.26 Hz, RFA
    153.80 m/s vs COSMIC PK 152.95 m/s / 139.7 Hz (+0.6 %, -0.3 %) and MSC KE 152.5 m/s /
    140.1 Hz; quartic kernel 155.09 m/s / 136.6 Hz (+1.4 %, -2.2 %). Within 3 % (speed) and 5 %
    (frequency) of both."""
    for kernel in ("parabolic", "quartic"):
        rfa, pk = _pt145(chordwise=4, spanwise=6, modes=3, kernel=kernel)
        print(
            f"\npt145 Nastran layout, {kernel}: RFA {rfa.flutter_speed:.2f} m/s, p-k "
            f"{pk.flutter_speed:.2f} m/s at {pk.flutter.frequency:.2f} Hz; COSMIC PK "
            f"{COSMIC_PK[0]:.2f} m/s {COSMIC_PK[1]:.1f} Hz, MSC KE {MSC_KE}"
        )
        for published in (COSMIC_PK, MSC_KE):
            for result in (rfa, pk):
                assert result.flutter_speed == pytest.approx(published[0], rel=0.03)
                assert result.flutter.frequency == pytest.approx(published[1], rel=0.05)


@pytest.mark.slow
def test_pt145_default_grid():
    """aeroservo's default grid (6 x 17 boxes, 17 modes) and a finer 8 x 24 one give
    161.2 and 162.5 m/s at 130.5 and 128.8 Hz (p-k; RFA within 0.05 %): 5-6 % above the
    published Nastran DLM (153 m/s, on 24 boxes) and 6-7 % above the TN D-1824 point
    (151.9 m/s, 121 Hz).

    This is not an error of the model: with Nastran's own 24 boxes it reproduces Nastran to
    0.6 % (previous test); the published result is not converged in the boxes. Refining
    spanwise matters most (4 x 6: 155.0, 4 x 12: 158.9, 4 x 17: 160.2, 6 x 6: 156.1,
    6 x 12: 160.0, 12 x 34: 163.5 m/s): 6 strips over-predict the lift (as coarse strips do in
    the steady tests above), which lowers the flutter speed. The converged thin-surface DLM is
    then ~7 % above the measurement, and its frequency 5 % (128 vs 121 Hz) above it."""
    results = {}
    for label, settings in (("default", {}), ("8x24", {"chordwise": 8, "spanwise": 24})):
        rfa, pk = _pt145(**settings)
        results[label] = pk
        print(
            f"\npt145 {label}: RFA {rfa.flutter_speed:.2f} m/s, p-k {pk.flutter_speed:.2f} m/s "
            f"at {pk.flutter.frequency:.2f} Hz (COSMIC {COSMIC_PK[0]:.2f}, tunnel "
            f"{WIND_TUNNEL[0]:.2f} m/s)"
        )
        assert rfa.flutter_speed == pytest.approx(pk.flutter_speed, rel=RFA_PK_TOL)
    default, fine = results["default"], results["8x24"]
    assert abs(fine.flutter_speed / default.flutter_speed - 1) < 0.015  # converged to 1.5 %
    assert fine.flutter_speed > default.flutter_speed > COSMIC_PK[0]
    # the documented offsets (see the docstring): 3-8 % above Nastran's 24-box result
    assert 1.03 < default.flutter_speed / COSMIC_PK[0] < 1.08
    assert 0.88 < default.flutter.frequency / COSMIC_PK[1] < 0.97


@pytest.mark.slow
def test_pt145_fine_grid():
    """12 x 34 boxes (30 modes): 163.46 m/s at 127.3 Hz, within 1 % of the 8 x 24 grid."""
    _, pk = _pt145(chordwise=12, spanwise=34)
    print(f"\npt145 12x34: p-k {pk.flutter_speed:.2f} m/s at {pk.flutter.frequency:.2f} Hz")
    assert pk.flutter_speed == pytest.approx(162.5, rel=0.015)


# --------------------------------------------------------------------------------------------
# 6. Rational-function approximations of known rational data
# --------------------------------------------------------------------------------------------

K_TAB = np.concatenate(
    [[0.0], np.array([0.01, 0.03, 0.06, 0.1, 0.15, 0.2, 0.3, 0.4, 0.5, 0.65, 0.8, 1.0])]
)


def _dissipative(rng, n):
    x = rng.standard_normal((n, n))
    return -(x @ x.T) / n


@pytest.fixture(scope="module")
def synthetic():
    """Random matrices of a 5-mode model with 3 extra (root) rows: A1 and A2 with negative
    semi-definite symmetric parts on the modes (dissipative: mass and damping positive), A1 with
    an antisymmetric part too; 4 lag roots lag_roots(1, 4)."""
    rng = np.random.default_rng(36)
    n, rows = 5, 8
    a0, a1, a2 = (rng.standard_normal((rows, n)) for _ in range(3))
    s = rng.standard_normal((n, n))
    a1[:n, :n] = _dissipative(rng, n) + 0.5 * (s - s.T)
    a2[:n, :n] = _dissipative(rng, n)
    roots = lag_roots(1.0, 4)
    return {
        "n": n,
        "a0": a0,
        "a1": a1,
        "a2": a2,
        "roots": roots,
        "B": rng.standard_normal((roots.size, rows, n)),
        "D": rng.standard_normal((rows, roots.size)),
        "E": rng.standard_normal((roots.size, n)),
    }


@pytest.mark.parametrize("dissipative", [0, 5])
def test_fit_roger_recovers_known_form(synthetic, dissipative):
    """Q(ik) of a Roger form with known roots is recovered exactly (matrices to 1e-8; measured
    1e-14), with and without the dissipative projection (a no-op on dissipative data)."""
    s = synthetic
    q = ref.roger_form(K_TAB, s["a0"], s["a1"], s["a2"], s["roots"], s["B"])
    fit = fit_roger(K_TAB, q, s["roots"], dissipative=dissipative)
    for got, want in ((fit.A0, s["a0"]), (fit.A1, s["a1"]), (fit.A2, s["a2"]), (fit.B, s["B"])):
        assert np.abs(got - want).max() < 1e-8
    k = np.linspace(0.0, 3.0, 31)
    want = ref.roger_form(k, s["a0"], s["a1"], s["a2"], s["roots"], s["B"])
    assert np.abs(fit(k) - want).max() < 1e-8 * np.abs(want).max()


@pytest.mark.parametrize("dissipative", [0, 5])
def test_fit_minimum_state_recovers_known_form(synthetic, dissipative):
    """Data made by a minimum-state form ``A0 + p A1 + p^2 A2 + D (pI - R)^-1 E p`` with the
    same roots is fitted by Karpel's alternating least squares to 1e-6 of its largest value,
    inside and beyond the tabulated range (measured 2e-15)."""
    s = synthetic
    args = (s["a0"], s["a1"], s["a2"], s["roots"], s["D"], s["E"])
    q = ref.minimum_state_form(K_TAB, *args)
    fit = fit_minimum_state(K_TAB, q, s["roots"], dissipative=dissipative)
    assert fit.kind == "minimum-state" and fit.n_lag_states == s["roots"].size
    k = np.linspace(0.0, 2.0, 41)
    want = ref.minimum_state_form(k, *args)
    assert np.abs(fit(k) - want).max() < 1e-6 * np.abs(want).max()
    assert np.abs(fit.A1 - s["a1"]).max() < 1e-6 and np.abs(fit.A2 - s["a2"]).max() < 1e-6


# --------------------------------------------------------------------------------------------
# 7. Box convergence
# --------------------------------------------------------------------------------------------


@pytest.mark.slow
def test_goland_box_convergence(goland_dlm):
    """Goland's DLM p-k flutter speed (rho = 1.225, Mach 0) at the default grid (6 chordwise x
    20 strips: square boxes) and at a grid 1.5 times as fine both ways (9 x 30). Measured:
    156.09 -> 157.47 m/s (+0.88 %), 11.21 -> 11.10 Hz; twice as fine (12 x 40, 24 s, no longer
    run): 158.08 m/s (+1.27 %); earlier 8 x 27 157.16, 16 x 27 157.53 m/s. Below 2 %."""
    n_strips = int(goland_dlm.dlm.grid.lattice.strip.max()) + 1
    chordwise = goland_dlm.aero.chordwise
    fine_settings = DoubletLattice(chordwise=3 * chordwise // 2, spanwise=3 * n_strips // 2)
    fine_model = aes.AeroelasticModel(aes.examples.goland(), n_elements=10, aero=fine_settings)
    _, coarse = flutter_pair(goland_dlm, SEA_LEVEL)
    _, fine = flutter_pair(fine_model, SEA_LEVEL)
    change = fine.flutter_speed / coarse.flutter_speed - 1
    print(
        f"\nGoland box convergence: {chordwise} x {n_strips} {coarse.flutter_speed:.2f} m/s "
        f"{coarse.flutter.frequency:.3f} Hz -> {3 * chordwise // 2} x {3 * n_strips // 2} "
        f"{fine.flutter_speed:.2f} m/s {fine.flutter.frequency:.3f} Hz ({100 * change:+.2f} %)"
    )
    assert abs(change) < 0.02


# --------------------------------------------------------------------------------------------
# 8. The AIC cache
# --------------------------------------------------------------------------------------------


@pytest.fixture()
def small_lattice():
    lat, _ = rectangle(3.0, 3, 4)
    return lat


def _cache_files(folder):
    return sorted((folder / "aic").glob("*.npz")) if (folder / "aic").is_dir() else []


def test_aic_cache_memory_and_disk(small_lattice, tmp_path, monkeypatch):
    """A second call is served from memory (the same array); with the in-memory cache emptied
    the disk file is read (the computation is not called); a damaged file is recomputed, equal,
    and rewritten."""
    monkeypatch.setenv("AEROSERVO_CACHE", str(tmp_path))
    monkeypatch.setattr(dlm_module, "_MEMORY", {})
    k = np.array([0.0, 0.2, 0.9])
    first = aics(small_lattice, 0.3, k)
    assert aics(small_lattice, 0.3, k) is first
    files = _cache_files(tmp_path)
    assert len(files) == 1
    # other Mach number, frequencies, kernel, symmetry: other keys
    aics(small_lattice, 0.31, k)
    aics(small_lattice, 0.3, k[:2])
    aics(small_lattice, 0.3, k, kernel="parabolic")
    assert len(_cache_files(tmp_path)) == 4

    def refuse(*args, **kwargs):
        raise AssertionError("computed although the disk cache holds it")

    monkeypatch.setattr(dlm_module, "_MEMORY", {})
    with monkeypatch.context() as m:
        m.setattr(dlm_module, "_compute", refuse)
        from_disk = aics(small_lattice, 0.3, k)
    assert from_disk is not first and np.array_equal(from_disk, first)

    files[0].write_bytes(b"not an npz file")
    monkeypatch.setattr(dlm_module, "_MEMORY", {})
    again = aics(small_lattice, 0.3, k)
    assert np.array_equal(again, first)
    monkeypatch.setattr(dlm_module, "_MEMORY", {})
    with monkeypatch.context() as m:
        m.setattr(dlm_module, "_compute", refuse)
        assert np.array_equal(aics(small_lattice, 0.3, k), first)  # rewritten, readable


def test_aic_cache_off_writes_nothing(small_lattice, tmp_path, monkeypatch):
    """AEROSERVO_CACHE=off: nothing is written (neither in the folder a cache would use by
    default, XDG_CACHE_HOME, nor in HOME); the memory cache still serves repeated calls."""
    monkeypatch.setenv("AEROSERVO_CACHE", "off")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    monkeypatch.setattr(dlm_module, "_MEMORY", {})
    assert dlm_module.cache_folder() is None
    q = aics(small_lattice, 0.2, np.array([0.0, 0.5]))
    assert aics(small_lattice, 0.2, np.array([0.0, 0.5])) is q
    assert list(tmp_path.rglob("*")) == []


# --------------------------------------------------------------------------------------------
# 9. Bad input
# --------------------------------------------------------------------------------------------


def test_aics_mach_one_is_refused(small_lattice):
    """Mach 1 (and above): one line naming the field and the subsonic limit."""
    for mach in (1.0, 1.4):
        with pytest.raises(InputError, match=r"^mach = .*subsonic, Mach < 1") as info:
            aics(small_lattice, mach, np.array([0.1]))
        assert "\n" not in str(info.value)
    with pytest.raises(InputError, match=r"kernel = 'x': allowed values are quartic, parabolic"):
        aics(small_lattice, 0.5, np.array([0.1]), kernel="x")
    with pytest.raises(InputError, match=r"reduced frequencies: expected finite values >= 0"):
        aics(small_lattice, 0.5, np.array([-0.1]))


@pytest.mark.parametrize(
    "settings, match",
    [
        ({"chordwise": 0}, r"^dlm\.chordwise = 0: allowed range"),
        ({"lags": 0}, r"^dlm\.lags = 0: allowed range"),
        (
            {"reduced_frequencies": (0.5,)},
            r"^dlm\.reduced_frequencies: 1 non-zero values cannot "
            r"fit 4 lag roots",
        ),
        ({"reduced_frequencies": (0.2, 0.5), "lags": 4}, r"^dlm\.reduced_frequencies: 2 "),
        ({"kernel": "x"}, r"^dlm\.kernel = 'x': allowed values are quartic, parabolic"),
        ({"rfa": "pade"}, r"^dlm\.rfa = 'pade': allowed values"),
        ({"spanwise": 0}, r"^dlm\.spanwise = 0: allowed range"),
    ],
)
def test_doublet_lattice_settings_refused(settings, match):
    """Each bad setting raises one InputError line naming dlm.<key>."""
    with pytest.raises(InputError, match=match) as info:
        DoubletLattice(**settings)
    assert "\n" not in str(info.value)


def test_unknown_dlm_key_refused():
    with pytest.raises(InputError, match=r"^dlm\.boxes: unknown key; allowed are "):
        as_aero({"boxes": 4})


def test_cache_folder_environment(monkeypatch, tmp_path):
    """The cache folder follows AEROSERVO_CACHE (a folder, or off/0/none/empty)."""
    monkeypatch.setenv("AEROSERVO_CACHE", str(tmp_path))
    assert dlm_module.cache_folder() == tmp_path
    for off in ("off", "OFF", "0", "none", ""):
        monkeypatch.setenv("AEROSERVO_CACHE", off)
        assert dlm_module.cache_folder() is None
