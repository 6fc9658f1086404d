"""LinearTurbine: the design loop on linear models (issue 15 part 2).

Oracle: a LinearTurbine built from the reduced model's own ``linearize(v)`` holds the same
plants as the model, so every step of the loop (baseline, ΔD%, shaping, linear prediction)
must give the model's own numbers through the other route. The .lin route is checked on
the shipped floating IEA 15 MW linearisation against the file's own matrices.
"""
import dataclasses
import warnings

import control
import numpy as np
import pytest
from numpy.testing import assert_allclose

from specdesign import spec
from specdesign.openfast import (
    DEFAULT_SIGNALS,
    LinearOperatingPoint,
    LinearTurbine,
    RotorModelSchedule,
    plant_from_linearization,
    read_linearization,
    rotor_speed_model,
)
from specdesign.rosco import first_order_rotor_model, rosco_baseline
from specdesign.turbine import iea15mw
from specdesign.validate import linear_prediction
from specdesign.validate.tables import linear_table3

SPEEDS = (15.0, 17.0, 19.0, 21.0, 23.0)


@pytest.fixture(scope="module")
def model():
    return iea15mw()


@pytest.fixture(scope="module")
def lt(model):
    return LinearTurbine.from_model(model, SPEEDS)


@pytest.fixture(scope="module")
def sample(package_data):
    return package_data / "sample_floating_19mps.1.lin"


@pytest.fixture(scope="module")
def floating(sample):
    return LinearTurbine.from_lin_files(sample)


# ----------------------------------------------------------------------------- oracle: two routes, same plants
def test_stored_plants_are_the_models(model, lt):
    for v in SPEEDS:
        a, b = lt.linearize(v), model.linearize(v)
        for k in "ABCD":
            assert_allclose(getattr(a, k), getattr(b, k), rtol=0, atol=0)
        assert a.input_labels == b.input_labels and a.output_labels == b.output_labels
    assert lt.wind_range == (15.0, 23.0) and lt.rotor_radius == model.rotor_radius


@pytest.mark.parametrize("v", [15.0, 19.0, 23.0])
def test_baseline_analysis_matches_the_model(model, lt, v):
    ref, got = spec.baseline_analysis(model, v), spec.baseline_analysis(lt, v)
    assert_allclose(got.t_response, ref.t_response, rtol=1e-12)
    assert_allclose(got.sensitivity, ref.sensitivity, rtol=1e-10, atol=1e-14)
    assert got.damage_rate == pytest.approx(ref.damage_rate, rel=1e-12)
    assert got.wind_psd == pytest.approx(ref.wind_psd, rel=1e-12)


def test_shaping_and_design_specifications_match_the_model(model, lt):
    ref = spec.shape_to_target(spec.baseline_analysis(model, 19.0), 15.0)
    got = spec.shape_to_target(spec.baseline_analysis(lt, 19.0), 15.0)
    assert got.notches == ref.notches
    assert got.promise.exact_del == pytest.approx(ref.promise.exact_del, rel=1e-10)
    dm, dl = spec.design_specifications(model, 19.0), spec.design_specifications(lt, 19.0)
    w = spec.default_omega(50)
    assert_allclose(dl.tower.response(w), dm.tower.response(w), rtol=1e-10)
    assert_allclose(dl.speed.response(w), dm.speed.response(w), rtol=1e-10)


@pytest.mark.parametrize("v", [17.0, 21.0])
def test_linear_prediction_matches_the_model(model, lt, v):
    c = rosco_baseline(model, v)
    ref, got = linear_prediction(model, c, v), linear_prediction(lt, c, v)
    assert got.del_ == pytest.approx(ref.del_, rel=1e-12)
    assert_allclose(got.psd, ref.psd, rtol=1e-10, atol=1e-14 * ref.psd.max())


