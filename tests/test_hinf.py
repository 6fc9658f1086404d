"""loopshaping.hinf: synthesis against python-control's mixsyn and against frequency-domain
oracles, ill-posed problems refused fast, reduction bounds, discretisation."""
import subprocess
import sys
import textwrap
import warnings
from pathlib import Path

import control as ct
import numpy as np
import pytest

from loopshaping import hinf

s = ct.tf("s")
# Skogestad & Postlethwaite, Multivariable Feedback Control, Example 2.11 (the plant and
# performance weight python-control's robust examples use).
G = 200 / ((10 * s + 1) * (0.05 * s + 1) ** 2)
W_S = (s / 1.5 + 10) / (s + 10 * 1e-4)
W_KS = ct.tf(1, 1)
W_T = ct.tf([1 / 20, 1], [1 / 2000, 1])  # biproper: a large high-frequency penalty on T

OMEGA = np.logspace(-5, 6, 40001)


def _quiet_mixsyn(*args):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FutureWarning)  # mixsyn uses deprecated connect()
        return ct.mixsyn(*args)


def _freq(sys, w):
    """Frequency response as an (n_out, n_in, len(w)) complex array."""
    r = np.asarray(ct.frequency_response(sys, w).complex)
    return r.reshape(sys.noutputs, sys.ninputs, len(w))


def _weighted_siso_stack(g, k, weights, w):
    """|[W_S S; W_KS K S; W_T T]| on a grid from G(jω), K(jω) only (SISO: a column)."""
    gj, kj = _freq(g, w)[0, 0], _freq(k, w)[0, 0]
    S = 1 / (1 + gj * kj)
    cols = []
    for W, F in zip(weights, (S, kj * S, gj * kj * S)):
        if W is not None:
            cols.append(_freq(ct.ss(W), w)[0, 0] * F)
    return np.sqrt(np.sum(np.abs(np.array(cols)) ** 2, axis=0))


@pytest.mark.parametrize(
    "weights",
    [(W_S, W_KS, None), (W_S, ct.tf(0.1, 1), W_T), (W_S, ct.tf([0.1, 1], [0.001, 1]), None)],
    ids=["S/KS", "S/KS/T", "S/KS-dynamic"],
)
def test_mixed_sensitivity_matches_mixsyn_gamma(weights):
    ws, wks, wt = weights
    _, _, (gamma_pc, _) = _quiet_mixsyn(G, ws, wks, wt)
    K, gamma = hinf.mixed_sensitivity(G, w_s=ws, w_ks=wks, w_t=wt)
    assert gamma == pytest.approx(gamma_pc, rel=0.01)
    assert isinstance(K, ct.StateSpace)


def test_mimo_mixed_sensitivity_matches_mixsyn_and_grid():
    G2 = ct.tf([[[1.0], [0.5]], [[0.2], [2.0]]], [[[1.0, 1.0], [1.0, 2.0]], [[1.0, 1.0], [1.0, 3.0]]])
    ws = (s / 2 + 1) / (s + 1e-2)
    wks = ct.tf([0.1, 0.05], [0.01, 1])
    _, _, (gamma_pc, _) = _quiet_mixsyn(G2, ws, wks)
    res = hinf.mixed_sensitivity(G2, w_s=ws, w_ks=wks, suboptimality=0.02)
    assert res.controller.ninputs == 2 and res.controller.noutputs == 2
    assert res.gamma_bound / 1.02 == pytest.approx(gamma_pc, rel=0.01)
    # σ_max of [W_S S; W_KS K S] from G(jω), K(jω) only.
    w = np.logspace(-4, 4, 4000)
    Gj, Kj = _freq(ct.ss(G2), w), _freq(res.controller, w)
    wsj, wksj = _freq(ct.ss(ws), w)[0, 0], _freq(ct.ss(wks), w)[0, 0]
    peak = 0.0
    for i in range(len(w)):
        S = np.linalg.inv(np.eye(2) + Gj[:, :, i] @ Kj[:, :, i])
        M = np.vstack([wsj[i] * S, wksj[i] * Kj[:, :, i] @ S])
        peak = max(peak, np.linalg.svd(M, compute_uv=False)[0])
    assert peak <= res.gamma * (1 + 1e-6)
    assert peak >= res.gamma * (1 - 1e-2)


