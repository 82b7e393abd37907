"""Gust disturbances against closed forms: 1-cos shape, turbulence spectra and variance."""

import numpy as np
import pytest
from scipy.integrate import quad

from aeroservo.aero import GustSeries, OneMinusCosine, Turbulence
from aeroservo.aero.gusts import dryden_psd, von_karman_psd
from aeroservo.errors import InputError


def test_one_minus_cosine_shape():
    g = OneMinusCosine(length=30.0, amplitude=4.0, start=0.1)
    V = 150.0
    t_peak = 0.1 + 0.5 * 30.0 / V
    assert g(np.array([t_peak]), V)[0] == pytest.approx(4.0)
    t = np.array([0.0, 0.1, 0.1 + 30.0 / V, 1.0])
    np.testing.assert_allclose(g(t, V), 0.0, atol=1e-12)
    # area = amplitude/2 x duration of the gust (closed form of the 1-cos integral)
    tt = np.linspace(0.1, 0.1 + 30.0 / V, 20001)
    assert np.trapezoid(g(tt, V), tt) == pytest.approx(2.0 * 30.0 / V, rel=1e-6)


@pytest.mark.parametrize("psd", [dryden_psd, von_karman_psd])
def test_spectra_integrate_to_the_variance(psd):
    """Both one-sided spectra integrate to sigma^2 over [0, inf) (closed-form normalization)."""
    sigma, L, V = 1.7, 533.0, 150.0
    var, _ = quad(lambda w: psd(w, V, sigma, L), 0.0, np.inf, limit=500)
    assert var == pytest.approx(sigma**2, rel=1e-4)


@pytest.mark.parametrize("model", ["dryden", "von_karman"])
def test_turbulence_signal_variance_and_seed(model):
    turb = Turbulence(sigma=2.0, scale=100.0, model=model, seed=11)
    t = np.arange(0, 200.0, 0.01)
    w = turb(t, 150.0)
    # 200 s are ~300 scale-length crossings: the sample variance is within a few percent
    assert np.var(w) == pytest.approx(4.0, rel=0.1)
    np.testing.assert_array_equal(w, turb(t, 150.0))
    other = Turbulence(sigma=2.0, scale=100.0, model=model, seed=12)(t, 150.0)
    assert not np.array_equal(w, other)


def test_gust_series_interpolates_and_validates():
    g = GustSeries(time=(0.0, 1.0, 2.0), velocity=(0.0, 2.0, 0.0))
    np.testing.assert_allclose(g(np.array([0.5, 1.5, 3.0]), 100.0), [1.0, 1.0, 0.0])
    with pytest.raises(InputError, match="time must increase"):
        GustSeries(time=(0.0, 0.0, 1.0), velocity=(0.0, 1.0, 0.0))
    with pytest.raises(InputError, match=r"gust.length = -1"):
        OneMinusCosine(length=-1.0, amplitude=1.0)
    with pytest.raises(InputError, match="turbulence.model = 'kaimal'"):
        Turbulence(sigma=1.0, model="kaimal")