def test_scheduled_controller_is_blended_at_the_sets_trim_pitch(model, lt):
    # ROSCO's gain-scheduled form: the blend weights come from trim(v).pitch, the model's here
    from specdesign.rosco import rosco_scheduled

    c = rosco_scheduled(model)
    for v in (17.0, 21.0):
        ref, got = linear_prediction(model, c, v), linear_prediction(lt, c, v)
        assert got.del_ == pytest.approx(ref.del_, rel=1e-12)


def test_pitch_and_tower_damper_prediction_equals_the_interconnection(model, lt):
    # a design's two loops as one controller (ScheduledController.fixed), predicted on the
    # LinearTurbine route, against Dirlik on |T|²S_W of closedloop.closed_loop's interconnection
    # of the same linearisation (control.interconnect: an independent closing of both loops) on
    # the same grid and wind PSD; rtol from the two frequency-response routes' round-off (the
    # PSD spans ~20 decades, Dirlik's moments sum it)
    from specdesign import closedloop, wind
    from specdesign.simulate import ScheduledController
    from specdesign.validate import prediction_grid

    v = 19.0
    pitch = rosco_baseline(model, v)
    atd = control.tf([-0.05, 0.0], [1.0, 0.8])  # rad per m/s of tower-top velocity, high-passed (damps the mode)
    got = linear_prediction(lt, ScheduledController.fixed(pitch, atd), v)
    w = prediction_grid()
    sw = wind.rotor_effective_spectrum(w, v, model.rotor_radius, turbulence_class="B") * wind.record_window(w)
    loop = closedloop.closed_loop(lt.linearize(v), pitch, atd, warn=False)
    assert got.del_ == pytest.approx(closedloop.closed_loop_del(loop, w, sw, 4.0), rel=1e-9)
    # the damper changes the prediction (so the ATD loop was closed), and a zero damper is no damper
    assert got.del_ != pytest.approx(linear_prediction(lt, pitch, v).del_, rel=1e-3)
    none = ScheduledController.fixed(pitch, control.tf([0.0], [1.0]))
    assert none.atd is None and linear_prediction(lt, none, v).del_ == linear_prediction(lt, pitch, v).del_


def test_plants_dict_route_equals_model_route(model, lt):
    from specdesign.rosco import rosco_gain_schedule

    ops = {v: LinearOperatingPoint(v, *(getattr(model.trim(v), k) for k in ("rotor_speed", "pitch", "gen_torque")))
           for v in SPEEDS}
    # any order of the dict: sorted by speed
    d = LinearTurbine.from_plants({v: model.linearize(v) for v in reversed(SPEEDS)}, rotor_radius=model.rotor_radius,
                                  operating_points=ops, schedule=rosco_gain_schedule(model))
    assert d.wind_speeds.tolist() == list(SPEEDS)
    assert spec.baseline_analysis(d, 19.0).damage_rate == pytest.approx(spec.baseline_analysis(lt, 19.0).damage_rate,
                                                                       rel=1e-14)


def test_interpolation_between_speeds_is_linear_in_the_matrices(model, lt):
    mid, lo, hi = lt.linearize(18.0), model.linearize(17.0), model.linearize(19.0)
    for k in "ABCD":
        assert_allclose(getattr(mid, k), 0.5 * (getattr(lo, k) + getattr(hi, k)), rtol=1e-14, atol=1e-300)
    op = lt.trim(18.0)
    assert op.pitch == pytest.approx(0.5 * (model.trim(17.0).pitch + model.trim(19.0).pitch), rel=1e-14)
    # and it is a fair stand-in for the model's own linearisation there (the matrices are smooth in v)
    w = 1j * np.array([0.1, 1.0, 3.0])
    ref = np.asarray(model.linearize(18.0)(w))[:2, :2]
    assert_allclose(np.asarray(mid(w))[:2, :2], ref, rtol=0.05)


