"""The compiled loop's shortcuts (issue 16 part 4) change no result: identical bank locals run
once, Cp and Ct from one cell lookup, the loop checks answered once per plant, controller,
wind speed and step. Each against the computation the shortcut replaces."""
import dataclasses

import control
import numpy as np
import pytest

from specdesign import closedloop, turbine
from specdesign import simulate as sm
from specdesign.controller.scheduled import controller_bank
from specdesign.simulate import checks, core
from specdesign.simulate.checks import checked_loop
from specdesign.turbine.kernel import HEADER_SIZE, bicubic


@pytest.fixture(scope="module")
def model():
    return turbine.iea15mw()


def _every_local(Ad, Bd, Cd, Dd, Rq, Ns):
    return np.arange(Rq.size, dtype=np.int64)


def test_identical_locals_run_once_is_bitwise_every_local_run(model, monkeypatch):
    """Oracle: the same loop running every local of the bank (no merging)."""
    rosco = sm.rosco_scheduled(model)
    atd = control.tf([-0.014187, -0.014187 * 4.357], [1, 0.3276])
    same_atd = dataclasses.replace(rosco, atd=tuple(atd for _ in rosco.pitch), name="ATD")
    # output-blended locals, each an integrating lag (slow modes: conditional integration at the
    # pitch floor, which 13 m/s reaches)
    lag = turbine.rosco_baseline(model, 19.0) * control.tf([1, 0.05], [1, 0.02])
    blended = sm.scheduled(model, {v: lag for v in (13.0, 19.0, 25.0)})
    kw = dict(seeds=[1], duration=60.0, transient=5.0)
    for c in (rosco, same_atd, blended):
        assert len(set(core._same_locals(*_bank(c)).tolist())) < len(c.pitch)  # something is merged
        merged = sm.simulate(model, c, [13.0, 19.0], **kw)
        with monkeypatch.context() as m:
            m.setattr(core, "_same_locals", _every_local)
            every = sm.simulate(model, c, [13.0, 19.0], **kw)
        for k in merged.outputs:
            assert np.array_equal(merged[k], every[k]), (c.name, k)


def _bank(c):
    """The padded bank arrays simulate builds (Ad, Bd, Cd, Dd, Rq, Ns)."""
    _, mats, _, _ = controller_bank(c, 0.02)
    K, nc = len(mats), max(1, max(m[0].shape[0] for m in mats))
    Ad, Bd, Cd, Dd = np.zeros((K, nc, nc)), np.zeros((K, nc, 2)), np.zeros((K, nc)), np.zeros((K, 2))
    Rq, Ns = np.zeros(K), np.zeros(K, dtype=np.int64)
    for q, (A, B, C, D, r, ns) in enumerate(mats):
        n = A.shape[0]
        Ad[q, :n, :n], Bd[q, :n, :], Cd[q, :n], Dd[q, :], Rq[q], Ns[q] = A, B, C, D, r, ns
    return Ad, Bd, Cd, Dd, Rq, Ns


def test_aero_loads_are_two_bicubic_evaluations(model):
    """aero_loads looks the cell up once for Cp and Ct; oracle: bicubic on each table and the
    loads written out (torque = q·R·Cp/λ, thrust = q·Ct, q = ½ρπR²v²), equal bit for bit,
    inside the table and beyond its edges (held there)."""
    p = model.kernel_params()
    n_cells = (int(p[turbine.P_N_TSR]) - 1) * (int(p[turbine.P_N_PITCH]) - 1) * 16
    radius, rho = p[turbine.P_RADIUS], p[turbine.P_RHO]
    rng = np.random.default_rng(3)
    for omega, v, beta in zip(rng.uniform(0.2, 1.2, 200), rng.uniform(1.0, 30.0, 200), rng.uniform(-0.2, 0.6, 200)):
        tsr = omega * radius / v
        cp = bicubic(p, HEADER_SIZE, tsr, beta)
        ct = bicubic(p, HEADER_SIZE + n_cells, tsr, beta)
        q = 0.5 * rho * (np.pi * radius * radius) * v * v
        assert turbine.aero_loads(p, omega, v, beta) == (q * radius * cp / tsr, q * ct)


def test_checked_loop_answers_once_per_plant_controller_speed_and_step(model, monkeypatch):
    """Oracle: closedloop.unstable_poles and check_loop_step called directly."""
    plant = sm.turbine_plant(model)
    c = turbine.rosco_baseline(model, 19.0)
    calls = []
    real = closedloop.unstable_poles

    def counted(*a, **kw):
        calls.append(a[2])
        return real(*a, **kw)

    monkeypatch.setattr(checks, "unstable_poles", counted)  # the name checked_loop looks up
    assert checked_loop(plant, c, 19.0, 0.02).size == 0 == real(plant, c, 19.0).size
    assert checked_loop(plant, c, 19.0, 0.02).size == 0
    assert calls == [19.0]
    checked_loop(plant, c, 19.0, 0.01)  # another step, another controller object: asked again
    checked_loop(plant, turbine.rosco_baseline(model, 19.0), 19.0, 0.02)
    assert len(calls) == 3
    # an unstable loop's poles (ROSCO's gains at 19 m/s × 20): the same as asked directly
    hot = 20.0 * c
    bad = checked_loop(plant, hot, 19.0, 0.02)
    assert bad.size and np.array_equal(bad, real(plant, hot, 19.0))
    # a step the sampled loop cannot take is refused every time, as check_loop_step refuses it
    for _ in range(2):
        with pytest.raises(ValueError, match="too large for controller"):
            checked_loop(plant, c, 19.0, 0.9)
        with pytest.raises(ValueError, match="too large for controller"):
            sm.check_loop_step(plant, c, 19.0, 0.9)


class _Inline:
    """An executor running each task at once, in submission order: the serial campaign."""

    def submit(self, fn, *args):
        import concurrent.futures as cf

        f = cf.Future()
        f.set_result(fn(*args))
        return f


def test_local_campaign_two_speeds_at_a_time_is_bitwise_the_serial_one(model, monkeypatch):
    """Oracle: the same campaign with its tasks run one after the other (an inline executor)."""
    from test_campaign_store import assert_bitwise_equal

    from specdesign import validate
    from specdesign.validate import campaign as vc

    rosco = sm.rosco_scheduled(model)
    ctrls = {"ROSCO": rosco, "PI19": turbine.rosco_baseline(model, 19.0)}
    kw = dict(model=model, duration=60.0, transient=5.0, keep_series=1, progress=False)
    serial = validate.run_campaign(ctrls, [15.0, 19.0, 23.0], [1, 2], executor=_Inline(), **kw)
    used = []
    real = vc._overlap
    monkeypatch.setattr(vc, "_overlap", lambda c: used.append(real(c)) or used[-1])
    local = validate.run_campaign(ctrls, [15.0, 19.0, 23.0], [1, 2], **kw)
    import numba

    assert used == [numba.threading_layer() in ("omp", "tbb")]
    assert_bitwise_equal(local, serial)
    if not used[0]:
        pytest.skip("numba's threading layer is the workqueue: the campaign stayed serial")
