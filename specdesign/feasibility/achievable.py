"""The best pitch design over every stabilising controller: a convex Youla design (see :mod:`specdesign.feasibility`)."""
from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from .. import spectral
from .._checks import positive_scalar
from ..closedloop import MAX_SENSITIVITY, frequency_response, refine_grid, siso_response
from ..fatigue import TOWER_M
from ..spectral import trapezoid_weights

__all__ = ["HF_END", "HF_GAIN_RATIO", "HF_GRID_MARGIN", "HF_OMEGA", "MAX_HF_GAIN_RATIO", "SOLVER_FALLBACK_OPTIONS", "SOLVER_OPTIONS", "YOULA_REAL_POLES",
           "YOULA_PAIRS", "AchievablePitch", "achievable_pitch", "hf_check_omega", "hf_gain_bound", "YoulaProblem"]


#: Poles (rad/s) of the Youla basis: real poles spanning the wind band, and lightly damped pairs
#: (ζ = 0.2) around the tower mode, where the specification is shaped.
YOULA_REAL_POLES = np.geomspace(0.03, 10.0, 6)
YOULA_PAIRS = (0.9, 1.02, 1.1, 1.25)
#: Lowest frequency of the high-frequency gain bound |C| ≤ κ·|C_ROSCO| (rad/s): above the tower
#: mode (~1.1 rad/s on the IEA 15 MW, where the specification asks for pitch action) and below
#: 3P (2.375 rad/s).
HF_OMEGA = 2.0
#: Highest frequency of that bound (rad/s): the design grid's end (spec.default_omega); above it
#: the controller is only required to roll off (strictly proper: its gain falls at least as 1/ω).
HF_END = 10.0
#: κ of the high-frequency gain bound, |C_β(jω)| ≤ κ·|C_ROSCO(jω)| on HF_OMEGA-HF_END, that
#: ROSCO's actuator tolerates (``max_hf_gain_ratio=MAX_HF_GAIN_RATIO``). Source:
#: ``benchmarks/hf_bound.py`` (docs/feasibility.md, "The default factor"): ROSCO in OpenFAST on
#: the IEA 15 MW monopile with a TurbSim field at 19 m/s; the control band's pitch rate (ROSCO's)
#: and κ times ROSCO's pitch rate driven by the measured generator-speed content above HF_OMEGA,
#: in quadrature, keep 3σ within the pitch-rate limit.
HF_GAIN_RATIO = 110.0
#: Default ``max_hf_gain_ratio`` of every design entry point: the measured :data:`HF_GAIN_RATIO`,
#: the bound on (None switches it off). Under it the certified pairs promise the paper's 25 %
#: target at every speed 15-25 m/s once the plant cases' margin follows their excess
#: (``margin_bumps``, :mod:`specdesign.feasibility.margin`; docs/feasibility.md, "A
#: high-frequency gain bound and what it costs").
MAX_HF_GAIN_RATIO: float | None = HF_GAIN_RATIO
#: The Youla design keeps |C| this factor below the bound at its grid points, so that the bound
#: holds between them (a smooth Y interpolated between points 1.7 % apart: < 1 %) and after the
#: QFT step's balanced truncation (which must meet it by ORDER_MARGIN_DB = 0.01 dB).
HF_GRID_MARGIN = 0.98
#: Clarabel's stopping tolerances. A gap of 1e-6 on an objective of order 1 moves the promise by
#: < 1e-5 pp; tighter gaps (1e-7, 1e-8) are reached only after the primal residual of the
#: near-degenerate |S| cones at the lowest frequencies (S(0) = 0 forces them nearly tight) has
#: started to grow, and Clarabel then stops "almost solved" or fails ("insufficient progress")
#: at some relaxations and not at others a hair away: at 17 m/s and 17 − 1e-9 m/s, 8 of 42
#: relaxations (0.5-3 dB) were inaccurate or failed with a gap of 1e-7 and none with these.
#: A failed relaxation is a hole in the certificate search that moves its result by several pp.
SOLVER_OPTIONS = {"tol_gap_abs": 1e-6, "tol_gap_rel": 1e-6, "tol_feas": 1e-7}
#: Tried when :data:`SOLVER_OPTIONS` ends short of "optimal": without equilibration (the other
#: setting that solved every relaxation of the test above at 23 m/s).
SOLVER_FALLBACK_OPTIONS = {**SOLVER_OPTIONS, "equilibrate_enable": False}


