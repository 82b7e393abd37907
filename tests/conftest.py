"""Shared fixtures.

Reference numbers come from ``tests/data/reference_cases.json``, a verbatim copy of the
project's public reference data (``shared/reference/cases.json``, see its README for sources
and confidence codes). Each test names the case id it uses.
"""

from __future__ import annotations

import atexit
import json
import os
import shutil
import tempfile
from pathlib import Path

import pytest

import aeroservo as aes

DATA = Path(__file__).parent / "data"
ROOT = Path(__file__).parent.parent

# The doublet-lattice AICs are cached on disk (aeroservo.aero.dlm): the tests share one fresh
# folder (inherited by the command-line runs they start), removed at the end, so that they
# neither read nor fill the user's cache.
_AIC_CACHE = tempfile.mkdtemp(prefix="aeroservo-test-aics-")
os.environ["AEROSERVO_CACHE"] = _AIC_CACHE
atexit.register(shutil.rmtree, _AIC_CACHE, ignore_errors=True)


def needs_panelaero():
    """Skip with the reason when the optional doublet-lattice library is missing."""
    return pytest.importorskip(
        "panelaero",
        reason="PanelAero is not installed (pip install 'aeroservo[dlm]'): doublet-lattice "
        "tests skip",
    )


def designed_loop(stem: str):
    """A shipped scenario's plant and designed controller at its design speed (a schedule
    evaluated there), with an ideal actuator (``ideal_loops``): ``(plant, controller)``."""
    from ideal_loops import ideal

    from aeroservo.files import load_scenario
    from aeroservo.stability.boundary import flutter_boundary

    sc = ideal(load_scenario(ROOT / "scenarios" / f"{stem}.toml"))  # the loops they check
    model = sc.model()
    vf = flutter_boundary(model, sc.density).flutter_speed
    loop = sc.loop(model)
    speed = sc.speed_factor * vf
    ctrl = loop.design_controller(sc.controller, speed, sc.sample_rate, vf)
    return loop.plant(speed), ctrl.at(speed) if hasattr(ctrl, "at") else ctrl


def reference(case_id: str) -> dict:
    """The reference case with this id."""
    cases = json.loads((DATA / "reference_cases.json").read_text())["cases"]
    for case in cases:
        if case["id"] == case_id:
            return case
    raise KeyError(case_id)


@pytest.fixture(scope="session")
def goland10() -> aes.AeroelasticModel:
    return aes.AeroelasticModel(aes.examples.goland(), n_elements=10)


@pytest.fixture(scope="session")
def goland40() -> aes.AeroelasticModel:
    return aes.AeroelasticModel(aes.examples.goland(), n_elements=40)


@pytest.fixture(scope="session")
def goland10_flutter(goland10) -> aes.FlutterResult:
    return aes.flutter_boundary(goland10, 1.225)


@pytest.fixture(scope="session")
def aileron10() -> aes.AeroelasticModel:
    return aes.AeroelasticModel(aes.examples.goland_aileron(), n_elements=10)


@pytest.fixture(scope="session")
def goland_dlm() -> aes.AeroelasticModel:
    """Goland's wing with the doublet lattice at its default settings (10 elements)."""
    needs_panelaero()
    return aes.AeroelasticModel(aes.examples.goland(), n_elements=10, aero="dlm")


@pytest.fixture(scope="session")
def aileron_dlm() -> aes.AeroelasticModel:
    """Goland's wing with its aileron and the doublet lattice (10 elements)."""
    needs_panelaero()
    return aes.AeroelasticModel(aes.examples.goland_aileron(), n_elements=10, aero="dlm")


@pytest.fixture(autouse=True)
def _close_pyplot_figures():
    """Once pyplot is imported, aeroservo's figures are registered in it
    (:mod:`aeroservo._figures`): close them after each test so they do not pile up."""
    yield
    import sys

    plt = sys.modules.get("matplotlib.pyplot")
    if plt is not None:
        plt.close("all")
