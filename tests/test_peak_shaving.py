"""ROSCO's peak shaving (``PS_Mode = 1``) in the workbench's ROSCO (issue 27, item 4).

Oracles: the DISCON.IN's own table (``PS_WindSpeeds``, ``PS_BldPitchMin``) for the limit, and
ROSCO's compiled library itself for the wind-speed estimate: its debug output (``LoggingLevel =
1``: ``WE_Vw``, the extended Kalman filter's estimate, and ``PC_MinPit``, the limit it sets) on a
run of the workbench's simulator, against the ported estimator replayed on the same run's
signals. The slow agreement of the tower DEL with the compiled DISCON is in
tests/test_constant_power.py.
"""
import dataclasses
import warnings

import numpy as np
import pytest

import specdesign.rosco.discon as discon_module
from specdesign.controller.peak_shaving import (
    PEAK_SHAVING_STATES,
    S_VW,
    PeakShaving,
    peak_shaving_from_discon,
    peak_shaving_step,
    tsr_reference,
)
from specdesign.export import export_discon
from specdesign.rosco import (
    Discon,
    from_discon,
    iea15mw_discon,
    rosco_scheduled,
    rosco_test_cases,
    write_discon,
)
from specdesign.simulate import ScheduledController, simulate
from specdesign.turbine import from_openfast, iea15mw


@pytest.fixture(scope="module")
def nrel():
    try:
        cases = rosco_test_cases()
    except ModuleNotFoundError as e:
        pytest.skip(f"the rosco package is not installed ({e})")
    path = cases / "NREL-5MW/DISCON.IN"
    return path, from_openfast(path.parent / "NREL-5MW.fst")


def test_limit_is_the_files_table_above_fine_pitch():
    m = iea15mw()
    ps = peak_shaving_from_discon(iea15mw_discon(), m.tsr_grid, m.pitch_grid, m.cp_table)
    entries = {}
    for line in iea15mw_discon().read_text().splitlines():
        left, _, right = line.partition("!")
        if right.split():
            entries[right.split()[0]] = left.split()
    v = np.array(entries["PS_WindSpeeds"], float)
    b = np.array(entries["PS_BldPitchMin"], float)
    np.testing.assert_array_equal(ps.wind_speeds, v)
    np.testing.assert_array_equal(ps.min_pitch, b)
    # at a table point the table's value (ROSCO's interp1d), held at the ends, never below fine pitch
    k = int(np.argmax(b > 0.05))
    assert ps.limit(v[k]) == pytest.approx(b[k], abs=1e-15)
    assert ps.limit(0.5 * (v[k] + v[k + 1])) == pytest.approx(0.5 * (b[k] + b[k + 1]), rel=1e-12)
    assert ps.limit(100.0) == b[-1] and ps.limit(0.0) == max(b[0], ps.fine_pitch)


def test_off_and_refused(tmp_path):
    m = iea15mw()
    grids = (m.tsr_grid, m.pitch_grid, m.cp_table)
    assert peak_shaving_from_discon(write_discon(iea15mw_discon(), tmp_path / "a.IN", PS_Mode=0), *grids) is None
    # an estimator the workbench does not run: refused, naming the file, the line, the key and the fix
    bad = write_discon(iea15mw_discon(), tmp_path / "b.IN", WE_Mode=1)
    with pytest.raises(ValueError, match=r"b\.IN: line \d+: WE_Mode = 1 .*PS_Mode = 0"):
        peak_shaving_from_discon(bad, *grids)
    with pytest.raises(ValueError, match=r"b\.IN: line \d+: WE_Mode = 1 .*PS_Mode = 0"):
        rosco_scheduled(m, schedule=from_discon(bad))
    assert rosco_scheduled(m, schedule=from_discon(bad), peak_shaving=False).peak_shaving is None
    ps = peak_shaving_from_discon(iea15mw_discon(), *grids)
    with pytest.raises(ValueError, match="cp_table must be finite with shape"):
        dataclasses.replace(ps, cp_table=ps.cp_table[:, 1:])
    sc = rosco_scheduled(m)
    with pytest.raises(TypeError, match="peak_shaving must be a PeakShaving"):
        dataclasses.replace(sc, peak_shaving="yes")
    with pytest.raises(ValueError, match="for form='gains' only"):
        ScheduledController(np.zeros(1), sc.pitch[:1], peak_shaving=ps)


def test_rosco_scheduled_carries_the_files_peak_shaving():
    m = iea15mw()
    sc = rosco_scheduled(m, schedule=from_discon(iea15mw_discon()))
    assert isinstance(sc.peak_shaving, PeakShaving) and sc.peak_shaving.inertia > 0
    assert rosco_scheduled(m, schedule=from_discon(iea15mw_discon()), peak_shaving=False).peak_shaving is None
    assert rosco_scheduled(m).peak_shaving is None  # the model's own schedule: no file, no peak shaving


