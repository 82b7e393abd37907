"""Bad arguments to the public API are refused with a one-line InputError (issue 15).

Each case of :data:`CORPUS` is a call with one bad argument; it must raise
:class:`aeroservo.errors.InputError` (never an AttributeError, TypeError, MemoryError or an
exception from deep inside numpy, scipy or python-control) whose message is one line and names
the argument (and usually the value). The hypothesis tests fuzz the numeric arguments: a call
either succeeds or raises InputError, without a RuntimeWarning (overflow, invalid value).
"""

import re
import warnings
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import event, given, settings
from hypothesis import strategies as st

import aeroservo as aes
from aeroservo.aero import GustSeries, OneMinusCosine, Turbulence
from aeroservo.design import (
    Bryson,
    Limits,
    OpenLoop,
    lqr_controller,
    state_map,
    with_sensor_filters,
)
from aeroservo.errors import InputError
from aeroservo.linear import Sensor, Servo, StateSpaceBuilder, discretize, statespace_family
from aeroservo.linear.models import tip_deflection_state
from aeroservo.simulate import simulate
from aeroservo.stability.divergence import divergence_speed, divergence_speeds, static_speeds
from aeroservo.structure.examples import goland, goland_aileron

RHO = 1.225
HM = "aileron_hinge_moment"
NAN, INF = float("nan"), float("inf")
OUTS = ["tip_disp", "tip_twist"]


@pytest.fixture(scope="module")
def ctx():
    """Models built once: a wing, its model, a design model, a plant and an open loop."""
    wing = goland_aileron()
    model = aes.AeroelasticModel(wing)
    design = aes.statespace(model, 100.0, RHO, inputs=[HM, "gust"], outputs=OUTS, n_modes=4)
    plant = aes.statespace(model, 100.0, RHO, inputs=[HM, "gust"], outputs=OUTS)
    builder = StateSpaceBuilder(model, RHO, [HM], OUTS)
    n = design.nstates
    asym = np.eye(n)
    asym[0, 1] = 1.0
    return SimpleNamespace(
        wing=wing,
        model=model,
        small=aes.AeroelasticModel(goland(), 4),
        design=design,
        plant=plant,
        builder=builder,
        ol=OpenLoop((HM,), 1e-3),
        I=np.eye(n),
        R=np.eye(1),
        asym=asym,
        bryson=Bryson(outputs={"tip_disp": 0.05}, inputs={HM: 500.0}),
    )


def ss(c, **kw):
    """statespace of the Goland aileron wing at 100 m/s, sea level, with one change."""
    args = {"wing": c.wing, "speed": 100.0, "density": RHO} | kw
    return aes.statespace(args.pop("wing"), args.pop("speed"), args.pop("density"), **args)


def design_lqr(c, **kw):
    args = {"sys": c.design, "controls": [HM], "Q": c.I, "R": c.R} | kw
    return lqr_controller(args.pop("sys"), args.pop("controls"), **args)


def sim(c, **kw):
    args = {"plant": c.plant, "controller": c.ol, "duration": 0.01} | kw
    return simulate(args.pop("plant"), args.pop("controller"), **args)


def sweep(c, speeds):
    return aes.eigen_sweep(c.small, speeds, RHO)


T = np.linspace(0.0, 1.0, 11)

