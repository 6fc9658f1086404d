"""Closed-loop formulas against python-control's interconnect, spectra and DEL."""
import warnings

import control
import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.signal import cont2discrete
from scipy.special import gamma

from specdesign import closedloop as cl
from specdesign.closedloop.maps import state_space_response
from specdesign.turbine import OUTPUT_NAMES, iea15mw, rosco_baseline
from specdesign.wind import rotor_effective_spectrum

OMEGA = np.logspace(-3, 1.3, 300)


@pytest.fixture(scope="module")
def setup():
    model = iea15mw()
    P = model.linearize(19.0)
    C = rosco_baseline(model, 19.0)
    # an ATD controller with dynamics: band-passed tower-top velocity, negative gain (β = −K·z)
    K = control.tf([-0.04, 0], [1, 0.2]) * control.tf([1], [0.1, 1])
    return model, P, C, K


def _rel(a, b):
    """Largest relative error; responses below 1e-6 of their peak count relative to that floor
    (tower_top_acc falls as ω² towards 0, where both routes lose digits to cancellation)."""
    return np.max(np.abs(a - b) / np.maximum(np.abs(b), 1e-6 * np.abs(b).max()))


def test_eq4_eq5_match_interconnect(setup):
    _, P, C, _ = setup
    with warnings.catch_warnings():
        warnings.simplefilter("error", cl.ClosedLoopUnstableWarning)
        T = cl.closed_loop(P, C)
    assert T.input_labels == ["wind"]
    assert T.output_labels == list(OUTPUT_NAMES) + ["pitch_cmd"]
    assert _rel(cl.t_gen_speed_wind(P, C, OMEGA), cl.frequency_response(T, OMEGA, "gen_speed")) < 1e-9
    assert _rel(cl.t_tower_wind(P, C, OMEGA), cl.frequency_response(T, OMEGA, "tower_base_my")) < 1e-9
    for y in OUTPUT_NAMES:
        if y == "power":
            continue  # identically ∝ gen_speed above rated
        assert _rel(cl.t_output_wind(P, C, OMEGA, y), cl.frequency_response(T, OMEGA, y)) < 1e-9, y


def test_eq4_written_out(setup):
    # T_Ω,w = P_Ω,w/(1 + C·P_Ω,β) with every factor evaluated independently by control
    _, P, C, _ = setup
    s = 1j * OMEGA
    pw = P["gen_speed", "wind"](s)
    pb = P["gen_speed", "pitch_cmd"](s)
    assert _rel(cl.t_gen_speed_wind(P, C, OMEGA), pw / (1 + C(s) * pb)) < 1e-12


def test_atd_formula_matches_interconnect(setup):
    _, P, C, K = setup
    with warnings.catch_warnings():
        warnings.simplefilter("error", cl.ClosedLoopUnstableWarning)
        T = cl.closed_loop(P, C, atd_controller=K)
    for y in ("gen_speed", "tower_base_my", "tower_top_vel", "pitch"):
        got = cl.t_output_wind(P, C, OMEGA, y, atd_controller=K)
        assert _rel(got, cl.frequency_response(T, OMEGA, y)) < 1e-9, y
    # pitch command: T_β,w = −(C P_Ω,w + K P_z,w)/(1 + C P_Ω,β + K P_z,β)
    s = 1j * OMEGA
    num = C(s) * P["gen_speed", "wind"](s) + K(s) * P["tower_top_vel", "wind"](s)
    den = 1 + C(s) * P["gen_speed", "pitch_cmd"](s) + K(s) * P["tower_top_vel", "pitch_cmd"](s)
    assert _rel(cl.frequency_response(T, OMEGA, "pitch_cmd"), -num / den) < 1e-9
    # acceleration feedback is another measurement, same algebra
    Ka = control.tf([-0.02], [1, 0.2])
    Ta = cl.closed_loop(P, C, atd_controller=Ka, atd_measurement="tower_top_acc")
    got = cl.t_tower_wind(P, C, OMEGA, atd_controller=Ka, atd_measurement="tower_top_acc")
    assert _rel(got, cl.frequency_response(Ta, OMEGA, "tower_base_my")) < 1e-9


def test_atd_damps_the_tower_peak(setup):
    _, P, C, K = setup
    base = np.abs(cl.t_tower_wind(P, C, OMEGA))
    atd = np.abs(cl.t_tower_wind(P, C, OMEGA, atd_controller=K))
    band = (OMEGA > 0.9) & (OMEGA < 1.2)
    assert atd[band].max() < 0.9 * base[band].max()