def test_estimator_and_limit_match_roscos_own(nrel, monkeypatch, tmp_path):
    """The ported estimator replayed on a run of the compiled DISCON (its own inputs: the rotor
    speed, its last pitch command, the torque from the electrical power) gives ROSCO's WE_Vw and
    PC_MinPit of that run's debug file. Measured: within 6e-5 m/s and 5e-7 rad over 60 s."""
    path, model = nrel
    folders = []
    run_copy = discon_module._run_copy

    def with_debug_file(discon_in, folder):  # the harness turns ROSCO's debug output off; on for this run
        out = run_copy(discon_in, folder)
        lines = [("1" + ln[1:]) if "! LoggingLevel" in ln else ln for ln in out.read_text().splitlines()]
        out.write_text("\n".join(lines) + "\n")
        folders.append(folder)
        return out

    monkeypatch.setattr(discon_module, "_run_copy", with_debug_file)
    dt = 0.02
    d = Discon(path)
    try:
        r = simulate(model, d, [19.0], seeds=[1], duration=60.0, transient=0.0, dt=dt, record_dt=dt)
        text = (folders[0] / "run0").read_text().splitlines()
    finally:
        d.close()
    names = text[1].split()
    dbg = np.array([[float(x) for x in ln.split()] for ln in text[3:] if ln.strip()])
    ps = peak_shaving_from_discon(path, model.tsr_grid, model.pitch_grid, model.cp_table)
    p, st = ps.params(), np.zeros(PEAK_SHAVING_STATES)
    om, cmd, power = r["gen_speed"][0, 0], r["pitch_cmd"][0, 0], r["power"][0, 0]
    torque = power / (model.generator_efficiency * om)
    lim, vw = np.empty(om.size), np.empty(om.size)
    for k in range(om.size):
        lim[k] = peak_shaving_step(p, st, om[k], cmd[k], torque[k], r["wind"][0, 0, 0], dt, k == 0)
        vw[k] = st[S_VW]  # the estimate WE_Vw
    n = min(dbg.shape[0], om.size)
    assert n > 2500
    np.testing.assert_allclose(dbg[:n, 0], np.arange(n) * dt, atol=1e-4)  # the same steps
    we, pc = dbg[:n, names.index("WE_Vw")], dbg[:n, names.index("PC_MinPit")]
    assert np.ptp(we) > 1.0 and np.ptp(pc) > 0.02  # the estimate and the limit move: the check can fail
    np.testing.assert_allclose(vw[:n], we, atol=1e-3)  # the debug file's 6 significant digits
    np.testing.assert_allclose(lim[:n], pc, atol=2e-6)
    # fed the measured pitch instead of ROSCO's own last command, the estimate strays by ~0.1 m/s
    st2, vw2 = np.zeros(PEAK_SHAVING_STATES), np.empty(n)
    for k in range(n):
        peak_shaving_step(p, st2, om[k], r["pitch"][0, 0, k], torque[k], r["wind"][0, 0, 0], dt, k == 0)
        vw2[k] = st2[S_VW]
    assert np.abs(vw2 - we).max() > 0.05


def test_peak_shaving_holds_the_pitch_in_a_lull(nrel):
    # 15 m/s, 3.6 m/s above rated: without peak shaving the NREL 5 MW's PI reaches fine pitch in
    # the lulls; with it the command stays above the file's table at the estimated wind
    path, model = nrel
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        on = rosco_scheduled(model, schedule=from_discon(path), scheduling_filter="rosco")
    off = dataclasses.replace(on, peak_shaving=None)
    kw = {"seeds": [1], "duration": 300.0}
    a, b = simulate(model, on, [15.0], **kw), simulate(model, off, [15.0], **kw)
    assert np.degrees(b["pitch_cmd"].min()) < 0.01
    assert np.degrees(a["pitch_cmd"].min()) > 1.5
    assert a["pitch_cmd"].min() >= on.peak_shaving.min_pitch.min()


def test_export_refuses_peak_shaving(tmp_path):
    sc = rosco_scheduled(iea15mw(), schedule=from_discon(iea15mw_discon()))
    with pytest.raises(ValueError, match=r"peak shaving .*peak_shaving=None"):
        export_discon(sc, tmp_path)


def test_mode_2_reference_is_the_tsr_on_the_estimate(nrel, tmp_path):
    # ROSCO's VS_ControlMode = 2 (ComputeVariablesSetpoints): VS_TSRopt·WE_Vw/WE_BladeRadius
    path, model = nrel
    grids = (model.tsr_grid, model.pitch_grid, model.cp_table)
    ps = peak_shaving_from_discon(path, *grids)
    assert ps.tsr == 7.5 and ps.rotor_radius == 63.0  # the file's VS_TSRopt and WE_BladeRadius
    st = np.zeros(PEAK_SHAVING_STATES)
    st[S_VW] = 20.0
    assert tsr_reference(ps.params(), st) == pytest.approx(7.5 * 20.0 / 63.0, rel=1e-15)
    mode3 = peak_shaving_from_discon(write_discon(path, tmp_path / "m3.IN", VS_ControlMode=3), *grids)
    assert mode3.tsr == 0.0 and np.isnan(tsr_reference(mode3.params(), st))