def test_default_schedule_is_rosco_pole_placement_on_the_rotor_model(model):
    # independent: the reduced model's own first-order rotor model (kernel Jacobian row)
    lt = LinearTurbine.from_model(model, SPEEDS, schedule=None)
    assert isinstance(lt.schedule, RotorModelSchedule)
    for v in (15.0, 19.0, 23.0):
        _, a, b, bw = first_order_rotor_model(model, v)
        assert rotor_speed_model(lt.linearize(v)) == pytest.approx((a, b, bw), rel=1e-12)
        kp, ki = lt.schedule.gains(v)
        assert kp == pytest.approx((2 * 0.2 + a) / b, rel=1e-12) and ki == pytest.approx(0.04 / b, rel=1e-12)
    # the baseline is rosco_baseline's form with those gains: C(0.5j) from the gains and ROSCO's filter
    from specdesign.rosco import speed_filter

    kp, ki = lt.schedule.gains(19.0)
    s = 0.5j
    assert complex(lt.baseline_controller(19.0)(s)) == pytest.approx(complex((kp + ki / s) * speed_filter()(s)), rel=1e-12)


def test_linear_table3_rows(model, lt):
    designed = {v: rosco_baseline(model, v) * 1.0 for v in (17.0, 19.0)}  # the baseline itself: 0 %
    t = linear_table3(lt, designed, (17.0, 19.0), promised={17.0: 20.0, 19.0: 25.0})
    vals = t.values()
    assert [r[0] for r in t.rows] == ["Specification", "Linear prediction"]
    assert_allclose(vals[0], [20.0, 25.0, 22.5])
    assert_allclose(vals[1], 0.0, atol=1e-9)
    # a real design: the linear rows equal the predictions through the model's route
    c = rosco_baseline(model, 19.0) * control.tf([1.0, 0.2, 1.2], [1.0, 0.6, 1.2])
    row = linear_table3(lt, c, [19.0]).values()[0, 0]
    ref = 100 * (1 - linear_prediction(model, c, 19.0).del_ / linear_prediction(model, rosco_baseline(model, 19.0), 19.0).del_)
    assert row == pytest.approx(ref, rel=1e-10)


# ----------------------------------------------------------------------------- the .lin route
def test_lin_route_reads_the_file(sample, floating):
    data = read_linearization(sample)
    assert floating.wind_range == (19.0, 19.0) and floating.sources == (str(sample),)
    op = floating.trim(19.0)
    assert op.rotor_speed == pytest.approx(0.7919) and op.pitch == pytest.approx(0.2876)
    assert floating.rotor_radius == pytest.approx(np.sqrt(4.484e4 / np.pi), rel=1e-3)  # RtArea in the file
    p = floating.linearize(19.0)
    assert list(p.input_labels) == ["wind", "pitch_cmd", "gen_torque"]
    # D from wind to the tower-base moment is the file's (kN-m → N·m), unchanged by the state reduction
    y, u = list(data.y_desc), list(data.u_desc)
    iy, iu = y.index("ED TwrBsMyt, (N-m)"), u.index("IfW Extended input: horizontal wind speed (steady/uniform wind), m/s")
    assert p["tower_base_my", "wind"].D[0, 0] == data.D[iy, iu]
    # the azimuth and the two HydroDyn states nothing reads are removed
    assert p.nstates == data.A.shape[0] - 3
    assert not any("DOF_GeAz" in s and "derivative" not in s for s in p.state_labels)


def _lin_copy(sample, path, wind_speed, azimuth=None):
    lines = sample.read_text().splitlines()
    for i, line in enumerate(lines):
        if line.strip().startswith("Wind Speed:"):
            lines[i] = f"   Wind Speed:                         {wind_speed:.4f} m/s"
        if azimuth is not None and line.strip().startswith("Azimuth:"):
            lines[i] = f"   Azimuth:                             {azimuth:.4f} rad"
    path.write_text("\n".join(lines) + "\n")
    return path