def test_gamma_is_the_closed_loop_norm_on_a_dense_grid():
    res = hinf.mixed_sensitivity(G, w_s=W_S, w_ks=ct.tf(0.1, 1), w_t=W_T, suboptimality=0.05)
    mag = _weighted_siso_stack(G, res.controller, (W_S, ct.tf(0.1, 1), W_T), OMEGA)
    # The grid maximum is a lower bound of the norm and, with 40 000 points, a tight one.
    assert mag.max() <= res.gamma * (1 + 1e-6)
    assert mag.max() >= res.gamma * (1 - 1e-3)
    assert res.gamma <= res.gamma_bound * (1 + 1e-9)
    # Closed loop G·K with negative feedback is stable (the contract's sign convention).
    L = ct.series(res.controller, ct.ss(G))
    assert np.all(ct.feedback(L, 1, sign=-1).poles().real < 0)


def test_result_unpacks_and_is_frozen():
    res = hinf.mixed_sensitivity(G, w_s=W_S, w_ks=W_KS)
    K, gamma = res
    assert K is res.controller and gamma == res.gamma
    with pytest.raises(AttributeError):
        res.gamma = 0.0


def _general_plant(d22):
    """A 2-state unstable plant with output disturbance, noise and control penalty."""
    A = np.array([[0.5, 1.0], [0.0, -2.0]])
    B1 = np.array([[1.0, 0.0], [0.5, 0.0]])
    B2 = np.array([[0.0], [1.0]])
    C1 = np.array([[1.0, 0.0], [0.0, 0.0]])
    D11 = np.zeros((2, 2))
    D12 = np.array([[0.0], [0.3]])
    C2 = np.array([[1.0, 1.0]])
    D21 = np.array([[0.0, 0.2]])
    D22 = np.array([[d22]])
    B = np.hstack([B1, B2])
    C = np.vstack([C1, C2])
    D = np.block([[D11, D12], [D21, D22]])
    return ct.ss(A, B, C, D)


def _lft_freq(P, K, w, n_meas=1, n_ctrl=1):
    """F_l(P, K)(jω) = P11 + P12 K (I − P22 K)⁻¹ P21 pointwise (u = K y)."""
    Pj, Kj = _freq(P, w), _freq(K, w)
    nz, nw = P.noutputs - n_meas, P.ninputs - n_ctrl
    out = np.empty(len(w))
    for i in range(len(w)):
        p, k = Pj[:, :, i], Kj[:, :, i]
        P11, P12, P21, P22 = p[:nz, :nw], p[:nz, nw:], p[nz:, :nw], p[nz:, nw:]
        F = P11 + P12 @ k @ np.linalg.solve(np.eye(n_ctrl) - P22 @ k, P21)
        out[i] = np.linalg.svd(F, compute_uv=False)[0]
    return out


@pytest.mark.parametrize("d22", [0.0, 0.4])
def test_synthesize_general_plant_against_lft_oracle(d22):
    P = _general_plant(d22)
    res = hinf.synthesize(P, 1, 1, suboptimality=0.02)
    w = np.logspace(-4, 5, 6000)
    mag = _lft_freq(P, res.controller, w)
    assert mag.max() <= res.gamma * (1 + 1e-6)
    assert mag.max() >= res.gamma * (1 - 2e-3)
    # Internal stability checked independently by interconnection of P and K.
    Pn = ct.ss(P.A, P.B, P.C, P.D, inputs=["w1", "w2", "u"], outputs=["z1", "z2", "y"])
    Kn = ct.ss(res.controller.A, res.controller.B, res.controller.C, res.controller.D,
               inputs=["y"], outputs=["u"])
    cl = ct.interconnect([Pn, Kn], inplist=["w1", "w2"], outlist=["z1", "z2"])
    assert np.all(cl.poles().real < 0)
    # D22 only changes the controller, not the achievable performance.
    assert res.gamma == pytest.approx(hinf.synthesize(_general_plant(0.0), 1, 1,
                                                      suboptimality=0.02).gamma, rel=1e-6)


