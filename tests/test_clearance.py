"""Flutter clearance in the field's terms: standard atmosphere, EAS / Mach / knots, structural
damping, Prandtl-Glauert compressibility with matched points, the flutter envelope.

Independent answers: the ISA 1976 table values (shared/reference README, "Standard atmosphere
check values"), closed forms (in-vacuo decay rates, EAS, the Prandtl-Glauert scaling of the
static divergence speed), and a second method (the p-k with the exact Theodorsen function on
the same structure and damping).
"""

import dataclasses
import json
import math
import re

import numpy as np
import pytest
import scipy.linalg as sla

import aeroservo as aes
from aeroservo import cli
from aeroservo.aero.atmosphere import FT, KNOT, isa, isa_ft
from aeroservo.stability import pk_flutter
from aeroservo.stability.matched import MACH_TOL, flutter_at
from aeroservo.studies.envelope import flutter_envelope, parse_altitudes
from aeroservo.system import TypicalSection
from aeroservo.system.damping import StructuralDamping

# --- standard atmosphere -----------------------------------------------------------------------


@pytest.mark.parametrize(
    "h, T, p, rho, a",
    [
        (0.0, 288.15, 101325.0, 1.225, 340.29),
        (11000.0, 216.65, 22632.0, 0.36392, 295.07),
        (20000.0, 216.65, 5474.9, None, 295.07),
    ],
)
def test_isa_table(h, T, p, rho, a):
    """ISA 1976 by geopotential altitude, to 1e-4 (the table's own rounding)."""
    atm = isa(h)
    assert atm.temperature == pytest.approx(T, rel=1e-4)
    assert atm.pressure == pytest.approx(p, rel=1e-4)
    assert atm.speed_of_sound == pytest.approx(a, rel=1e-4)
    if rho is not None:
        assert atm.density == pytest.approx(rho, rel=1e-4)
    assert atm.density == pytest.approx(atm.pressure / (287.05287 * atm.temperature), rel=1e-12)


def test_isa_20_km_density_is_a_geometric_altitude_value():
    """The reference lists 0.08891 kg/m^3 at 20 000 m next to the geopotential 5 474.9 Pa and
    216.65 K, which give 0.08803: 0.08891 is the table value at 20 km *geometric* altitude."""
    assert isa(20000.0).density == pytest.approx(0.088035, rel=1e-4)
    assert isa(20000.0, geometric=True).density == pytest.approx(0.08891, rel=1e-4)


def test_isa_in_feet_and_bounds():
    assert isa_ft(36089.24).temperature == pytest.approx(216.65, rel=1e-6)  # tropopause
    assert isa_ft(10000.0).density == pytest.approx(isa(10000.0 * FT).density, rel=1e-12)
    for bad in (-2000.0, 60000.0, float("nan")):
        with pytest.raises(aes.InputError, match="altitude"):
            isa(bad)


# --- speeds in the field's terms -----------------------------------------------------------------


def test_result_carries_eas_mach_and_knots(goland10):
    r = flutter_at(goland10, isa(5000.0))
    atm = isa(5000.0)
    assert r.altitude == 5000.0 and r.speed_of_sound == pytest.approx(atm.speed_of_sound)
    assert r.flutter_eas == pytest.approx(r.flutter_speed * math.sqrt(atm.density / 1.225))
    assert r.flutter_mach == pytest.approx(r.flutter_speed / atm.speed_of_sound)
    assert r.divergence_mach == pytest.approx(r.divergence_speed / atm.speed_of_sound)
    d = r.to_dict()
    for key in ("altitude", "density", "speed_of_sound", "flutter_speed", "flutter_eas"):
        assert d[key] is not None
    assert d["flutter_ktas"] == pytest.approx(r.flutter_speed / KNOT)
    assert "KTAS" in r.summary(units="knots") and "Mach" in r.summary()
    # density only: EAS yes, Mach no
    r0 = aes.flutter_boundary(goland10, 1.225)
    assert r0.flutter_eas == pytest.approx(r0.flutter_speed) and r0.flutter_mach is None


# --- structural damping ----------------------------------------------------------------------------