def test_mapping_plant_and_array_controller(setup):
    _, P, C, _ = setup
    keys = [(y, u) for y in ("gen_speed", "tower_base_my") for u in ("wind", "pitch_cmd")]
    resp = {k: P[k[0], k[1]](1j * OMEGA) for k in keys}
    got = cl.t_tower_wind(resp, C(1j * OMEGA), OMEGA)
    assert _rel(got, cl.t_tower_wind(P, C, OMEGA)) < 1e-12
    with pytest.raises(ValueError, match="C as a frequency response"):
        cl.t_tower_wind(resp, np.ones(3), OMEGA)


def test_integral_action_and_open_loop_limit(setup):
    _, P, C, _ = setup
    T = cl.closed_loop(P, C)
    assert abs(cl.frequency_response(T, [1e-6, 1e-5], "gen_speed")[0]) < 1e-4 * abs(control.dcgain(P["gen_speed", "wind"]))
    # C → 0: the closed loop is the open loop
    zero = control.tf([1e-300], [1])
    assert _rel(cl.t_tower_wind(P, zero, OMEGA), P["tower_base_my", "wind"](1j * OMEGA)) < 1e-9


def test_instability_is_reported(setup):
    _, P, C, K = setup
    with pytest.warns(cl.ClosedLoopUnstableWarning, match="poles") as rec:
        cl.closed_loop(P, C, atd_controller=-25 * K)  # wrong sign, large gain: tower mode unstable
    assert "closed loop" in str(rec[0].message)
    unstable = control.ss([[0.5]], [[1]], [[1]], [[0]])
    with pytest.warns(cl.ClosedLoopUnstableWarning, match="0.5"):
        assert cl.check_stability(unstable, "toy") is False
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert cl.check_stability(cl.closed_loop(P, C, warn=False)) is True


def test_output_psd_and_del(setup):
    model, P, C, _ = setup
    T = cl.closed_loop(P, C)
    w = np.linspace(0.0, 10.0, 4001)
    s_w = rotor_effective_spectrum(w, 19.0, model.rotor_radius)
    s_y = cl.output_psd(T, w, s_w, "tower_base_my")
    assert_allclose(s_y, np.abs(cl.t_tower_wind(P, C, w)) ** 2 * s_w, rtol=1e-9)
    # narrow-band DEL written out: D/s = ν0 (2√(2 m0))^m Γ(1 + m/2), DEL = (D/s / 1 Hz)^(1/m)
    m = 4.0
    m0 = np.trapezoid(s_y, w)
    m2 = np.trapezoid(w**2 * s_y, w)
    nu0 = np.sqrt(m2 / m0) / (2 * np.pi)
    del_nb = (nu0 * (2 * np.sqrt(2 * m0)) ** m * gamma(1 + m / 2)) ** (1 / m)
    assert_allclose(cl.closed_loop_del(T, w, s_w, m, method="narrowband"), del_nb, rtol=1e-6)
    # Dirlik is below the conservative narrow-band figure for a broad-band load
    assert cl.closed_loop_del(T, w, s_w, m) < del_nb


def test_bad_inputs(setup):
    _, P, C, _ = setup
    anonymous = control.ss(P.A, P.B, P.C, P.D)
    with pytest.raises(ValueError, match="plant lacks"):
        cl.closed_loop(anonymous, C)
    with pytest.raises(TypeError, match="pitch_controller"):
        cl.closed_loop(P, "PI")
    with pytest.raises(ValueError, match="SISO"):
        cl.closed_loop(P, control.ss(P.A, P.B, P.C, P.D))
    with pytest.raises(ValueError, match="sys lacks"):
        cl.frequency_response(P, OMEGA, "rotor_thrust")
    with pytest.raises(ValueError, match="wind_psd"):
        cl.output_psd(P, OMEGA, np.ones(3), "gen_speed")
    with pytest.raises(ValueError, match="m="):
        cl.closed_loop_del(P, OMEGA, np.ones(OMEGA.size), -1)


def test_loop_maps_and_figures(setup):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from specdesign.plots.turbine import plot_fatigue_origin, plot_open_vs_baseline

    _, P, C, _ = setup
    maps = cl.loop_maps(P, C, OMEGA)
    s = 1j * OMEGA
    assert_allclose(maps.gen_open, P["gen_speed", "wind"](s), rtol=1e-9)
    assert_allclose(maps.loop, C(s) * P["gen_speed", "pitch_cmd"](s), rtol=1e-9)
    assert _rel(maps.tower_closed, cl.t_tower_wind(P, C, OMEGA)) < 1e-12
    ax = plot_open_vs_baseline(maps)
    assert len(ax) == 3 and all(a.get_ylabel() for a in ax) and "rad/s" in ax[2].get_xlabel()
    assert len(ax[0].get_lines()) == 2
    psd = np.abs(maps.tower_closed) ** 2
    ax = plot_fatigue_origin(OMEGA, maps.tower_closed, psd, np.ones_like(OMEGA), m=4)
    assert ax[2].get_legend() is not None
    with pytest.raises(ValueError, match="psd"):
        plot_fatigue_origin(OMEGA, maps.tower_closed, psd[:-1], np.ones_like(OMEGA))
    plt.close("all")