def test_suboptimal_gamma_is_rounded_up_to_its_grid_so_round_off_does_not_move_it():
    # issue 28 item 4: the bisection's upper end γ_hi is a step function of the data; the
    # controller is formed at (1 + s)·γ_hi rounded up to the grid (1 + GAMMA_GRID)^k
    P = _general_plant(0.0)
    res = hinf.synthesize(P, 1, 1, suboptimality=0.02)
    gamma_hi = hinf.synthesize(P, 1, 1, suboptimality=0.0).gamma_bound  # the same bisection, no rounding
    k = np.log(res.gamma_bound) / np.log1p(hinf.GAMMA_GRID)
    assert k == pytest.approx(round(k), abs=1e-9)
    assert 1.02 * gamma_hi <= res.gamma_bound <= 1.02 * gamma_hi * (1 + hinf.GAMMA_GRID)
    # the plant moved by 1e-9 relative (a rounding error of the operating point): the same γ, and a
    # controller that moves by about as much (the central controller is smooth in the data at a
    # fixed γ; 1e-6 leaves room for the Riccati solutions' conditioning)
    nudged = ct.ss(np.asarray(P.A) * (1 + 1e-9), P.B, P.C, P.D)
    res_n = hinf.synthesize(nudged, 1, 1, suboptimality=0.02)
    assert res_n.gamma_bound == res.gamma_bound
    w = np.logspace(-2, 1, 200)
    ka, kb = _freq(res.controller, w)[0, 0], _freq(res_n.controller, w)[0, 0]
    assert np.max(np.abs(kb - ka) / np.abs(ka)) <= 1e-6


@pytest.mark.parametrize("alpha", [0.3, 1.0])
@pytest.mark.parametrize("d22", [0.0, 0.4])
def test_decay_rate_bounds_every_closed_loop_pole(alpha, d22):
    # The unstable 2-state plant: without a shift its closed loop has a pole at ≈ −0.1.
    P = _general_plant(d22)
    res = hinf.synthesize(P, 1, 1, decay_rate=alpha, suboptimality=0.02)
    assert res.decay_rate == alpha and any("α-shifted" in n for n in res.notes)
    # Closed loop rebuilt independently by interconnection of P and the returned K.
    Pn = ct.ss(P.A, P.B, P.C, P.D, inputs=["w1", "w2", "u"], outputs=["z1", "z2", "y"])
    K = res.controller
    Kn = ct.ss(K.A, K.B, K.C, K.D, inputs=["y"], outputs=["u"])
    cl = ct.interconnect([Pn, Kn], inplist=["w1", "w2"], outlist=["z1", "z2"])
    assert np.max(cl.poles().real) < -alpha
    assert np.max(res.closed_loop.poles().real) < -alpha
    # γ is the jω-axis norm of the returned closed loop, and no better than unshifted.
    mag = _lft_freq(P, K, np.logspace(-4, 5, 6000))
    assert mag.max() == pytest.approx(res.gamma, rel=2e-3)
    assert res.gamma >= hinf.synthesize(P, 1, 1, suboptimality=0.02).gamma * (1 - 1e-6)


def test_decay_rate_in_mixed_sensitivity_keeps_integral_weights():
    # Only the plant's states are shifted: W_S with a (shifted) integrator stays allowed, and
    # the loop G–K has every pole left of −α; the weights keep their own poles.
    alpha = 0.5
    res = hinf.mixed_sensitivity(G, w_s=W_S, w_ks=W_KS, decay_rate=alpha)
    L = ct.feedback(ct.ss(G) * res.controller)
    assert np.max(L.poles().real) < -alpha
    assert res.gamma == pytest.approx(_weighted_siso_stack(G, res.controller, (W_S, W_KS, None),
                                                           OMEGA).max(), rel=1e-3)