CORPUS = [
    # statespace: signals
    ("ss-inputs-None-entry", lambda c: ss(c, inputs=[None]), "inputs[0] = None"),
    ("ss-inputs-int", lambda c: ss(c, inputs=5), "inputs = 5: expected a list of signal names"),
    ("ss-outputs-int", lambda c: ss(c, outputs=5), "outputs = 5"),
    ("ss-inputs-bare-string", lambda c: ss(c, inputs=HM), f"inputs = {HM!r}"),
    ("ss-outputs-bare-string", lambda c: ss(c, outputs="tip_twist"), "outputs = 'tip_twist'"),
    ("ss-outputs-empty", lambda c: ss(c, outputs=[]), "outputs = []"),
    ("ss-inputs-empty", lambda c: ss(c, inputs=()), "inputs = ()"),
    ("ss-outputs-int-entry", lambda c: ss(c, outputs=["tip_twist", 5]), "outputs[1] = 5"),
    ("ss-inputs-dict", lambda c: ss(c, inputs={HM: 1}), "inputs = {"),
    # statespace: options
    ("ss-n_modes-0", lambda c: ss(c, n_modes=0), "n_modes = 0: allowed range is [1, 35]"),
    ("ss-n_modes-negative", lambda c: ss(c, n_modes=-3), "n_modes = -3"),
    ("ss-n_modes-float", lambda c: ss(c, n_modes=2.5), "n_modes = 2.5"),
    ("ss-n_modes-huge", lambda c: ss(c, n_modes=10**6), "n_modes = 1000000"),
    ("ss-servo-unknown-key", lambda c: ss(c, servo={"foo": 1}), "servo['foo']"),
    (
        "ss-servo-value",
        lambda c: ss(c, inputs=[HM], servo={"aileron": 1}),
        "servo['aileron'] = 1",
    ),
    ("ss-servo-string", lambda c: ss(c, servo="fast"), "servo = 'fast'"),
    ("ss-balanced-string", lambda c: ss(c, balanced="no"), "balanced = 'no'"),
    ("ss-balanced-int", lambda c: ss(c, balanced=1), "balanced = 1"),
    ("ss-gust-None", lambda c: ss(c, gust=None), "gust = None"),
    ("ss-n_elements-0", lambda c: ss(c, n_elements=0), "n_elements = 0"),
    # statespace: flight condition and wing
    ("ss-speed-huge", lambda c: ss(c, speed=1e308), "speed = 1e+308: allowed range is [0, 1000]"),
    ("ss-speed-nan", lambda c: ss(c, speed=NAN), "speed = nan"),
    ("ss-speed-negative", lambda c: ss(c, speed=-1.0), "speed = -1"),
    ("ss-speed-string", lambda c: ss(c, speed="100"), "speed = '100'"),
    ("ss-speed-None", lambda c: ss(c, speed=None), "speed = None"),
    ("ss-density-zero", lambda c: ss(c, density=0.0), "density = 0"),
    ("ss-density-inf", lambda c: ss(c, density=INF), "density = inf"),
    ("ss-density-negative", lambda c: ss(c, density=-RHO), "density = -1.225"),
    ("ss-density-huge", lambda c: ss(c, density=1e300), "density = 1e+300"),
    ("ss-density-bool", lambda c: ss(c, density=True), "density = True"),
    ("ss-density-string", lambda c: ss(c, density="abc"), "density = 'abc'"),
    ("ss-wing-None", lambda c: ss(c, wing=None), "wing = None"),
    ("ss-wing-string", lambda c: ss(c, wing="goland"), "wing = 'goland'"),
    ("ss-wing-list", lambda c: ss(c, wing=[1]), "wing = [1]"),
    # Servo and Sensor
    ("servo-bandwidth-nan", lambda c: Servo(bandwidth=NAN), "servo.bandwidth = nan"),
    ("servo-order-float", lambda c: Servo(order=1.0), "servo.order = 1.0"),
    ("servo-order-bool", lambda c: Servo(order=True), "servo.order = True"),
    ("servo-order-string", lambda c: Servo(order="1"), "servo.order = '1'"),
    ("servo-order-3", lambda c: Servo(order=3, bandwidth=10.0), "servo.order = 3"),
    ("servo-bandwidth-huge", lambda c: Servo(2, 1e300), "servo.bandwidth = 1e+300"),
    ("servo-bandwidth-zero", lambda c: Servo(1, 0.0), "servo.bandwidth = 0"),
    ("servo-damping-nan", lambda c: Servo(2, 10.0, NAN), "servo.damping = nan"),
    ("sensor-x-nan", lambda c: Sensor("s", "acceleration", NAN), "sensor 's'.x = nan"),
    ("sensor-name-None", lambda c: Sensor(None, "twist", 1.0), "sensor.name = None"),
    ("sensor-quantity-list", lambda c: Sensor("s", ["x"], 1.0), "sensor 's'.quantity"),
    # statespace_family, builder, discretize, initial state
    ("family-empty", lambda c: statespace_family(c.wing, [], RHO), "speeds = []"),
    ("family-scalar", lambda c: statespace_family(c.wing, 100.0, RHO), "speeds = 100.0"),
    ("family-nan", lambda c: statespace_family(c.wing, [100.0, NAN], RHO), "speeds[1] = nan"),
    ("family-fast", lambda c: statespace_family(c.wing, [100, 2000], RHO), "speeds[1] = 2000"),
    ("family-ragged", lambda c: statespace_family(c.wing, [1, [2, 3]], RHO), "speeds[1]"),
    ("family-keyword", lambda c: statespace_family(c.wing, [1.0], RHO, foo=1), "'foo'"),
    (
        "family-too-many",
        lambda c: statespace_family(c.wing, np.linspace(1, 100, 10**6), RHO),
        "above the limit of 1 GiB",
    ),
    ("builder-wing", lambda c: StateSpaceBuilder(c.wing, RHO), "model = Wing(span=6.096"),
    ("builder-balanced", lambda c: c.builder.at(100.0, balanced=1), "balanced = 1"),
    ("builder-speed", lambda c: c.builder.matrices(-5.0), "speed = -5"),
    ("discretize-None", lambda c: discretize(None, 100.0), "sys = None"),
    ("discretize-rate-0", lambda c: discretize(c.design, 0.0), "sample_rate = 0"),
    ("discretize-rate-tiny", lambda c: discretize(c.design, 1e-300), "sample_rate = 1e-300"),
    ("tip-state-None", lambda c: tip_deflection_state(None, 0.01), "plant = None"),
    ("tip-state-nan", lambda c: tip_deflection_state(c.builder, NAN), "tip = nan"),
    # flutter_boundary, eigen_sweep, divergence
    (
        "flutter-progress-int",
        lambda c: aes.flutter_boundary(c.model, RHO, progress=5),
        "progress = 5",
    ),
    (
        "flutter-progress-string",
        lambda c: aes.flutter_boundary(c.model, RHO, progress="print"),
        "progress = 'print'",
    ),
    (
        "flutter-exact-branches",
        lambda c: aes.flutter_boundary(c.model, RHO, exact_branches="yes"),
        "exact_branches = 'yes'",
    ),
    ("sweep-nan", lambda c: sweep(c, [100.0, NAN]), "speeds[1] = nan"),
    ("sweep-negative", lambda c: sweep(c, [-100, 50]), "speeds[0] = -100"),
    ("sweep-fast", lambda c: sweep(c, [1.0, 2000.0]), "speeds[1] = 2000"),
    ("sweep-string", lambda c: sweep(c, "abc"), "speeds = 'abc'"),
    ("sweep-decreasing", lambda c: sweep(c, [3.0, 2.0]), "speeds[1] = 2"),
    ("sweep-2d", lambda c: sweep(c, [[1.0, 2.0]]), "speeds = [[1.0, 2.0]]"),
    ("sweep-empty", lambda c: sweep(c, []), "speeds = []"),
    ("sweep-bools", lambda c: sweep(c, [True, False]), "speeds = [True, False]"),
    ("sweep-scalar", lambda c: sweep(c, 100.0), "speeds = 100.0"),
    (
        "sweep-too-many",  # a 1e8-speed grid without allocating it: a broadcast view
        lambda c: sweep(c, np.broadcast_to(np.float64(1.0), (10**8,))),
        "above the limit of 1 GiB",
    ),
    ("divergence-model", lambda c: divergence_speed(c.model), "system = <AeroelasticModel>"),
    ("divergence-None", lambda c: divergence_speed(None), "system = <None>"),
    ("divergence-speeds-wing", lambda c: divergence_speeds(c.wing), "system = <Wing>"),
    ("static-shapes", lambda c: static_speeds(np.eye(2), np.eye(3), RHO), "K_static"),
    ("static-density", lambda c: static_speeds(np.eye(2), np.eye(2), -1.0), "density = -1"),
    ("static-nan", lambda c: static_speeds(np.eye(2) * NAN, np.eye(2), RHO), "Ks"),
    # lqr and Bryson's rule
    ("lqr-Q-negative", lambda c: design_lqr(c, Q=-c.I), "Q must be positive semi-definite"),
    ("lqr-R-negative", lambda c: design_lqr(c, R=-c.R), "R must be positive definite"),
    ("lqr-R-zero", lambda c: design_lqr(c, R=0 * c.R), "R must be positive definite"),
    ("lqr-Q-string", lambda c: design_lqr(c, Q="abc"), "Q = 'abc'"),
    ("lqr-Q-nan", lambda c: design_lqr(c, Q=c.I * NAN), "Q has NaN"),
    ("lqr-Q-asymmetric", lambda c: design_lqr(c, Q=c.asym), "Q is not symmetric"),
    ("lqr-Q-shape", lambda c: design_lqr(c, Q=np.eye(3)), "Q has shape (3, 3)"),
    ("lqr-R-complex", lambda c: design_lqr(c, R=np.array([[1 + 1j]])), "R = "),
    ("lqr-controls-None", lambda c: design_lqr(c, controls=None), "controls = None"),
    ("lqr-controls-string", lambda c: design_lqr(c, controls=HM), f"controls = {HM!r}"),
    ("lqr-controls-empty", lambda c: design_lqr(c, controls=[]), "controls = []"),
    ("lqr-controls-twice", lambda c: design_lqr(c, controls=[HM, HM]), "appears twice"),
    ("lqr-controls-unknown", lambda c: design_lqr(c, controls=["elevator"]), "'elevator'"),
    ("lqr-sys-None", lambda c: design_lqr(c, sys=None), "sys = None"),
    ("lqr-sys-discrete", lambda c: design_lqr(c, sys=c.design.sample(1e-3)), "discrete-time"),
    ("lqr-rate-0", lambda c: design_lqr(c, sample_rate=0.0), "sample_rate = 0"),
    ("lqr-rate-nan", lambda c: design_lqr(c, sample_rate=NAN), "sample_rate = nan"),
    ("lqr-rate-huge", lambda c: design_lqr(c, sample_rate=1e9), "sample_rate = 1e+09"),
    ("lqr-state-map-rows", lambda c: design_lqr(c, state_map=np.eye(3)), "state_map has 3 rows"),
    ("lqr-state-map-string", lambda c: design_lqr(c, state_map="x"), "state_map = 'x'"),
    (
        "lqr-bryson-dict",
        lambda c: lqr_controller(c.design, [HM], bryson={"tip_disp": 1}),
        "bryson = {",
    ),
    ("lqr-no-weights", lambda c: lqr_controller(c.design, [HM]), "give Q and R, or bryson"),
    (
        "bryson-outputs-list",
        lambda c: Bryson(outputs=["tip_disp"], inputs={HM: 1.0}),
        "bryson.outputs = ['tip_disp']",
    ),
    ("bryson-inputs-int", lambda c: Bryson({"tip_disp": 1.0}, 5), "bryson.inputs = 5"),
    ("bryson-huge", lambda c: Bryson({"tip_disp": 1e300}, {HM: 1.0}), "bryson.outputs['tip_disp']"),
    ("bryson-tiny", lambda c: Bryson({"tip_disp": 1e-300}, {HM: 1.0}), "= 1e-300"),
    ("bryson-zero", lambda c: Bryson({"tip_disp": 0.05}, {HM: 0}), f"bryson.inputs[{HM!r}] = 0"),
    ("bryson-nan", lambda c: Bryson({"tip_disp": NAN}, {HM: 1.0}), "= nan"),
    ("bryson-key", lambda c: Bryson({5: 1.0}, {HM: 1.0}), "key 5"),
    ("bryson-state-weight", lambda c: Bryson({"tip_disp": 1.0}, {HM: 1.0}, -1.0), "state_weight"),
    # plant helpers
    ("limits-list", lambda c: Limits(magnitude=[1.0]), "limits.magnitude = [1.0]"),
    ("limits-inf", lambda c: Limits(rate={HM: INF}), f"limits.rate[{HM!r}] = inf"),
    ("filters-order-float", lambda c: with_sensor_filters(c.plant, OUTS, 30.0, 2.0), "order = 2.0"),
    ("filters-cutoff-nan", lambda c: with_sensor_filters(c.plant, OUTS, NAN), "cutoff = nan"),
    (
        "filters-sensors-string",
        lambda c: with_sensor_filters(c.plant, "tip_twist", 30.0),
        "sensors = 'tip_twist'",
    ),
    ("filters-sys-None", lambda c: with_sensor_filters(None, OUTS, 30.0), "sys = None"),
    ("state-map-None", lambda c: state_map(None, c.builder), "plant_builder = None"),
    # gusts
    ("gust-length-tiny", lambda c: OneMinusCosine(length=1e-300, amplitude=1.0), "gust.length"),
    ("gust-length-nan", lambda c: OneMinusCosine(NAN, 1.0), "gust.length = nan"),
    ("gust-amplitude", lambda c: OneMinusCosine(10.0, 100.0), "gust.amplitude = 100"),
    ("gust-start-negative", lambda c: OneMinusCosine(10.0, 1.0, -1.0), "gust.start = -1"),
    ("gust-start-late", lambda c: OneMinusCosine(10.0, 1.0, 1e4), "gust.start = 10000"),
    ("gust-speed-nan", lambda c: OneMinusCosine(10.0, 1.0)(T, NAN), "speed = nan"),
    ("turbulence-sigma", lambda c: Turbulence(sigma=100.0), "turbulence.sigma = 100"),
    ("turbulence-sigma-neg", lambda c: Turbulence(sigma=-1.0), "turbulence.sigma = -1"),
    ("turbulence-scale-zero", lambda c: Turbulence(1.0, 0.0), "turbulence.scale = 0"),
    ("turbulence-scale-huge", lambda c: Turbulence(1.0, 1e6), "turbulence.scale = 1e+06"),
    ("turbulence-seed", lambda c: Turbulence(1.0, seed=1.5), "turbulence.seed = 1.5"),
    ("turbulence-model", lambda c: Turbulence(1.0, model=5), "turbulence.model = 5"),
    ("turbulence-speed-zero", lambda c: Turbulence(1.0)(T, 0.0), "speed = 0"),
    ("series-velocity", lambda c: GustSeries((0, 1), (0, 100)), "velocity[1] = 100"),
    ("series-time-late", lambda c: GustSeries((0, 1e4), (0, 1)), "time[1] = 10000"),
    ("series-time-nan", lambda c: GustSeries((0, NAN), (0, 1)), "time[1] = nan"),
    ("series-time-string", lambda c: GustSeries("ab", (0, 1)), "time = 'ab'"),
    ("series-ragged", lambda c: GustSeries([0, [1, 2]], (0, 1)), "gust series: time"),
    ("series-decreasing", lambda c: GustSeries((0, 2, 1), (0, 1, 0)), "time[2] = 1"),
    ("series-lengths", lambda c: GustSeries((0, 1, 2), (0, 1)), "same length"),
    # simulate
    ("sim-duration-huge", lambda c: sim(c, duration=1e9), "limit of 10000000 samples"),
    (
        "sim-memory",
        lambda c: sim(c, duration=9000.0, record_states=True),
        "above the limit of 1 GiB",
    ),
    ("sim-duration-nan", lambda c: sim(c, duration=NAN), "duration = nan"),
    ("sim-duration-zero", lambda c: sim(c, duration=0.0), "duration = 0"),
    ("sim-duration-string", lambda c: sim(c, duration="1"), "duration = '1'"),
    ("sim-duration-short", lambda c: sim(c, duration=1e-9), "shorter than one sample"),
    ("sim-plant-None", lambda c: sim(c, plant=None), "plant = None"),
    ("sim-plant-discrete", lambda c: sim(c, plant=c.plant.sample(1e-3)), "plant: a discrete"),
    ("sim-controller-None", lambda c: sim(c, controller=None), "controller = None"),
    ("sim-controller-dt", lambda c: sim(c, controller=OpenLoop((HM,), 0.0)), "controller.dt"),
    (
        "sim-noise-negative",
        lambda c: sim(c, sensor_noise={"tip_twist": -1.0}),
        "sensor_noise['tip_twist'] = -1",
    ),
    ("sim-noise-nan", lambda c: sim(c, sensor_noise={"tip_twist": NAN}), "= nan"),
    ("sim-noise-unknown", lambda c: sim(c, sensor_noise={"foo": 1.0}), "sensor_noise: 'foo'"),
    ("sim-noise-list", lambda c: sim(c, sensor_noise=[1.0]), "sensor_noise = [1.0]"),
    ("sim-x0-nan", lambda c: sim(c, x0=np.full(c.plant.nstates, NAN)), "x0: has NaN"),
    ("sim-x0-shape", lambda c: sim(c, x0=np.zeros(3)), "x0: expected"),
    ("sim-x0-string", lambda c: sim(c, x0="abc"), "x0 = 'abc'"),
    ("sim-disturbance-int", lambda c: sim(c, disturbance=5), "disturbance = 5"),
    (
        "sim-disturbance-shape",
        lambda c: sim(c, disturbance=lambda t, v: np.zeros(3)),
        "disturbance: returned",
    ),
    ("sim-limits-dict", lambda c: sim(c, limits={HM: 1.0}), "limits = {"),
    ("sim-delay-string", lambda c: sim(c, delay="yes"), "delay = 'yes'"),
    ("sim-record-int", lambda c: sim(c, record_states=1), "record_states = 1"),
    ("sim-outputs-string", lambda c: sim(c, outputs="tip_disp"), "outputs = 'tip_disp'"),
    ("sim-outputs-empty", lambda c: sim(c, outputs=[]), "outputs = []"),
    ("sim-outputs-unknown", lambda c: sim(c, outputs=["foo"]), "output 'foo'"),
    ("sim-seed", lambda c: sim(c, seed=-1), "seed = -1"),
]


