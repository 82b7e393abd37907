"""``matlab/load_aeroservo.m`` run by GNU Octave (octave-cli with the control package).

Models exported by ``aeroservo export`` and :func:`aeroservo.files.export_mat` are loaded in
Octave; their frequency responses (Octave's ``freqresp``) must match Python's, and the names,
units, flight condition, state scaling and sample time must survive. Skipped, with the reason
shown, where octave-cli or its control package is not installed (``.ci/run`` installs both from
Debian's packages).
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from scipy.io import loadmat, savemat

import aeroservo as aes
from aeroservo.cli import main
from aeroservo.files import export_mat
from aeroservo.files.statespace_export import state_unit
from aeroservo.linear import discretize

MATLAB_DIR = Path(__file__).resolve().parents[1] / "matlab"
FLAGS = ["--norc", "--quiet", "--no-history", "--no-window-system"]
NO_OCTAVE = (
    "GNU Octave (octave-cli) not installed: .ci/run installs it from Debian's packages "
    "'octave' (which ships octave-cli) and 'octave-control'"
)
SPEED, DENSITY = 150.0, 1.225  # [m/s], [kg/m^3]
INPUTS, OUTPUTS = ["aileron_hinge_moment", "gust"], ["tip_twist", "tip_le_accel"]
RATE = 200.0  # sample rate of the discrete model [Hz]
W = np.logspace(0.0, np.log10(600.0), 60)  # [rad/s], below the 628 rad/s Nyquist of RATE

pytestmark = pytest.mark.slow


def run_octave(exe: str, cwd: Path, code: str) -> subprocess.CompletedProcess:
    """Run ``code`` in octave-cli in ``cwd`` (no startup files, no history, no display)."""
    return subprocess.run(
        [exe, *FLAGS, "--eval", code],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )


@pytest.fixture(scope="module")
def octave(tmp_path_factory) -> str:
    """The octave-cli executable, with its control package loadable; else skip with the reason."""
    exe = shutil.which("octave-cli")
    if exe is None:
        pytest.skip(NO_OCTAVE)
    r = run_octave(exe, tmp_path_factory.mktemp("octave"), "pkg load control")
    if r.returncode != 0:
        why = (r.stderr.strip().splitlines() or ["no message"])[0]
        pytest.skip(
            f"GNU Octave's control package does not load ({why}): .ci/run installs it from "
            "Debian's package 'octave-control'"
        )
    return exe


def strings(value) -> list[str]:
    """A cell of char loaded by ``loadmat(simplify_cells=True)`` as a list of str."""
    return [str(s) if np.size(s) else "" for s in np.atleast_1d(np.asarray(value, dtype=object))]


def response(sys, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Python's frequency response (outputs x inputs x frequencies) and its entrywise first-order
    sensitivity to rounding of A, B, C, D: ``kappa_ij = |c_i M^-1| (|M^-1 b_j| (|A| + |z|) + |b_j|)
    + |c_i| |M^-1 b_j| + |D_ij|`` with ``M = z I - A`` (2-norms), ``z = jw`` or ``exp(jw dt)``."""
    A, B, C, D = (np.asarray(m, dtype=float) for m in (sys.A, sys.B, sys.C, sys.D))
    z = np.exp(1j * w * sys.dt) if sys.dt else 1j * w
    H = sys(z, squeeze=False)
    kappa = np.empty(H.shape)
    norm_a = np.linalg.norm(A, 2)
    for k, zk in enumerate(z):
        m_inv = np.linalg.inv(zk * np.eye(A.shape[0]) - A)
        left = np.linalg.norm(C @ m_inv, axis=1)
        right = np.linalg.norm(m_inv @ B, axis=0)
        kappa[:, :, k] = (
            np.outer(left, right * (norm_a + abs(zk)) + np.linalg.norm(B, axis=0))
            + np.outer(np.linalg.norm(C, axis=1), right)
            + np.abs(D)
        )
    return H, kappa