def test_decay_rate_slower_weight_mode_is_refused():
    # Shifting the whole plant (weights included) past a weight's pole at −1e-3 leaves a mode
    # the controller cannot move: refused at once, naming the remedy.
    P = hinf.mixed_sensitivity(G, w_s=W_S, w_ks=W_KS).generalized_plant
    with pytest.raises(ValueError, match="decay_rate=0.1.*decay_states"):
        hinf.synthesize(P, 1, 1, decay_rate=0.1)
    with pytest.raises(ValueError, match="decay_rate"):
        hinf.synthesize(P, 1, 1, decay_rate=-1.0)
    with pytest.raises(ValueError, match="decay_states"):
        hinf.synthesize(P, 1, 1, decay_rate=0.1, decay_states=[True])


def test_integrator_in_weight_is_shifted_with_a_note():
    w_s_int = (s / 1.5 + 10) / s
    with pytest.warns(hinf.WellPosednessWarning, match="w_s"):
        res = hinf.mixed_sensitivity(G, w_s=w_s_int, w_ks=ct.tf(0.1, 1), shift=1e-4)
    assert any("w_s" in n and "imaginary axis" in n for n in res.notes)
    # Same as shifting the integrator by hand and asking python-control.
    _, _, (gamma_pc, _) = _quiet_mixsyn(G, (s / 1.5 + 10) / (s + 1e-4), ct.tf(0.1, 1))
    assert res.gamma == pytest.approx(gamma_pc, rel=0.01)


ILL_POSED = textwrap.dedent(
    """
    import control as ct
    from loopshaping import hinf
    s = ct.tf("s")
    G = 200 / ((10 * s + 1) * (0.05 * s + 1) ** 2)
    try:
        hinf.mixed_sensitivity(G, w_s=(s / 1.5 + 10) / (s + 1e-3),
                               w_t=ct.tf([1 / 20, 1], [1 / 2000, 1]))
    except ValueError as e:
        print("VALUEERROR")
        print(e)
    else:
        print("NO ERROR")
    """
)


def test_ill_posed_rank_deficient_d12_raises_instead_of_hanging():
    # A strictly proper plant with only w_s and w_t: D12 = 0. SLICOT's sb10ad iterates on
    # it without end (python-control's mixsyn hangs), so run it in a subprocess: a hang is
    # a failure (the timeout), not a stuck test run. How fast it refuses is not asserted.
    root = Path(__file__).resolve().parents[1]  # import this checkout's loopshaping
    out = subprocess.run([sys.executable, "-c", ILL_POSED], capture_output=True, text=True,
                         timeout=60, cwd=root)
    assert out.returncode == 0, out.stderr
    first, message = out.stdout.split("\n", 1)
    assert first == "VALUEERROR", out.stdout
    assert "D12" in message and "w_ks" in message and "regularize" in message


def test_ill_posed_regularized_on_request():
    ws, wt = (s / 1.5 + 10) / (s + 1e-3), ct.tf([1 / 20, 1], [1 / 2000, 1])
    with pytest.warns(hinf.WellPosednessWarning, match="D12") as rec:
        res = hinf.mixed_sensitivity(G, w_s=ws, w_t=wt, regularize=True, epsilon=1e-2,
                                     suboptimality=0.05)
    assert any("D12" in n for n in res.notes)
    assert all(r.filename == __file__ for r in rec)  # warned at the caller's line
    # Regularisation only adds a (small) output, so the [W_S S; W_T T] stack is ≤ γ.
    mag = _weighted_siso_stack(G, res.controller, (ws, None, wt), OMEGA)
    assert mag.max() <= res.gamma * (1 + 1e-6)
    L = ct.series(res.controller, ct.ss(G))
    assert np.all(ct.feedback(L, 1).poles().real < 0)


def test_plant_integrator_raises_imaginary_axis_zero():
    with pytest.raises(ValueError, match="imaginary axis.*shift the pole"):
        hinf.mixed_sensitivity(1 / s, w_s=W_S, w_ks=0.1)


def test_not_stabilisable_and_not_detectable_raise():
    A = np.diag([1.0, -1.0])
    B = np.array([[0.0, 0.0], [1.0, 1.0]])  # the unstable mode gets neither w nor u
    C = np.array([[1.0, 1.0], [1.0, 1.0]])
    D = np.array([[0.0, 1.0], [1.0, 0.0]])
    with pytest.raises(ValueError, match="not stabilisable"):
        hinf.synthesize(ct.ss(A, B, C, D), 1, 1)
    # Dual: the unstable mode is invisible to the measurement.
    with pytest.raises(ValueError, match="not detectable"):
        hinf.synthesize(ct.ss(A.T, C.T, B.T, D.T), 1, 1)