def test_lin_files_grouped_by_wind_speed(sample, tmp_path):
    # two azimuths at 17 m/s (averaged by read_linearization) and one at 21 m/s, read by a glob
    a = _lin_copy(sample, tmp_path / "lin_17_a.lin", 17.0)
    b = _lin_copy(sample, tmp_path / "lin_17_b.lin", 17.0, azimuth=2.0944)
    c = _lin_copy(sample, tmp_path / "lin_21.lin", 21.0)
    lt = LinearTurbine.from_lin_files(str(tmp_path / "lin_*.lin"))
    assert lt.wind_speeds.tolist() == [17.0, 21.0] and lt.sources == (str(a), str(b), str(c))
    ref, _ = plant_from_linearization(read_linearization([a, b]))
    got = lt.linearize(17.0)
    for k in "ABCD":
        assert_allclose(getattr(got, k), getattr(ref, k), rtol=0, atol=0)
    mid, hi = lt.linearize(19.0), lt.linearize(21.0)
    assert_allclose(mid.A, 0.5 * (np.asarray(got.A) + np.asarray(hi.A)), rtol=1e-14, atol=1e-300)
    with pytest.raises(ValueError, match="17-21 m/s"):
        lt.linearize(16.0)


def test_tower_top_velocity_is_the_derivative_of_the_deflection(sample):
    lt = LinearTurbine.from_lin_files(sample, signals={"tower_top_disp": "YawBrTDxt"})
    p = lt.linearize(19.0)
    w = np.array([0.05, 0.2, 1.0, 5.0])
    vel = np.asarray(p["tower_top_vel", "pitch_cmd"](1j * w)).ravel()
    disp = np.asarray(p["tower_top_disp", "pitch_cmd"](1j * w)).ravel()
    assert_allclose(vel, 1j * w * disp, rtol=1e-8)


def test_floating_baseline_and_the_platform_mode(floating):
    base = spec.baseline_analysis(floating, 19.0)
    # ΔD% peaks at the closed-loop platform-pitch mode (OpenFAST: ~0.2 rad/s), not at the tower's
    peak = base.omega[np.argmax(base.sensitivity)]
    assert 0.15 < peak < 0.25
    c = floating.baseline_controller(19.0)
    pred = linear_prediction(floating, c, 19.0, omega=base.omega)
    assert pred.del_ > 0
    # the classic floating problem: a faster rotor-speed loop takes the platform mode's damping
    from specdesign.closedloop import unstable_poles

    fast = rosco_baseline(floating, 19.0, schedule=RotorModelSchedule(floating, omega_pc=0.4))
    bad = unstable_poles(floating.kernel_plant(), fast, 19.0)
    assert bad.size and np.all(np.abs(np.abs(bad.imag) - 0.21) < 0.03)


# ----------------------------------------------------------------------------- bad input
def test_missing_channel_names_it_and_lists_the_file(sample):
    with pytest.raises(ValueError, match=r"signal 'tower_base_my'.*NoSuchChannel.*TwrBsMyt"):
        LinearTurbine.from_lin_files(sample, signals={"tower_base_my": "NoSuchChannel"})
    with pytest.raises(ValueError, match=r"signals\['gen_speed'\] cannot be None"):
        LinearTurbine.from_lin_files(sample, signals={"gen_speed": None})
    with pytest.raises(ValueError, match="matches several"):
        LinearTurbine.from_lin_files(sample, signals={"extra": "Root"})
    with pytest.raises(ValueError, match="matches no"):
        LinearTurbine.from_lin_files(str(sample.parent / "nothing_*.lin"))


def test_optional_default_signal_can_be_left_out(sample):
    lt = LinearTurbine.from_lin_files(sample, signals={"power": None, "pitch": None})
    assert "power" not in lt.output_names and "gen_speed" in lt.output_names
    assert set(DEFAULT_SIGNALS) >= {"wind", "pitch_cmd", "gen_speed", "tower_base_my", "tower_top_vel"}


def test_speed_outside_the_set(lt, floating):
    for v in (14.9, 23.5):
        with pytest.raises(ValueError, match="outside the linearisations"):
            lt.linearize(v)
    with pytest.raises(ValueError, match=r"19 m/s only \(one linearisation\)"):
        floating.linearize(18.0)
    with pytest.raises(ValueError, match="outside the linearisations"):
        spec.baseline_analysis(floating, 20.0)