def _youla_basis(s):
    """(n_s, n_basis) complex responses of the basis functions of Y at ``s`` (1/s)."""
    cols = [np.ones_like(s)]
    cols += [p / (s + p) for p in YOULA_REAL_POLES]
    for wn in YOULA_PAIRS:
        den = s * s + 2 * 0.2 * wn * s + wn * wn
        cols += [wn * wn / den, wn * s / den]
    return np.stack(cols, axis=1)


def _youla_tf(coef):
    import control

    terms = [control.tf([coef[0]], [1.0])]
    terms += [control.tf([c * p], [1.0, p]) for c, p in zip(coef[1:1 + YOULA_REAL_POLES.size], YOULA_REAL_POLES)]
    rest = coef[1 + YOULA_REAL_POLES.size:]
    for k, wn in enumerate(YOULA_PAIRS):
        a, b = rest[2 * k], rest[2 * k + 1]
        terms.append(control.tf([b * wn, a * wn * wn], [1.0, 2 * 0.2 * wn, wn * wn]))
    y = terms[0]
    for t in terms[1:]:
        y = y + t
    return y


def hf_ratio(max_hf_gain_ratio):
    """κ of the high-frequency gain bound, checked: None (no bound) or a number > 0 (-)."""
    if max_hf_gain_ratio is None:
        return None
    return positive_scalar(max_hf_gain_ratio, "max_hf_gain_ratio")


def hf_gain_bound(model, wind_speed, omega, max_hf_gain_ratio=MAX_HF_GAIN_RATIO, hf_omega=HF_OMEGA):
    """The high-frequency bound on the pitch controller's gain, κ·|C_ROSCO(jω)| on its band.

    Parameters
    ----------
    model : specdesign.turbine.TurbineModel
        The turbine (ROSCO's controller at ``wind_speed``: :func:`specdesign.spec.baseline_controller`).
    wind_speed : float
        Operating point, m/s.
    omega : array_like
        Frequencies, rad/s.
    max_hf_gain_ratio : float or None
        κ (-); default :data:`MAX_HF_GAIN_RATIO` (the measured κ, on), None: no bound; :data:`HF_GAIN_RATIO` is the measured κ.
    hf_omega : float
        Lowest frequency of the bound, rad/s (its highest is :data:`HF_END`).

    Returns
    -------
    numpy.ndarray or None
        |C_β| allowed at ``omega`` (rad per rad/s): κ·|C_ROSCO| on [``hf_omega``, :data:`HF_END`],
        ``np.inf`` outside it; None without a bound.
    """
    from .. import spec

    kappa = hf_ratio(max_hf_gain_ratio)
    if kappa is None:
        return None
    w = np.asarray(omega, float)
    lo = positive_scalar(hf_omega, "hf_omega")
    band = (w >= lo) & (w <= HF_END)
    out = np.full(w.shape, np.inf)
    out[band] = kappa * np.abs(siso_response(spec.baseline_controller(model, float(wind_speed)), w[band]))
    return out


def hf_check_omega(model, omega, controller_poles=()):
    """Where the high-frequency gain bound is checked: ``omega`` on its band, both ends and 3P.

    A bound relative to ROSCO's fast-falling |C| binds at the band's ends, which a logarithmic
    grid of the whole band need not hold; a controller's own lightly damped poles make narrow
    peaks of |C| that a grid can step over (one between points 1.3 % apart hid a 0.8 dB excess
    at 15 m/s), so with ``controller_poles`` the points are refined around them
    (:func:`specdesign.closedloop.refine_grid`).

    Parameters
    ----------
    model : specdesign.turbine.TurbineModel
        The turbine (3P from its ``rated_rotor_speed``, where it has one).
    omega : array_like
        A grid, rad/s.
    controller_poles : array_like of complex, optional
        The checked controller's poles, 1/s.

    Returns
    -------
    numpy.ndarray
        The points of ``omega`` on [HF_OMEGA, HF_END], both ends and 3P (and the refinement around
        ``controller_poles``), sorted, rad/s.
    """
    w = np.asarray(omega, float)
    extra = [HF_OMEGA, HF_END]
    three_p = 3.0 * float(getattr(model, "rated_rotor_speed", np.nan))
    if HF_OMEGA <= three_p <= HF_END:
        extra.append(three_p)
    out = np.union1d(w[(w >= HF_OMEGA) & (w <= HF_END)], extra)
    poles = np.asarray(controller_poles, complex).ravel()
    return refine_grid(out, poles) if poles.size else out