def test_corpus_is_large_and_ids_unique():
    ids = [case[0] for case in CORPUS]
    assert len(ids) >= 60
    assert len(set(ids)) == len(ids)


@pytest.mark.parametrize(
    "call,fragment", [case[1:] for case in CORPUS], ids=[case[0] for case in CORPUS]
)
def test_bad_call_is_refused(ctx, call, fragment):
    with pytest.raises(InputError, match=re.escape(fragment)) as info:
        call(ctx)
    assert issubclass(type(info.value), InputError)
    message = str(info.value)
    assert "\n" not in message, message
    assert fragment in message, message


# -- fuzzing the numeric arguments --------------------------------------------------------------

ODD = st.one_of(
    st.none(),
    st.booleans(),
    st.text(max_size=4),
    st.lists(st.floats(allow_nan=True, allow_infinity=True), max_size=3),
)
NUMBER = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-(10**30), max_value=10**30),
    ODD,
)
FUZZ = settings(max_examples=60, deadline=None, database=None)


def often(allowed, other=NUMBER):
    """``allowed`` 3 times in 4, otherwise ``other`` (``one_of`` would flatten and dilute it)."""
    return st.integers(0, 3).flatmap(lambda k: other if k == 0 else allowed)


def mixed(lo: float, hi: float):
    """Allowed values (the bounds included) 3 times in 4, otherwise anything of :data:`NUMBER`."""
    return often(st.one_of(st.floats(lo, hi), st.sampled_from([lo, hi])))