@pytest.fixture(scope="module")
def models(aileron10, tmp_path_factory) -> tuple[Path, dict]:
    """Exported models: the CLI's default (balanced), a physical single-input single-output
    one, a sampled one, and one with names as char matrices and no optional fields."""
    folder = tmp_path_factory.mktemp("models")
    argv = ["export", "goland_aileron", "--speed", str(SPEED), "--out", str(folder / "cli.mat")]
    assert main(argv + ["--inputs", ",".join(INPUTS), "--outputs", ",".join(OUTPUTS)]) == 0
    bal = aes.statespace(aileron10, SPEED, DENSITY, INPUTS, OUTPUTS)
    phys = aes.statespace(aileron10, SPEED, DENSITY, INPUTS[:1], OUTPUTS[:1], balanced=False)
    sampled = discretize(bal, RATE)
    export_mat(phys, folder / "physical.mat")
    export_mat(sampled, folder / "sampled.mat")
    plain = {k: np.asarray(getattr(bal, k)) for k in "ABCD"}
    plain.update(speed=SPEED, density=DENSITY)
    for key, labels in (("state", bal.state_labels), ("input", INPUTS), ("output", OUTPUTS)):
        plain[f"{key}_names"] = np.array(labels)  # a blank-padded char matrix in the .mat file
    savemat(folder / "charnames.mat", plain)
    return folder, {"cli": bal, "physical": phys, "sampled": sampled, "charnames": bal}


CHECK = """
addpath('{matlab}');
load('w.mat');
cases = {{'cli', 'physical', 'sampled', 'charnames'}};
for k = 1:numel(cases)
    sys = load_aeroservo([cases{{k}} '.mat']);
    H = freqresp(sys, w);
    [~, ~, ~, ~, Ts] = ssdata(sys);
    state_names = sys.StateName;
    input_names = sys.InputName;
    output_names = sys.OutputName;
    userdata = sys.UserData;
    save('-v7', [cases{{k}} '_out.mat'], 'H', 'Ts', 'state_names', 'input_names', ...
         'output_names', 'userdata');
end
"""


def test_octave_loads_models_with_python_frequency_response(octave, models):
    folder, systems = models
    savemat(folder / "w.mat", {"w": W})
    r = run_octave(octave, folder, CHECK.format(matlab=MATLAB_DIR.as_posix()))
    assert r.returncode == 0, f"octave-cli exited with {r.returncode}:\n{r.stderr}\n{r.stdout}"
    eps = np.finfo(float).eps
    for case, sys in systems.items():
        out = loadmat(folder / f"{case}_out.mat", simplify_cells=True)
        H_py, kappa = response(sys, W)
        H_oct = np.asarray(out["H"]).reshape(H_py.shape)
        # the first-order rounding bound eps * kappa holds with a factor 0.3 (measured, Octave
        # 7.3 / control 3.4); 10 leaves a margin while any wrong matrix, scaling, dt or ordering
        # gives O(|H|) errors
        ratio = np.abs(H_oct - H_py) / (eps * kappa)
        assert ratio.max() < 10.0, f"{case}: |H_octave - H_python| = {ratio.max():.3g} eps kappa"
        assert float(out["Ts"]) == (sys.dt or 0.0), case
        assert strings(out["state_names"]) == list(sys.state_labels), case
        assert strings(out["input_names"]) == list(sys.input_labels), case
        assert strings(out["output_names"]) == list(sys.output_labels), case
        info = out["userdata"]
        assert (info["speed_m_s"], info["density_kg_m3"]) == (SPEED, DENSITY), case
        if case == "charnames":  # no units, no scaling in the file: none in UserData
            assert not {"state_units", "input_units", "state_scaling"} & set(info), case
            continue
        np.testing.assert_array_equal(np.atleast_1d(info["state_scaling"]), sys.state_scaling)
        assert strings(info["state_units"]) == [state_unit(n) for n in sys.state_labels], case
        assert strings(info["input_units"]) == [sys.signal_units[n] for n in sys.input_labels]
        assert strings(info["output_units"]) == [sys.signal_units[n] for n in sys.output_labels]


def test_octave_without_control_package_says_what_to_install(octave, models):
    folder, _ = models
    code = (
        "pkg('global_list', fullfile(pwd, 'no_global_list'));"
        "pkg('local_list', fullfile(pwd, 'no_local_list'));"
        f"addpath('{MATLAB_DIR.as_posix()}'); load_aeroservo('cli.mat');"
    )
    r = run_octave(octave, folder, code)
    assert r.returncode != 0
    assert "needs its control package" in r.stderr and "octave-control" in r.stderr, r.stderr