def test_bad_speed_sets(model):
    p = model.linearize(19.0)
    ops = [LinearOperatingPoint(v, 0.79, 0.2) for v in (17.0, 19.0, 19.0)]
    with pytest.raises(ValueError, match=r"repeat \[19.0\]"):
        LinearTurbine(np.array([17.0, 19.0, 19.0]), (p, p, p), tuple(ops), 120.0)
    ops = [LinearOperatingPoint(v, 0.79, 0.2) for v in (19.0, 17.0)]
    with pytest.raises(ValueError, match="strictly increasing"):
        LinearTurbine(np.array([19.0, 17.0]), (p, p), tuple(ops), 120.0)
    with pytest.raises(ValueError, match="as many plants"):
        LinearTurbine(np.array([17.0, 19.0]), (p,), tuple(ops), 120.0)
    with pytest.raises(ValueError, match="lacks the signals"):
        LinearTurbine.from_plants({19.0: p[["gen_speed", "tower_top_vel"], :]}, rotor_radius=120.0)
    with pytest.raises(ValueError, match="rotor_radius"):
        LinearTurbine.from_plants({19.0: p}, rotor_radius=-1.0)
    with pytest.raises(ValueError, match="non-empty dict"):
        LinearTurbine.from_plants({}, rotor_radius=120.0)


def test_plant_from_linearization_reports_signals(sample):
    plant, used = plant_from_linearization(read_linearization(sample))
    assert used["tower_top_vel"] == "d/dt ED YawBrTDxt, (m)"
    assert used["wind"].startswith("IfW Extended input: horizontal wind speed")
    assert plant.output_labels[:2] == ["gen_speed", "tower_base_my"]


# ----------------------------------------------------------------------------- designs
@pytest.fixture(scope="module")
def cases_lt(model):
    # the designs' plant cases are v ± 0.5, ± 1 m/s: stored, not interpolated, so the oracle is exact
    return LinearTurbine.from_model(model, (18.0, 18.5, 19.0, 19.5, 20.0))


def test_pitch_feasibility_on_floating(floating):
    from specdesign.feasibility import pitch_feasibility

    ds = spec.design_specifications(floating, 19.0, speed_relax_db=0.0, tower_relax_db=0.0)
    assert pitch_feasibility(floating, 19.0, ds.base.system, ds.speed).feasible  # the baseline meets its own


def test_specification_for_target_on_linear_turbine(model, cases_lt):
    # oracle: the same plants and baseline through the model's route give the same specification
    from specdesign.feasibility import specification_for_target

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        got, ref = specification_for_target(cases_lt, 19.0, 20.0), specification_for_target(model, 19.0, 20.0)
    assert got.promise.exact_del == pytest.approx(ref.promise.exact_del, rel=1e-6)


def test_design_qft_on_linear_turbine(model, cases_lt):
    from specdesign.qft import design_qft

    got, ref = design_qft(cases_lt, 19.0, 20.0), design_qft(model, 19.0, 20.0)
    assert got.success == ref.success and got.del_reduction == pytest.approx(ref.del_reduction, rel=1e-6)


def test_design_hinf_on_linear_turbine(model, cases_lt):
    from specdesign.hinf import design_hinf

    got, ref = design_hinf(cases_lt, 19.0), design_hinf(model, 19.0)
    assert got.predicted_del_reduction == pytest.approx(ref.predicted_del_reduction, rel=1e-6)
    assert got.gamma == pytest.approx(ref.gamma, rel=1e-6)