def _rescaled(P, scales):
    """P in the state coordinates x = diag(scales)·x': the same transfer functions and modes."""
    T = np.diag(scales)
    return ct.ss(np.linalg.solve(T, P.A @ T), np.linalg.solve(T, P.B), P.C @ T, P.D)


def test_well_posedness_does_not_depend_on_the_state_units():
    # The unstable mode (s = 0.5) of _general_plant is reached by the control through the
    # coupling A[0, 1]. In units that make that coupling 1e-7 and B2 1e7 (a stiff state beside
    # a slow one, as a structural model's N·m beside rad), the PBH test's smallest singular value
    # (~1e-7) falls below 1e-9·‖[A B2]‖ (~1e-2) unless the check balances the states first; the
    # mode is as controllable as before, and the synthesis (which balances) finds the same γ.
    P = _general_plant(0.0)
    scaled = _rescaled(P, [1.0, 1e-7])
    assert np.abs(np.asarray(scaled.B)[1, 2]) == pytest.approx(1e7)
    hinf.check_well_posed(scaled, 1, 1)
    assert hinf.synthesize(scaled, 1, 1).gamma == pytest.approx(hinf.synthesize(P, 1, 1).gamma, rel=1e-3)
    # an unstabilisable mode stays unstabilisable in any units
    A = np.diag([1.0, -1.0])
    B = np.array([[0.0, 0.0], [1.0, 1.0]])
    C = np.array([[1.0, 1.0], [1.0, 1.0]])
    D = np.array([[0.0, 1.0], [1.0, 0.0]])
    for scales in ([1.0, 1.0], [1e-7, 1.0], [1.0, 1e-7], [1e6, 1e-6]):
        with pytest.raises(ValueError, match="not stabilisable"):
            hinf.check_well_posed(_rescaled(ct.ss(A, B, C, D), scales), 1, 1)


def test_d21_rank_deficient_raises():
    P = _general_plant(0.0)
    D = np.asarray(P.D).copy()
    D[2, :2] = 0.0  # noise-free measurement
    with pytest.raises(ValueError, match="D21"):
        hinf.synthesize(ct.ss(P.A, P.B, P.C, D), 1, 1)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(n_meas=0, n_ctrl=1), "n_meas"),
        (dict(n_meas=1, n_ctrl=3), "n_ctrl"),
        (dict(n_meas=1, n_ctrl=1, suboptimality=-1), "suboptimality"),
        (dict(n_meas=1, n_ctrl=1, epsilon=0.0), "epsilon"),
    ],
)
def test_bad_arguments_name_themselves(kwargs, match):
    with pytest.raises(ValueError, match=match):
        hinf.synthesize(_general_plant(0.0), **kwargs)


def test_bad_types_and_discrete_plants():
    with pytest.raises(TypeError, match="generalized_plant"):
        hinf.synthesize("P", 1, 1)
    with pytest.raises(ValueError, match="continuous"):
        hinf.mixed_sensitivity(ct.c2d(ct.ss(G), 0.1), w_s=W_S, w_ks=1)
    with pytest.raises(ValueError, match="at least one"):
        hinf.mixed_sensitivity(G)


def _hsv(sys):
    """Hankel singular values from the Gramians by scipy (independent of SLICOT).

    Square-root form, σ(L_o^T L_c) with W = L L^T: the eigenvalues of W_c·W_o square the
    condition number and lose the small values (1.8e-3 next to 37 came out 6e-5 off).
    """
    from scipy.linalg import cholesky, solve_continuous_lyapunov as lyap
    A, B, C = (np.asarray(M) for M in (sys.A, sys.B, sys.C))
    Lc = cholesky(lyap(A, -B @ B.T), lower=True)
    Lo = cholesky(lyap(A.T, -C.T @ C), lower=True)
    return np.linalg.svd(Lo.T @ Lc, compute_uv=False)