@dataclass(frozen=True)
class AchievablePitch:
    """A stabilising pitch design from :func:`achievable_pitch` and the specification it achieves.

    Parameters
    ----------
    wind_speed : float
        Operating point, m/s.
    speed_relax_db : float
        Relaxation of the generator-speed specification it meets, dB.
    max_sensitivity : float
        M_s it meets (-).
    omega : numpy.ndarray
        Grid, rad/s.
    youla : numpy.ndarray
        Coefficients of Y on the basis (:data:`YOULA_REAL_POLES`, :data:`YOULA_PAIRS`).
    t_tower, t_speed, sensitivity : numpy.ndarray
        T_{MyT,w} (N·m per m/s), T_{Ω,w} ((rad/s) per (m/s)) and S (-) on ``omega``, complex.
    del_reduction : float
        Exact (Dirlik, 1 Hz) tower-base DEL reduction against ROSCO, %.
    speed_excess_db : float
        Largest |T_{Ω,w}|/|W_Ω| on the grid, dB (≤ 0 up to the solver's tolerance).
    status : str
        The solver's status.
    """

    wind_speed: float
    speed_relax_db: float
    max_sensitivity: float
    omega: np.ndarray
    youla: np.ndarray
    t_tower: np.ndarray
    t_speed: np.ndarray
    sensitivity: np.ndarray
    del_reduction: float
    speed_excess_db: float
    status: str

    def controller(self, model):
        """The pitch controller C = Y/(1 − P_{Ω,β}·Y) that achieves it, β = −C·Ω_g.

        Parameters
        ----------
        model : specdesign.turbine.TurbineModel
            The turbine it was designed on.

        Returns
        -------
        control.TransferFunction
            C (rad per rad/s); of high order (the basis plus the plant): a certificate of
            feasibility and a reference, not a controller to implement as it is.
        """
        import control

        p = control.ss(model.linearize(self.wind_speed))["gen_speed", "pitch_cmd"]
        y = _youla_tf(self.youla)
        return control.minreal(control.feedback(y, control.tf(p), sign=+1), verbose=False)


def _noise_rate(model, plant, c_base, wind_speed, noise, w, tw, c_ref, ob, phi_o, rr):
    """The pitch rate driven by the measured speed's noise (:class:`~specdesign.controller.noise.SensorNoise`).

    With β = −C·(Ω_g + n), T_{β,n} = −C·S = −Y: affine in the design, the rate spectrum is
    |ω·Y|²·S_n with S_n the white noise's PSD at the noise's ``sample_time`` (flat on the grid),
    integrated with the grid's trapezoid weights ``tw``, plus the 3P line's variance A²/2 at
    ω_3P = 3·Ω_r (the trim's rotor speed) times |ω_3P·Y(jω_3P)|². ROSCO's side is the same with
    its C (``c_base``, ``c_ref`` on the grid) and S. The white part counts on the design grid
    only, as the wind's does: above its end (10 rad/s by default) neither is in the constraint.
    Returns ROSCO's noise-driven rate variance, (rad/s)², and the rows R (complex, in the
    orthonormal coordinates of ``phi_o``, ``rr``) with ‖R y‖² the design's.
    """
    s_ref = 1.0 / (1.0 + c_ref * ob)
    sn = noise.psd("gen_speed", w, noise.sample_time)
    ref = float(np.sum(tw * np.abs(w * c_ref * s_ref) ** 2 * sn))
    rows = [w[:, None] * phi_o * np.sqrt(tw * sn)[:, None]]
    w3, var3 = noise.lines(model.trim(wind_speed).rotor_speed)
    if var3 > 0:
        w2 = np.array([w3, 2.0 * w3])  # the maps take a grid of ≥ 2 frequencies: ω_3P is its first
        c3 = siso_response(c_base, w2)[0]
        ob3 = frequency_response(plant, w2, "gen_speed", "pitch_cmd")[0]
        ref += float(w3 ** 2 * np.abs(c3 / (1.0 + c3 * ob3)) ** 2 * var3)
        phi3 = np.linalg.solve(rr.T, _youla_basis(np.array([1j * w3]))[0])  # phi = q·rr: the row of q at ω_3P
        rows.append((w3 * np.sqrt(var3) * phi3)[None, :])
    return ref, rows