# ----------------------------------------------------------------------------- operating-point states, pickling
def test_lin_file_operating_point_states_and_outputs(sample, floating):
    """x and y of the operating point are the file's x_op and y_op (read here from the raw file's
    averaged data by description), a d/dt output is 0, and evaluate_outputs at the trim returns y."""
    data = read_linearization(sample)
    op = floating.trim(19.0)
    plant = floating.plants[0]
    desc = [d.replace(".", "_") for d in data.x_desc]
    assert len(op.x) == plant.nstates and len(op.y) == plant.noutputs
    for name, x in zip(plant.state_labels, op.x):
        assert x == data.x_op[desc.index(name)]
    y = dict(zip(plant.output_labels, op.y))
    for name, channel in (("gen_speed", "GenSpeed"), ("tower_base_my", "TwrBsMyt"), ("pitch", "BldPitch1")):
        i = next(i for i, d in enumerate(data.y_desc) if channel in d)
        assert y[name] == data.y_op[i]
    assert y["tower_top_vel"] == 0.0 and abs(y["gen_speed"] - op.rotor_speed) < 1e-3  # direct drive: GenSpeed = rotor
    assert_allclose(floating.evaluate_outputs(op.x, 19.0, op.pitch, op.gen_torque), op.y, rtol=0, atol=0)
    # off the trim: the plant's own linear map (a pitch step reaches the measured pitch 1:1 in OpenFAST)
    dy = floating.evaluate_outputs(op.x, 19.0, op.pitch + 0.01, op.gen_torque) - np.asarray(op.y)
    assert_allclose(dy, 0.01 * np.asarray(plant.D)[:, plant.input_labels.index("pitch_cmd")], rtol=1e-12)
    assert abs(dy[plant.output_labels.index("pitch")] - 0.01) < 1e-5


def test_from_model_operating_points_are_the_models_trims(model, lt):
    """from_model's states and outputs are the reduced model's trim and its outputs there; the
    actuator limits are the model's; between two speeds they interpolate linearly."""
    for v in SPEEDS:
        op, ref = lt.trim(v), model.trim(v)
        assert_allclose(op.x, ref.x, rtol=0, atol=0)
        assert_allclose(lt.evaluate_outputs(ref.x, v, ref.pitch, ref.gen_torque),
                        model.evaluate_outputs(ref.x, v, ref.pitch, ref.gen_torque), rtol=1e-12)
    assert (lt.pitch_min, lt.pitch_max, lt.pitch_rate_limit) == (model.pitch_min, model.pitch_max, model.pitch_rate_limit)
    assert_allclose(lt.trim(18.0).x, 0.5 * (np.asarray(model.trim(17.0).x) + np.asarray(model.trim(19.0).x)), rtol=1e-12)


def test_evaluate_outputs_needs_operating_point_states():
    lt = LinearTurbine.from_plants({19.0: iea15mw().linearize(19.0)}, rotor_radius=120.0)
    with pytest.raises(ValueError, match="no states and outputs"):
        lt.evaluate_outputs(np.zeros(5), 19.0, 0.3, 1e7)
    with pytest.raises(ValueError, match="has 2 states"):
        LinearTurbine.from_plants({19.0: iea15mw().linearize(19.0)}, rotor_radius=120.0,
                                  operating_points={19.0: LinearOperatingPoint(19.0, 0.79, 0.3, 1e7, (0.0, 0.0))})


def test_pickle_round_trip(floating):
    """python-control systems do not pickle; a LinearTurbine does (a forwarded MPC built on one is
    pickled to its server), and its default schedule is rebound to the copy."""
    import pickle

    copy = pickle.loads(pickle.dumps(floating))
    a, b = copy.linearize(19.0), floating.linearize(19.0)
    for k in "ABCD":
        assert_allclose(getattr(a, k), getattr(b, k), rtol=0, atol=0)
    assert (a.input_labels, a.output_labels, a.state_labels) == (b.input_labels, b.output_labels, b.state_labels)
    assert copy.trim(19.0) == floating.trim(19.0) and copy.sources == floating.sources
    assert copy.schedule.turbine is copy
    assert_allclose(copy.schedule.gains(19.0), floating.schedule.gains(19.0), rtol=0, atol=0)
    limited = dataclasses.replace(floating, pitch_rate_limit=0.0349)  # the actuator limits a linearisation lacks
    assert limited.schedule.turbine is limited and limited.pitch_rate_limit == 0.0349
    assert np.isnan(floating.pitch_rate_limit)