DAMPINGS = [
    StructuralDamping.modal(0.02),
    StructuralDamping.modal([0.01, 0.03, 0.02]),
    StructuralDamping.structural(0.03),
    StructuralDamping.rayleigh(0.5, 2e-4),
]


@pytest.mark.parametrize("damping", DAMPINGS, ids=lambda d: d.describe())
def test_in_vacuo_modes_decay_at_zeta_omega(damping):
    """Without air (density 1e-12, V = 0) each in-vacuo mode decays at zeta_j omega_j."""
    m = aes.AeroelasticModel(aes.examples.goland(), 10, damping=damping)
    modes = m.natural_modes(6)
    omega = 2 * np.pi * modes.frequencies
    zeta = damping.mode_ratios(omega)
    ev = sla.eigvals(m.state_matrix(0.0, 1e-12))
    ev = ev[ev.imag > 1.0]
    for w, z in zip(omega, zeta, strict=True):
        lam = ev[np.argmin(np.abs(np.abs(ev) - w))]
        assert -lam.real == pytest.approx(z * w, rel=1e-6)
        assert abs(lam) == pytest.approx(w, rel=1e-6)


@pytest.mark.parametrize("damping", DAMPINGS, ids=lambda d: d.describe())
def test_section_time_domain_with_damping_equals_pk(damping):
    """Same damping, two methods: the time-domain flutter speed (4-term Wagner fit) equals the
    p-k with the exact Theodorsen function to the accuracy of the fit (1e-3)."""
    sec = TypicalSection.from_nondimensional(
        semichord=1.0, a=-0.2, mu=20, x_alpha=0.1, r_alpha2=0.24, omega_h=40.0,
        omega_alpha=100.0, density=1.225, wagner="fit4", damping=damping,
    )  # fmt: skip
    r, p = aes.flutter_boundary(sec, 1.225), pk_flutter(sec, 1.225)
    assert r.flutter_speed == pytest.approx(p.flutter_speed, rel=1e-3)
    undamped = aes.flutter_boundary(dataclasses.replace(sec, damping=None), 1.225)
    assert r.flutter_speed > undamped.flutter_speed  # damping raises it


def test_goland_with_g_003_flutters_above_undamped(goland10_flutter):
    m = aes.AeroelasticModel(aes.examples.goland(), 10, damping=StructuralDamping.structural(0.03))
    r = aes.flutter_boundary(m, 1.225)
    assert goland10_flutter.flutter_speed == pytest.approx(137.84, rel=1e-4)
    assert r.flutter_speed > goland10_flutter.flutter_speed * 1.01
    assert r.damping == "g = 0.03" and "g = 0.03" in r.summary()
    p = pk_flutter(m, 1.225)
    assert p.flutter_speed == pytest.approx(r.flutter_speed, rel=5e-3)


def test_statespace_poles_with_damping_and_mach():
    m = aes.AeroelasticModel(
        aes.examples.goland_aileron(), 10, damping=StructuralDamping.modal(0.02)
    )
    r = aes.flutter_boundary(m, 1.225, mach=0.4, exact_branches=True)
    b = aes.StateSpaceBuilder(m, 1.225, mach=0.4)
    for i in (4, 9):
        poles = np.linalg.eigvals(b.matrices(r.speeds[i])[0])
        for lam in r.eigenvalues[i]:
            assert np.min(np.abs(poles - lam)) < 1e-8 * abs(lam)


@pytest.mark.parametrize(
    "kw", [{"ratios": (-0.1,)}, {"ratios": (1.5,)}, {"ratios": ()}, {"g": -0.01}, {"g": 2.0}]
)
def test_bad_damping(kw):
    kind = "structural_g" if "g" in kw else "modal"
    with pytest.raises(aes.InputError, match="damping"):
        StructuralDamping(kind, **kw)


# --- compressibility -------------------------------------------------------------------------------


