"""Indicial functions: exact Wagner function and its exponential approximations."""

import numpy as np
import pytest
from conftest import reference

from aeroservo import InputError
from aeroservo.aero import KUSSNER_SETS, WAGNER_SETS, IndicialSet, theodorsen_function, wagner_set
from aeroservo.aero.indicial import fit_wagner, wagner_exact


def test_exact_wagner_table():
    """Case wagner_exact_values (branch-cut inversion, reference sec. 6.2), abs 2e-5."""
    case = reference("wagner_exact_values")
    s = np.array(case["expected"]["s"])
    np.testing.assert_allclose(
        wagner_exact(s), case["expected"]["phi"], atol=case["tolerance"]["abs"]
    )


def test_rt_jones_values():
    """R. T. Jones row of the table in shared/reference sec. 6.2 (5 digits)."""
    s = np.array([0.5, 1, 2, 5, 10, 20, 50, 100])
    expected = [0.55037, 0.59417, 0.66550, 0.79383, 0.87864, 0.93275, 0.98304, 0.99826]
    np.testing.assert_allclose(WAGNER_SETS["rt_jones"](s), expected, atol=6e-6)


@pytest.mark.parametrize("name", ["rt_jones", "wp_jones", "fit2", "fit3", "fit4"])
def test_sets_within_their_stated_error(name):
    """Case wagner_approximations: max |error| vs the exact function, checked on the exact table."""
    case = reference("wagner_approximations")["sets"]
    key = {
        "rt_jones": "RT_Jones",
        "wp_jones": "WP_Jones",
        "fit2": "fit2_this_work",
        "fit3": "fit3_this_work",
        "fit4": "fit4_this_work",
    }[name]
    exact = reference("wagner_exact_values")["expected"]
    s = np.array(exact["s"])
    err = np.abs(WAGNER_SETS[name](s) - np.array(exact["phi"]))
    assert err.max() <= case[key]["max_abs_err_vs_exact"] + 2e-5
    # the published coefficients sum to 1/2 within their 5-digit rounding
    assert WAGNER_SETS[name](0.0) == pytest.approx(0.5, abs=2e-5)


def test_frequency_domain_counterpart_approximates_theodorsen():
    """The R. T. Jones set as a rational C(k) stays within 0.02 of the exact C(k) for k <= 2."""
    k = np.linspace(0.0, 2.0, 81)
    err = np.abs(WAGNER_SETS["rt_jones"].transfer(k) - theodorsen_function(k))
    assert err.max() < 0.02
    assert err[0] == pytest.approx(0.0, abs=1e-15)


def test_kussner_sets_start_at_zero():
    for s in KUSSNER_SETS.values():
        assert s(0.0) == pytest.approx(0.0, abs=1e-4)
        assert s(1e4) == pytest.approx(1.0)


@pytest.mark.parametrize(
    "spec,match",
    [
        ("jones", "unknown set"),
        ({"A": [0.2], "b": [-0.1]}, r"b\[0\]"),
        ({"A": [0.2, 0.3], "b": [0.1]}, "same number"),
        ({"A": [0.7, 0.6], "b": [0.1, 0.2]}, "sum"),
        ({"A": [0.5], "c": [0.1]}, "keys"),
        ({"A": ["x"], "b": [0.1]}, r"A\[0\] = .x.: expected a real number"),
        ({"A": [True], "b": [0.1]}, r"A\[0\] = True"),
        ({"A": "0.165", "b": [0.1]}, "list of numbers"),
        ({"A": [0.1], "b": [1e308]}, r"b\[0\] = 1e\+308: allowed range"),
        (3.0, "expected"),
    ],
)
def test_bad_sets_are_rejected(spec, match):
    with pytest.raises(InputError, match=match):
        wagner_set(spec)


def test_user_set():
    s = wagner_set({"A": [0.5], "b": [0.2], "name": "mine"})
    assert isinstance(s, IndicialSet) and s.n_terms == 1 and s.name == "mine"


@pytest.mark.slow
def test_one_term_set_is_reproducible():
    """The stored 'one_term' set is what fit_wagner(1) produces (no hand-tuned numbers)."""
    fit = fit_wagner(1)
    assert fit.b[0] == pytest.approx(WAGNER_SETS["one_term"].b[0], rel=1e-5)
