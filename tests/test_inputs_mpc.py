"""A NaN measurement (issue "Nothing silently wrong, part two"): QuadraticMPC, HealthMPC and
ROSCO's Discon behave the same documented way (specdesign._checks.bad_measurements): the run
with the bad sample holds its last command and its state, one RuntimeWarning names the signal,
the time and the run, and the controller resumes at the next finite sample. One NaN gen_speed
sample used to make both MPCs return NaN forever after; a callable that passes the NaN through
is stopped with a message naming the measurement."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

from specdesign.mpc import HealthMPC, QuadraticMPC
from specdesign.simulate import simulate
from specdesign.turbine import iea15mw


@pytest.fixture(scope="module")
def model():
    return iea15mw()


class Inject:
    """Wraps a controller; sets ``signal`` of run 0 to ``value`` for t in [t0, t1) s (in the
    arrays the simulator hands over: a sensor that drops out)."""

    def __init__(self, inner, signal="gen_speed", t0=5.0, t1=5.35, value=np.nan):
        self.inner, self.signal, self.t0, self.t1, self.value = inner, signal, t0, t1, value
        self.__name__ = "inject"

    def start(self, *a):
        if hasattr(self.inner, "start"):
            self.inner.start(*a)

    def __call__(self, t, y):
        if self.t0 <= t < self.t1:
            y[self.signal][0] = self.value
        return self.inner(t, y)


KW = dict(seeds=[3, 4], duration=10.0, transient=0.0, record_dt=0.02)


def _run(model, ctrl, **kw):
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always", RuntimeWarning)
        r = simulate(model, ctrl, [19.0, 19.0], **{**KW, **kw})
    return r, [str(x.message) for x in w if issubclass(x.category, RuntimeWarning)]


@pytest.mark.parametrize("make, signal", [(lambda m: QuadraticMPC(m), "gen_speed"),
                                          (lambda m: QuadraticMPC(m), "tower_top_acc"),
                                          (lambda m: HealthMPC(m, health_weight=10.0), "gen_speed"),
                                          (lambda m: HealthMPC(m, health_weight=10.0), "blade_root_my")])
@pytest.mark.parametrize("value", [np.nan, np.inf])
def test_a_bad_sample_holds_the_command_warns_once_and_resumes(model, make, signal, value):
    clean, _ = _run(model, make(model))
    r, msgs = _run(model, Inject(make(model), signal, value=value))
    cmd = r["pitch_cmd"]
    assert np.all(np.isfinite(cmd))  # it used to be NaN forever after
    # the ts = 0.1 s samples at 5.0, 5.1, 5.2 and 5.3 s are bad; commands recorded every 0.02 s
    # (a record holds the command of the step before it): the command of the 4.9 s sample is held
    t = np.arange(cmd.shape[-1]) * 0.02
    held = (t > 4.9 + 1e-9) & (t <= 5.4 + 1e-9)
    run0 = cmd[0, 0]
    assert np.all(run0[held] == run0[np.flatnonzero(t <= 4.9 + 1e-9)[-1] + 1])
    # up to then both runs are the clean ones, and run 1 (finite samples) never departs from them
    before = t <= 4.9 + 1e-9
    np.testing.assert_array_equal(run0[before], clean["pitch_cmd"][0, 0][before])
    np.testing.assert_array_equal(cmd[1, 0], clean["pitch_cmd"][1, 0])
    # it resumes: the command moves again after the bad samples
    assert np.ptp(run0[t > 5.5]) > 0
    ours = [m for m in msgs if "holds its last command" in m]
    assert len(ours) == 1 and f"measurement {signal!r}" in ours[0] and "t = 5 s (run 0)" in ours[0]


def test_a_callable_that_passes_nan_through_is_stopped_naming_the_measurement(model):
    beta = model.trim(19.0).pitch

    def naive(t, y):  # a controller with no guard: the NaN reaches its command
        return beta + 0.0 * y["gen_speed"]

    naive.__name__ = "naive"
    with pytest.raises(ValueError, match=r"finite pitch command .* at t = 5(\.\d+)? s; its measurements held NaN or "
                                         r"inf in gen_speed \(run 0\)"):
        simulate(model, Inject(naive), [19.0, 19.0], **KW)


def test_campaign_names_the_measurement(model):
    from specdesign.validate import run_campaign

    beta = model.trim(19.0).pitch

    class Naive:
        __name__ = "naive"

        def __call__(self, t, y):
            return beta + 0.0 * y["gen_speed"]

    with pytest.raises(ValueError, match=r"gen_speed \(run 0\)"):
        run_campaign({"naive": Inject(Naive())}, [19.0], [1], model=model, duration=10.0, transient=0.0,
                     predict=False)


def test_discon_holds_too(model):
    from specdesign.rosco import Discon, rosco_test_cases

    try:
        deck = rosco_test_cases() / "IEA-15-240-RWT/IEA-15-240-RWT-Monopile"
    except ModuleNotFoundError as e:
        pytest.skip(f"the rosco package is not installed ({e})")
    d = deck / "IEA-15-240-RWT-Monopile_DISCON.IN"
    clean, _ = _run(model, Discon(d))
    r, msgs = _run(model, Inject(Discon(d), t0=5.0, t1=5.05))
    run0 = r["pitch_cmd"][0, 0]
    assert np.all(np.isfinite(r["pitch_cmd"])) and np.all(np.isfinite(r["power"]))
    # ROSCO is called every step (0.02 s): the steps at 5.00, 5.02 and 5.04 s are skipped, so
    # the command of the 4.98 s step is held in the records at 5.02, 5.04 and 5.06 s
    i = round(5.0 / 0.02)
    assert run0[i + 1] == run0[i + 2] == run0[i + 3]
    np.testing.assert_array_equal(run0[:i + 1], clean["pitch_cmd"][0, 0][:i + 1])
    np.testing.assert_array_equal(r["pitch_cmd"][1, 0], clean["pitch_cmd"][1, 0])
    ours = [m for m in msgs if "holds its last command" in m]
    assert len(ours) == 1 and "'gen_speed'" in ours[0]
    with pytest.raises(ValueError, match="not finite at the first call"):
        simulate(model, Inject(Discon(d), t0=0.0, t1=0.01), [19.0], seeds=[1], duration=1.0, transient=0.0)