@pytest.mark.parametrize("mach", [0.3, 0.6, 0.85])
def test_divergence_scales_with_prandtl_glauert(goland10, mach):
    """Clean wing: the steady lift slope 2 pi / beta gives V_D(M) = V_D(0) sqrt(beta)."""
    v0 = aes.divergence_speed(goland10.system(1.225))
    vm = aes.divergence_speed(goland10.system(1.225, mach))
    assert vm == pytest.approx(v0 * (1 - mach**2) ** 0.25, rel=1e-10)


@pytest.mark.parametrize("mach", [0.3, 0.6])
def test_compressible_time_domain_equals_pk(mach):
    """Both methods scale the circulatory loads by 1/beta at reduced frequency k / beta^2."""
    m = aes.AeroelasticModel(aes.examples.goland(), 10, wagner="fit4")
    r, p = aes.flutter_boundary(m, 1.225, mach=mach), pk_flutter(m, 1.225, mach=mach)
    assert r.flutter_speed == pytest.approx(p.flutter_speed, rel=3e-3)
    assert r.flutter_speed < aes.flutter_boundary(m, 1.225).flutter_speed


def test_mach_limit_refused(goland10):
    for bad in (0.9, 0.95, 1.2, -0.1):
        with pytest.raises(aes.InputError, match="mach"):
            aes.flutter_boundary(goland10, 1.225, mach=bad)


@pytest.mark.parametrize("h", [0.0, 6000.0, 12000.0])
def test_matched_point(goland10, h):
    atm = isa(h)
    r = flutter_at(goland10, atm, compressibility="prandtl-glauert")
    assert abs(r.mach - r.flutter_speed / atm.speed_of_sound) < MACH_TOL
    assert len(r.info["mach_iterations"]) >= 2
    assert r.flutter_speed < flutter_at(goland10, atm).flutter_speed
    if r.flutter_mach > 0.7:
        assert any("approximate above Mach 0.7" in w for w in r.warnings)
    if r.divergence_speed is not None:  # the divergence is matched at its own Mach number
        vd = aes.divergence_speed(goland10.system(atm.density, r.divergence_mach))
        assert vd == pytest.approx(r.divergence_speed, rel=1e-8)


# --- envelope ----------------------------------------------------------------------------------------


def test_envelope_at_sea_level_equals_flutter(goland10):
    damped = aes.AeroelasticModel(
        aes.examples.goland(), 10, damping=StructuralDamping.structural(0.03)
    )
    for m in (goland10, damped):
        env = flutter_envelope(m, [0.0, 4000.0])
        r = aes.flutter_boundary(m, 1.225)
        # ISA sea level is p0 / (R T0) = 1.2250000176 kg/m^3; the roots converge to 1e-7
        assert env.points[0].density == pytest.approx(1.225, rel=2e-8)
        assert env.points[0].flutter_speed == pytest.approx(r.flutter_speed, rel=1e-6)
        assert env.points[0].divergence_speed == pytest.approx(r.divergence_speed, rel=1e-6)


def test_envelope_margins(goland10):
    env = flutter_envelope(goland10, [0.0, 6000.0, 12000.0], vd=110.0, md=0.5)
    for p in env.points:
        atm = isa(p.altitude)
        v_env = min(110.0, 0.5 * atm.speed_of_sound * math.sqrt(atm.density / 1.225))
        assert p.envelope_eas == pytest.approx(v_env)
        assert p.required_eas == pytest.approx(1.15 * v_env)
        assert p.margin_ok == (p.flutter_eas >= p.required_eas)
    d = env.to_dict()
    assert set(d["points"][0]) >= {"altitude", "density", "flutter_speed", "flutter_eas",
                                   "flutter_mach", "divergence_speed", "margin_ok"}  # fmt: skip
    rows = env.csv_text().strip().splitlines()
    assert len(rows) == 4 and rows[0].startswith("altitude,density")
    assert flutter_envelope(goland10, [0.0]).to_dict()["points"][0].get("margin_ok") is None


def test_parse_altitudes():
    assert parse_altitudes("0:3000:1000") == [0.0, 1000.0, 2000.0, 3000.0]
    assert parse_altitudes("0,500") == [0.0, 500.0]
    assert parse_altitudes("0:10000:10000", "ft") == pytest.approx([0.0, 3048.0])
    for bad in ("0:1000:0", "a:b:c", "1000:0:100", ""):
        with pytest.raises(
            aes.InputError, match=re.escape(f"--altitudes = {bad!r}: expected start:stop:step")
        ):
            parse_altitudes(bad)