def test_case_speeds_clip_and_list_each_operating_point_once():
    # offsets clipped to the range; a case within CASE_TOLERANCE of another is the same point
    speeds, nom = cl.case_speeds(19.0, (-1.0, -0.5, 0.5, 1.0), (10.6, 25.0))
    assert speeds == (18.0, 18.5, 19.0, 19.5, 20.0) and nom == 2
    speeds, nom = cl.case_speeds(25.0, (-1.0, -0.5, 0.5, 1.0), (10.6, 25.0))
    assert speeds == (24.0, 24.5, 25.0) and nom == 2
    edge = 25.0 - 1e-9
    speeds, nom = cl.case_speeds(edge, (-1.0, -0.5, 0.5, 1.0), (10.6, 25.0))
    assert speeds == (edge - 1.0, edge - 0.5, edge) and speeds[nom] == edge
    assert cl.case_speeds(19.0, (), (10.6, 25.0)) == ((19.0,), 0)
    with pytest.raises(ValueError, match="offsets"):
        cl.case_speeds(19.0, (np.nan,), (10.6, 25.0))
    with pytest.raises(ValueError, match=r"^template_offsets=\[\[0.5\]\] must be a 1-D array"):
        cl.case_speeds(19.0, [[0.5]], (10.6, 25.0), name="template_offsets")


def test_batched_siso_response_equals_python_controls():
    # siso_response(method="batched") evaluates a state space at every frequency at once
    # (state_space_response); python-control's per-frequency evaluation is the oracle.
    # The system is drawn from a seeded generator (control.rss draws from numpy's global state,
    # so it changed with every run and with the test order): 12 lightly to well damped modes
    # and a real pole, rotated by an orthogonal matrix so the eigenvalues are well conditioned
    rng = np.random.default_rng(3)
    wn = np.geomspace(0.01, 15.0, 12)
    zeta = rng.uniform(0.02, 0.5, wn.size)
    blocks = [np.array([[-z * w, w * np.sqrt(1 - z * z)], [-w * np.sqrt(1 - z * z), -z * w]])
              for w, z in zip(wn, zeta)]
    a0 = np.zeros((25, 25))
    for k, blk in enumerate(blocks):
        a0[2 * k:2 * k + 2, 2 * k:2 * k + 2] = blk
    a0[-1, -1] = -0.3
    q, _ = np.linalg.qr(rng.normal(size=(25, 25)))
    a, b, c = q @ a0 @ q.T, rng.normal(size=(25, 1)), rng.normal(size=(1, 25))
    sys = control.ss(a, b, c, rng.normal(size=(1, 1)))
    w = np.geomspace(0.005, 20.0, 700)
    got, ref = cl.siso_response(sys, w, method="batched"), cl.siso_response(sys, w)
    # Tolerance from the conditioning, not a fixed rtol: each method solves (jωI − A) x = B in
    # floating point, with a backward-stable error ‖δx‖ ≲ n·ε·κ(jωI − A)·‖x‖ (Higham, ch. 7);
    # C·δx is then at most ‖C‖·‖δx‖, and the two methods may err in opposite directions (×2).
    # The factor 10 covers the constants the bound leaves out.
    eye = np.eye(25)
    kappa = np.array([np.linalg.cond(1j * wk * eye - a) for wk in w])
    xnorm = np.array([np.linalg.norm(np.linalg.solve(1j * wk * eye - a, b)) for wk in w])
    bound = 2 * 10 * 25 * np.finfo(float).eps * kappa * np.linalg.norm(c) * xnorm
    assert np.all(np.abs(got - ref) <= bound)
    # and the bound is not vacuous: far below the response itself at every frequency
    assert np.all(bound < 1e-6 * np.abs(ref))
    tf = control.tf([1.0, 2.0], [1.0, 0.3, 1.0])  # a transfer function: its polynomials either way
    assert np.array_equal(cl.siso_response(tf, w, method="batched"), cl.siso_response(tf, w))
    with pytest.raises(ValueError, match="method"):
        cl.siso_response(sys, w, method="modal")