def succeeds_or_refuses(call) -> None:
    """The call returns, or raises InputError; any RuntimeWarning is an error."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        try:
            call()
        except InputError as exc:
            assert "\n" not in str(exc), str(exc)
            event("refused")
        else:
            event("accepted")


@FUZZ
@given(speed=mixed(0.0, 1000.0), density=mixed(1e-4, 2.0))
def test_fuzz_statespace(ctx, speed, density):
    succeeds_or_refuses(
        lambda: aes.statespace(ctx.model, speed, density, inputs=[HM], outputs=OUTS, n_modes=4)
    )


@FUZZ
@given(
    speeds=often(
        st.lists(st.floats(0.0, 1000.0), min_size=1, max_size=4, unique=True).map(sorted),
        st.one_of(
            st.lists(st.floats(allow_nan=True, allow_infinity=True), max_size=4),
            st.lists(st.integers(-(10**6), 10**6), max_size=4, unique=True).map(sorted),
            NUMBER,
        ),
    )
)
def test_fuzz_eigen_sweep(ctx, speeds):
    succeeds_or_refuses(lambda: aes.eigen_sweep(ctx.small, speeds, RHO))


@FUZZ
@given(
    length=mixed(0.01, 1e5),
    amplitude=mixed(-50.0, 50.0),
    start=mixed(0.0, 600.0),
    speed=mixed(0.0, 1000.0),
)
def test_fuzz_one_minus_cosine(length, amplitude, start, speed):
    def call():
        gust = OneMinusCosine(length, amplitude, start)
        gust(T, speed)

    succeeds_or_refuses(call)


@FUZZ
@given(
    order=often(st.sampled_from([0, 1, 2])),
    bandwidth=mixed(1e-3, 1e6),
    damping=mixed(1e-3, 100.0),
)
def test_fuzz_servo(ctx, order, bandwidth, damping):
    def call():
        servo = Servo(order, bandwidth, damping)
        aes.statespace(ctx.model, 100.0, RHO, inputs=["aileron_command"], servo=servo, n_modes=4)

    succeeds_or_refuses(call)


@FUZZ
@given(rate=mixed(1.0, 1e5))
def test_fuzz_lqr_sample_rate(ctx, rate):
    succeeds_or_refuses(
        lambda: lqr_controller(ctx.design, [HM], bryson=ctx.bryson, sample_rate=rate)
    )