# --- command line ------------------------------------------------------------------------------------


def test_cli_flutter_at_altitude(capsys):
    argv = ["flutter", "goland", "--altitude", "5000", "--compressibility", "prandtl-glauert"]
    assert cli.main([*argv, "--structural-g", "0.03", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["altitude"] == 5000.0 and out["compressibility"] == "prandtl-glauert"
    assert out["damping"] == "g = 0.03"
    assert abs(out["mach"] - out["flutter_mach"]) < MACH_TOL
    for key in ("flutter_eas", "divergence_eas", "divergence_mach", "speed_of_sound"):
        assert out[key] is not None
    assert cli.main(["flutter", "goland", "--altitude-ft", "10000", "--units", "knots"]) == 0
    assert "KTAS" in capsys.readouterr().out


@pytest.mark.parametrize(
    "argv, msg",
    [
        (["--altitude", "1000", "--density", "1.0"], "not allowed with"),
        (["--altitude", "60000"], "altitude = 60000"),
        (["--compressibility", "prandtl-glauert"], "needs the speed of sound"),
        (["--damping-ratio", "-0.1"], "--damping-ratio[0] = -0.1"),
        (["--structural-g", "3"], "--structural-g = 3"),
        (["--rayleigh", "1"], "ALPHA,BETA"),
    ],
)
def test_cli_bad_flight_options(argv, msg, capsys):
    assert cli.main(["flutter", "goland", *argv]) == 2
    err = capsys.readouterr().err
    assert msg in err and len(err.strip().splitlines()) == 1


def test_cli_envelope(tmp_path, capsys):
    csv, png = tmp_path / "env.csv", tmp_path / "env.png"
    argv = ["envelope", "goland", "--altitudes", "0:12000:6000", "--vd", "110", "--md", "0.5"]
    assert cli.main([*argv, "--csv", str(csv), "--plot", str(png), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert [p["altitude"] for p in out["points"]] == [0.0, 6000.0, 12000.0]
    assert csv.read_text().count("\n") == 4
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert cli.main([*argv, "--plot", str(tmp_path / "x.bogus")]) == 2  # checked first
    assert not (tmp_path / "x.bogus").exists()


def test_wing_and_scenario_files_take_the_keys(tmp_path):
    from aeroservo.files import load_wing
    from aeroservo.files.scenario_file import scenario_from_dict

    src = (__import__("conftest").ROOT / "scenarios" / "goland.toml").read_text()
    src = "\n".join(ln for ln in src.splitlines() if not ln.startswith("density"))
    assert "[analysis]" in src
    wing_file = tmp_path / "w.toml"
    wing_file.write_text(
        src.replace("[analysis]", "[analysis]\naltitude = 3000") + "\n[damping]\ng = 0.03\n"
    )

    _wing, opts = load_wing(wing_file)
    assert opts.altitude == 3000.0 and opts.density == pytest.approx(isa(3000.0).density)
    assert opts.damping.describe() == "g = 0.03"
    data = {
        "scenario": {"name": "x", "kind": "flutter"},
        "wing": {"builtin": "goland"},
        "flight": {"altitude_ft": 10000.0},
        "model": {"compressibility": "prandtl-glauert"},
        "damping": {"ratio": [0.02, 0.01]},
    }
    sc = scenario_from_dict(data, str(tmp_path / "s.toml"))
    assert sc.altitude == pytest.approx(3048.0) and sc.compressibility == "prandtl-glauert"
    assert sc.model().damping.ratios == (0.02, 0.01)
    bad = {**data, "flight": {"altitude": 1000.0, "density": 1.0}}
    with pytest.raises(aes.InputError, match="give one of density, altitude"):
        scenario_from_dict(bad, "s.toml")
    bad = {**data, "flight": {"density": 1.0}}
    with pytest.raises(aes.InputError, match="model.compressibility.*needs flight.altitude"):
        scenario_from_dict(bad, "s.toml")