def test_state_space_response_of_a_discrete_system_equals_python_controls():
    # sample_time=T evaluates C(zI − A)⁻¹B + D at z = e^{jωT}; python-control's evaluation of the
    # same discrete system at those points is the oracle. A zero-order-hold discretisation of a
    # damped system, T = 0.1 s, up to the Nyquist frequency π/T.
    a = np.array([[0.0, 1.0, 0.0], [-4.0, -0.4, 1.0], [0.0, 0.0, -2.0]])
    b, c, d = np.array([[0.0], [0.0], [1.0]]), np.array([[1.0, 0.5, 0.0]]), np.array([[0.2]])
    T = 0.1
    ad, bd, cd, dd, _ = cont2discrete((a, b, c, d), T, method="zoh")
    w = np.linspace(0.01, np.pi / T, 200)
    got = state_space_response(ad, bd, cd, dd, w, sample_time=T)[:, 0, 0]
    ref = np.array([complex(np.squeeze(control.ss(ad, bd, cd, dd, dt=T)(np.exp(1j * wk * T)))) for wk in w])
    # tolerance from the conditioning, as the continuous case above (n = 3, the factor 10)
    eye = np.eye(3)
    kappa = np.array([np.linalg.cond(np.exp(1j * wk * T) * eye - ad) for wk in w])
    xnorm = np.array([np.linalg.norm(np.linalg.solve(np.exp(1j * wk * T) * eye - ad, bd)) for wk in w])
    bound = 2 * 10 * 3 * np.finfo(float).eps * kappa * np.linalg.norm(cd) * xnorm
    assert np.all(np.abs(got - ref) <= bound)
    assert np.all(bound < 1e-9 * np.abs(ref))
    with pytest.raises(ValueError, match="sample_time"):
        state_space_response(ad, bd, cd, dd, w, sample_time=0.0)


def test_refine_grid_points_per_width_samples_every_peak_finely_and_no_more():
    # points_per_width: the spacing at a root of damping ζ is max(rel_step, 2ζ/points_per_width)
    # over ±rel_width of |Im p|, so a well-damped root gets a dozen points, a lightly damped one
    # keeps rel_step's, and every peak is still found to 0.01 dB
    w = np.geomspace(0.1, 10.0, 50)
    cases = ((1.0, 0.2), (3.0, 1e-3))  # (ω_n rad/s, ζ)
    systems = [control.tf([wn * wn], [1.0, 2 * z * wn, wn * wn]) for wn, z in cases]
    g = cl.refine_grid(w, systems, points_per_width=50)
    g0 = cl.refine_grid(w, systems)
    for sys, (wn, z) in zip(systems, cases):
        im = wn * np.sqrt(1 - z * z)
        band, band0 = g[np.abs(g / im - 1) <= 0.05], g0[np.abs(g0 / im - 1) <= 0.05]
        assert np.max(np.diff(np.log(band))) <= max(1e-4, 2 * z / 50) * (1 + 1e-9)
        peak = np.max(np.abs(cl.siso_response(sys, g)))
        true = np.max(np.abs(cl.siso_response(sys, np.geomspace(0.9 * wn, 1.1 * wn, 200001))))
        assert 20 * np.log10(true / peak) < 0.01
        if z > 0.01:
            assert band0.size > 900 and band.size < 30   # 1000 points at rel_step, a dozen here
        else:
            assert band.size == band0.size               # 2ζ/50 = 4e-5 < rel_step: rel_step's spacing
    with pytest.raises(ValueError, match="points_per_width"):
        cl.refine_grid(w, systems[0], points_per_width=0.0)


def test_merge_frequencies_keeps_one_point_per_root_computed_twice():
    # the tower mode as a pole of two maps differs by round-off: one design frequency, whichever
    # copy comes first, while points 1e-4 apart (refine_grid's spacing) stay distinct
    from specdesign.closedloop import FREQUENCY_RTOL, merge_frequencies

    w = 1.0699516312
    got = merge_frequencies([w, 2.0], [w * (1 + 1e-12), w * (1 - 1e-13), w * (1 + 1e-4)])
    assert got.tolist() == [w * (1 - 1e-13), w * (1 + 1e-4), 2.0]
    assert merge_frequencies([1.0, 1.0 + 10 * FREQUENCY_RTOL]).size == 2
    assert merge_frequencies().size == 0
    with pytest.raises(ValueError, match="finite positive"):
        merge_frequencies([1.0, np.nan])
    with pytest.raises(ValueError, match="rtol"):
        merge_frequencies([1.0], rtol=0.1)