def achievable_pitch(model, wind_speed, speed_relax_db=0.0, *, max_sensitivity=MAX_SENSITIVITY, max_pitch_rate_ratio=1.0,
                     m=TOWER_M, omega=None, base=None, integral_action=True, noise=None,
                     max_hf_gain_ratio=MAX_HF_GAIN_RATIO) -> AchievablePitch:
    """The pitch design that minimises the predicted tower damage under a generator-speed specification.

    Every stabilising controller of the stable plant is C = Y/(1 − P_{Ω,β}Y) with Y stable,
    and then S = 1 − P_{Ω,β}Y, T_{Ω,w} = P_{Ω,w}S, T_{MyT,w} = P_{MyT,w} − P_{MyT,β}P_{Ω,w}Y:
    affine in Y. With Y on a fixed stable basis, minimising Eq. (10)'s damage,
    Σ ΔD%(ω)·|T_{MyT,w}|²/|T^ROSCO_{MyT,w}|², subject to |T_{Ω,w}| ≤ 10^(g/20)|T^ROSCO_{Ω,w}|
    and |S| ≤ M_s on the grid, with at most ``max_pitch_rate_ratio`` times ROSCO's pitch-rate
    SD, is a convex (second-order cone) problem. The design is for the nominal plant at
    ``wind_speed`` (no plant cases besides it; robustness only through M_s), and its controller
    is of high order: it shows what a specification can promise, not what to implement.

    Parameters
    ----------
    model : specdesign.turbine.TurbineModel
        The turbine.
    wind_speed : float
        Operating point, m/s.
    speed_relax_db : float
        Relaxation g of the generator-speed specification, dB (≥ 0).
    max_sensitivity : float
        M_s (-).
    max_pitch_rate_ratio : float
        κ: the pitch-rate SD, ∫|ω·T_{β,w}|²S_W dω on the grid, at most κ² times ROSCO's
        (a quadratic constraint; 1.0: no more pitch activity than ROSCO); its variance for
        the square, with ``noise`` the noise-driven rate added on both sides.
    m : float
        Wöhler exponent (-).
    omega : array_like, optional
        Grid, rad/s (default :func:`specdesign.spec.default_omega`).
    base : specdesign.spec.Baseline, optional
        ROSCO's baseline at ``wind_speed`` if already computed (its grid is used).
    integral_action : bool
        Require S(0) = 0 (a linear equality on Y(0)): the controller integrates the speed error
        as ROSCO's PI does, so T_{Ω,w} vanishes at 0 rad/s and the speed specification holds
        below the grid too (without it the design may trade the steady-state speed error).
    noise : specdesign.controller.noise.SensorNoise, optional
        Sensor noise on the measured generator speed: the pitch-rate variance of both the
        design and ROSCO then includes ∫|ω·C·S|²·S_n dω on the grid (S_n the white noise's
        PSD at the noise's ``sample_time``) and the 3P line's |ω_3P·C·S|²·A²/2. None (default):
        the wind alone, as before.
    max_hf_gain_ratio : float or None
        κ of the high-frequency gain bound |C| ≤ κ·|C_ROSCO| on :data:`HF_OMEGA`-:data:`HF_END`
        rad/s, C strictly proper (default :data:`MAX_HF_GAIN_RATIO`, on; None: no bound; :data:`HF_GAIN_RATIO` is the measured κ).

    Returns
    -------
    AchievablePitch
        The design, its maps and its exact promise.

    Raises
    ------
    RuntimeError
        If the solver finds no solution.
    """
    g = float(speed_relax_db)
    if not (np.isfinite(g) and g >= 0):
        raise ValueError(f"speed_relax_db={speed_relax_db!r} must be a relaxation ≥ 0 dB")
    return YoulaProblem(model, wind_speed, max_sensitivity=max_sensitivity, max_pitch_rate_ratio=max_pitch_rate_ratio,
                        m=m, omega=omega, base=base, integral_action=integral_action, noise=noise,
                        max_hf_gain_ratio=max_hf_gain_ratio).solve(g)