@pytest.mark.parametrize("method", ["balanced", "singular_perturbation"])
@pytest.mark.parametrize("order", [1, 2, 3])
def test_reduction_error_between_hankel_bounds(method, order):
    K = hinf.mixed_sensitivity(G, w_s=W_S, w_ks=ct.tf([0.1, 1], [0.001, 1])).controller
    red = hinf.reduce(K, order, method=method)
    hsv = _hsv(K)
    np.testing.assert_allclose(red.hankel_singular_values, hsv, rtol=1e-6, atol=1e-9 * hsv[0])
    w = np.logspace(-5, 7, 20000)
    err_grid = np.abs(_freq(K, w)[0, 0] - _freq(red.controller, w)[0, 0]).max()
    assert err_grid <= red.error_hinf * (1 + 1e-6)
    assert err_grid >= red.error_hinf * (1 - 1e-3)
    assert red.bound == pytest.approx(2 * hsv[order:].sum(), rel=1e-6)
    assert hsv[order] * (1 - 1e-6) <= red.error_hinf <= red.bound * (1 + 1e-6)
    assert red.controller.nstates == order


def test_reduction_keeps_unstable_part():
    rng = np.random.default_rng(3)
    T = rng.normal(size=(6, 6))
    A = T @ np.diag([-0.3, -1.0, -2.0, -5.0, -10.0, -30.0]) @ np.linalg.inv(T)
    stable = ct.ss(A, rng.normal(size=(6, 1)), rng.normal(size=(1, 6)), rng.normal(size=(1, 1)))
    K = ct.parallel(stable, ct.ss(ct.tf([1.3], [1, -0.7])))
    red = hinf.reduce(K, 3)
    assert red.n_unstable == 1
    assert np.sum(red.controller.poles().real >= 0) == 1
    assert np.min(np.abs(red.controller.poles() - 0.7)) < 1e-9
    hsv = _hsv(stable)
    np.testing.assert_allclose(red.hankel_singular_values, hsv, rtol=1e-6, atol=1e-9 * hsv[0])
    assert hsv[2] * (1 - 1e-6) <= red.error_hinf <= 2 * hsv[2:].sum() * (1 + 1e-6)
    with pytest.raises(ValueError, match="unstable"):
        hinf.reduce(K, 0)


def test_reduce_arguments():
    K = hinf.mixed_sensitivity(G, w_s=W_S, w_ks=W_KS).controller
    with pytest.raises(ValueError, match="order"):
        hinf.reduce(K, K.nstates)
    with pytest.raises(ValueError, match="method"):
        hinf.reduce(K, 2, method="hankel")


@pytest.mark.parametrize("w0", [1.1, 20.0, 150.0])
def test_discretize_exact_at_prewarp_frequency(w0):
    K = hinf.mixed_sensitivity(G, w_s=W_S, w_ks=W_KS, suboptimality=0.05).controller
    dt = 0.01
    Kd = hinf.discretize(K, dt, prewarp_frequency=w0)
    assert Kd.dt == dt
    z = np.exp(1j * w0 * dt)
    kd = np.asarray(Kd(z)).ravel()[0]
    kc = np.asarray(K(1j * w0)).ravel()[0]
    assert kd == pytest.approx(kc, rel=1e-8)
    # Without prewarping Tustin warps the frequency, so the response differs there.
    kd_plain = np.asarray(hinf.discretize(K, dt)(z)).ravel()[0]
    assert abs(kd_plain - kc) > 1e3 * abs(kd - kc)


def test_discretize_arguments():
    K = hinf.mixed_sensitivity(G, w_s=W_S, w_ks=W_KS).controller
    with pytest.raises(ValueError, match="dt"):
        hinf.discretize(K, 0.0)
    with pytest.raises(ValueError, match="prewarp_frequency"):
        hinf.discretize(K, 0.1, prewarp_frequency=100.0)  # above π/dt
    with pytest.raises(ValueError, match="prewarp_frequency"):
        hinf.discretize(K, 0.1, method="zoh", prewarp_frequency=1.0)
    with pytest.raises(ValueError, match="method"):
        hinf.discretize(K, 0.1, method="euler")