class YoulaProblem:
    """The convex problem of :func:`achievable_pitch` at one operating point, compiled once.

    Only the generator-speed bound changes with the relaxation g (a cvxpy parameter), so
    :meth:`solve` at several g (a frontier, a bisection) re-uses the compiled problem.

    Parameters
    ----------
    model : specdesign.turbine.TurbineModel
        The turbine.
    wind_speed : float
        Operating point, m/s.
    max_sensitivity : float
        M_s (-).
    max_pitch_rate_ratio : float
        κ, pitch-rate SD allowance relative to ROSCO's (-).
    m : float
        Wöhler exponent (-).
    omega : array_like, optional
        Grid, rad/s (default :func:`specdesign.spec.default_omega`).
    base : specdesign.spec.Baseline, optional
        ROSCO's baseline at ``wind_speed`` if already computed (its grid is used).
    integral_action : bool
        Require S(0) = 0 (see :func:`achievable_pitch`).
    tower_bound : bool
        Also bound the tower map, |T_{MyT,w}| ≤ 10^(b/20)·|T^ROSCO_{MyT,w}| at each grid point,
        with b given to :meth:`solve` (``tower_bound_db``): the design then meets a given tower
        specification, as when shaping elements are certified
        (:func:`specdesign.feasibility.element_specification`).
    max_hf_gain_ratio : float or None
        κ_hf: bound the controller's high-frequency gain, |C(jω)| ≤ κ_hf·|C_ROSCO(jω)| at the
        grid points from ``hf_omega`` to :data:`HF_END` (3P included), with Y(∞) = 0 so that C
        is strictly proper (default :data:`MAX_HF_GAIN_RATIO`, on; None: no bound; :data:`HF_GAIN_RATIO` is the measured κ). Imposed convexly as
        |Y| ≤ b/(1 + b·|P_{Ω,β}|), b = κ_hf·|C_ROSCO| (times :data:`HF_GRID_MARGIN`), which
        implies it since C = Y/(1 − P_{Ω,β}Y). Its cost: docs/feasibility.md, "A high-frequency
        gain bound".
    hf_omega : float, optional
        Lowest frequency of that bound, rad/s (default :data:`HF_OMEGA`).
    noise : specdesign.controller.noise.SensorNoise, optional
        Sensor noise in the pitch-rate constraint (see :func:`achievable_pitch`).
    """

    def __init__(self, model, wind_speed, *, max_sensitivity=MAX_SENSITIVITY, max_pitch_rate_ratio=1.0, m=TOWER_M, omega=None,
                 base=None, integral_action=True, tower_bound=False, max_hf_gain_ratio=MAX_HF_GAIN_RATIO, hf_omega=None,
                 noise=None):
        import cvxpy as cp

        from .. import spec
        kappa = positive_scalar(max_pitch_rate_ratio, "max_pitch_rate_ratio")
        self.ms = positive_scalar(max_sensitivity, "max_sensitivity")
        self.wind_speed = float(wind_speed)
        if base is None:
            base = spec.baseline_analysis(model, wind_speed, m=m, omega=omega)
        self.base, w = base, base.omega
        plant = model.linearize(self.wind_speed)
        self.a = frequency_response(plant, w, "tower_base_my", "wind")
        self.ow = frequency_response(plant, w, "gen_speed", "wind")
        self.ob = frequency_response(plant, w, "gen_speed", "pitch_cmd")
        self.gy = frequency_response(plant, w, "tower_base_my", "pitch_cmd") * self.ow
        self.w_speed0 = np.abs(spec.speed_specification(model, self.wind_speed).response(w))
        phi = _youla_basis(1j * w)
        t_ref2 = np.abs(base.t_response) ** 2
        weight = np.maximum(base.sensitivity, 0.0) + 1e-3 * base.sensitivity.max()

        # solve in orthonormal coordinates of the basis on the grid (the raw basis is collinear)
        q, self.rr = np.linalg.qr(np.vstack([phi.real, phi.imag]))
        self.phi_o = phi_o = q[: w.size] + 1j * q[w.size:]
        self.y = y = cp.Variable(phi.shape[1])
        # the objective Σ weight·|T_MyT|²/|T^ROSCO|², T_MyT affine in y, is ‖M y + b‖²: handed to
        # the solver as ‖R y + Qᵀb‖² (M = QR, n_basis rows) and each |S| bound as one 3-cone on
        # affine expressions of y, the problem has n_basis variables instead of cvxpy's ~3·n_omega
        # auxiliaries for sums of squares and norms (the same optimum, 3-4× faster to solve)
        scale = np.sqrt(weight / t_ref2)
        tl = -(scale * self.gy)[:, None] * phi_o
        m_obj = np.vstack([tl.real, tl.imag])
        b_obj = np.r_[scale * self.a.real, scale * self.a.imag]
        q_obj, r_obj = np.linalg.qr(m_obj)
        qb = q_obj.T @ b_obj
        objective = cp.sum_squares(r_obj @ y + qb) + max(float(b_obj @ b_obj - qb @ qb), 0.0)
        sl = -self.ob[:, None] * phi_o
        self.s_bound = cp.Parameter(w.size, nonneg=True)  # min(M_s, W_Ω/|P_{Ω,w}|): |S| ≤ M_s and |P_{Ω,w}S| ≤ W_Ω
        constraints = [cp.SOC(self.s_bound, cp.vstack([1.0 + sl.real @ y, sl.imag @ y]), axis=0)]
        # pitch-rate activity: the rate spectrum |ω·T_{β,w}|²S_W, T_{β,w} = −P_{Ω,w}Y, integrated
        # (trapezoid weights), at most κ² times ROSCO's: ‖rl·y‖ ≤ κ, as ‖R_rate y‖ ≤ κ; with sensor
        # noise, the rate its measured-speed noise drives on both sides too (_noise_rate)
        tw = trapezoid_weights(w)
        c_base = spec.baseline_controller(model, self.wind_speed)
        c_ref = siso_response(c_base, w)
        rate_ref = float(np.sum(tw * np.abs(w * c_ref * self.ow / (1 + c_ref * self.ob)) ** 2 * base.wind_psd))
        noise_rows = ()
        if noise is not None:
            noise_ref, noise_rows = _noise_rate(model, plant, c_base, self.wind_speed, noise, w, tw, c_ref, self.ob, phi_o,
                                                self.rr)
            rate_ref += noise_ref
        rl = (w * self.ow)[:, None] * phi_o * np.sqrt(tw * base.wind_psd / rate_ref)[:, None]  # scaled to ROSCO's: O(1)
        rl = np.vstack([rl, *(r / np.sqrt(rate_ref) for r in noise_rows)])
        r_rate = np.linalg.qr(np.vstack([rl.real, rl.imag]), mode="r")
        constraints.append(cp.SOC(cp.Constant(kappa), r_rate @ y))
        if integral_action:  # S(0) = 1 − P_{Ω,β}(0)·Y(0) = 0, in the orthonormal coordinates
            p0 = float(np.real(plant["gen_speed", "pitch_cmd"].dcgain()))
            phi0 = np.linalg.solve(self.rr.T, np.real(_youla_basis(np.zeros(1, complex))[0]))
            constraints.append(p0 * (phi0 @ y) == 1.0)
        self.hf_gain = None
        kappa_hf = hf_ratio(max_hf_gain_ratio)
        if kappa_hf is not None:
            # |C| ≤ b = κ·|C_ROSCO| on hf_omega-HF_END. C = Y/S, S = 1 − P_{Ω,β}Y, so |C| ≤ |Y|/(1 − |P_{Ω,β}||Y|)
            # and |Y| ≤ b/(1 + b·|P_{Ω,β}|) guarantees |C| ≤ b at each grid point (above the crossover
            # b·|P_{Ω,β}| ≪ 1: little tightening), convexly (one 3-cone per frequency), with
            # HF_GRID_MARGIN for between the points; Y(∞) = 0 makes C strictly proper
            w_hf = HF_OMEGA if hf_omega is None else positive_scalar(hf_omega, "hf_omega")
            band = (w >= w_hf) & (w <= HF_END)
            if not band.any():
                raise ValueError(f"hf_omega={hf_omega!r} rad/s leaves no grid point between it and {HF_END:g} rad/s "
                                 "(HF_END): give one below it")
            self.hf_gain = (kappa_hf, w_hf)
            b = kappa_hf * np.abs(c_ref[band])
            y_max = HF_GRID_MARGIN * b / (1 + b * np.abs(self.ob[band]))
            yl = phi_o[band] / y_max[:, None]
            constraints.append(cp.SOC(np.ones(int(band.sum())), cp.vstack([yl.real @ y, yl.imag @ y]), axis=0))
            inf_row = np.linalg.solve(self.rr.T, np.eye(phi.shape[1])[0])  # Y(∞) = coef[0] = (R⁻¹y)[0]
            constraints.append(inf_row @ y == 0.0)
        self.t_bound = None
        if tower_bound:  # |T_MyT|/|T^ROSCO| ≤ 10^(b/20): one 3-cone per frequency, in units of ROSCO's map
            ref = np.abs(base.t_response)
            tt = -(self.gy / ref)[:, None] * phi_o
            self.t_bound = cp.Parameter(w.size, nonneg=True)
            constraints.append(cp.SOC(self.t_bound, cp.vstack([self.a.real / ref + tt.real @ y,
                                                               self.a.imag / ref + tt.imag @ y]), axis=0))
        self.problem = cp.Problem(cp.Minimize(objective), constraints)

    def solve(self, speed_relax_db, tower_bound_db=None):
        """The design under the speed map relaxed by ``speed_relax_db``.

        Parameters
        ----------
        speed_relax_db : float
            Relaxation g of the generator-speed specification, dB (≥ 0).
        tower_bound_db : array_like, optional
            The tower bound b(ω) on the grid, dB over ROSCO's |T_{MyT,w}| (a problem made with
            ``tower_bound=True`` only; required there).

        Returns
        -------
        AchievablePitch
            The design, its maps and its exact promise.

        Raises
        ------
        ValueError
            For a negative or non-finite relaxation, or a tower bound that is missing, not
            finite, of another length than the grid, or given to a problem without one.
        RuntimeError
            If the solver finds no solution or fails (a cvxpy ``SolverError``): a search over
            the relaxation then counts that relaxation as one with no design.
        """
        import cvxpy as cp

        g = float(speed_relax_db)
        if not (np.isfinite(g) and g >= 0):
            raise ValueError(f"speed_relax_db={speed_relax_db!r} must be a relaxation ≥ 0 dB")
        base, w = self.base, self.base.omega
        if (tower_bound_db is None) != (self.t_bound is None):
            raise ValueError("tower_bound_db is required by a YoulaProblem made with tower_bound=True, and refused by "
                             "one made without")
        if tower_bound_db is not None:
            b = np.asarray(tower_bound_db, float)
            if b.shape != w.shape or not np.all(np.isfinite(b)):
                raise ValueError(f"tower_bound_db must be {w.size} finite values (dB) on the problem's grid")
            self.t_bound.value = 10 ** (b / 20)
        w_speed = self.w_speed0 * 10 ** (g / 20)
        self.s_bound.value = np.minimum(self.ms, w_speed / np.abs(self.ow))
        failure = None
        for options in (SOLVER_OPTIONS, SOLVER_FALLBACK_OPTIONS):
            try:
                with warnings.catch_warnings():
                    # cvxpy's "solution may be inaccurate": the status says it, and the fallback is tried
                    warnings.filterwarnings("ignore", message="Solution may be inaccurate", category=UserWarning)
                    self.problem.solve(solver=cp.CLARABEL, **options)
            except cp.error.SolverError as e:  # e.g. Clarabel's "insufficient progress"
                failure = e
                continue
            failure = None
            if self.problem.status == "optimal":
                break
        if failure is not None:  # no design, said as such
            raise RuntimeError(f"achievable_pitch at {self.wind_speed:g} m/s: the solver failed ({failure})") from failure
        y, status = self.y.value, self.problem.status
        if y is None or status not in ("optimal", "optimal_inaccurate"):
            raise RuntimeError(f"achievable_pitch at {self.wind_speed:g} m/s: the solver returned {status!r}")
        coef = np.linalg.solve(self.rr, np.asarray(y, float))
        if self.hf_gain is not None:
            # Y(∞) = 0 holds to the solver's tolerance (~1e-12): exactly, so that C is strictly
            # proper and its transfer function has no spurious leading coefficient (a huge zero)
            coef[0] = 0.0
        yv = self.phi_o @ (self.rr @ coef)
        sens = 1 - self.ob * yv
        t_tower = self.a - self.gy * yv
        t_speed = self.ow * sens
        d = spectral.damage_rate(w, np.abs(t_tower) ** 2 * base.wind_psd, base.m, method=base.method)
        red = float(spectral.del_reduction(100.0 * (1.0 - d / base.damage_rate), base.m))
        excess = float(20 * np.log10(np.max(np.abs(t_speed) / w_speed)))
        return AchievablePitch(self.wind_speed, g, self.ms, w, coef, t_tower, t_speed, sens, red, excess, str(status))
