"""Necessary conditions on a specification pair for pitch control, and the frontier (see :mod:`specdesign.feasibility`)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._blas import on_one_blas_thread
from .._checks import as_omega, positive_scalar, real_scalar
from ..closedloop import (
    MAX_SENSITIVITY,
    closed_map,
    plant_responses,
    refine_grid,
    siso_response,
)
from ..fatigue import TOWER_M
from .. import spectral
from ..spectral import trapezoid_weights
from .achievable import MAX_HF_GAIN_RATIO, YoulaProblem

__all__ = ["PitchFeasibility", "pitch_feasibility", "PitchChecker", "pitch_checkers", "combine", "pitch_frontier",
           "sensitivity_disks"]


def sensitivity_disks(plant, omega, w_tower, w_speed, max_sensitivity=MAX_SENSITIVITY):
    """The disks of the complex sensitivity S(jω) that each specification allows.

    Parameters
    ----------
    plant : control.LTI
        Named plant (inputs ``wind``, ``pitch_cmd``; outputs ``gen_speed``, ``tower_base_my``).
    omega : array_like
        Frequencies, rad/s (all > 0).
    w_tower, w_speed : array_like
        |W_MyT(jω)| (N·m per m/s) and |W_Ω(jω)| ((rad/s) per (m/s)) on ``omega``; ``np.inf``
        for no constraint.
    max_sensitivity : float or None
        M_s, the bound on |S| of the pitch loop (-); None for none.

    Returns
    -------
    dict
        ``c`` (complex centre) and ``rho`` (radius) of the tower disk |S − c| ≤ ρ,
        ``r_speed`` = |W_Ω|/|P_{Ω,w}| and ``r_margin`` = M_s (radii of disks about 0),
        ``open_loop`` = P_{MyT,w} − K∞ (the factor of S in T_{MyT,w}) and ``k_inf`` = K∞,
        all arrays on ``omega``.
    """
    w = as_omega(omega, "omega", allow_zero=False)  # ω = 0: the disks' 1/|P| at DC is no frequency-domain bound
    ms = np.inf if max_sensitivity is None else positive_scalar(max_sensitivity, "max_sensitivity")
    R = plant_responses([plant], w, ("tower_base_my", "gen_speed"), method="batched")
    a, yb = R[("tower_base_my", "wind")][:, 0], R[("tower_base_my", "pitch_cmd")][:, 0]
    ow, ob = R[("gen_speed", "wind")][:, 0], R[("gen_speed", "pitch_cmd")][:, 0]
    k_inf = a - yb * ow / ob
    g = a - k_inf  # = P_{MyT,β}·P_{Ω,w}/P_{Ω,β}
    return dict(c=-k_inf / g, rho=np.asarray(w_tower, float) / np.abs(g), r_speed=np.asarray(w_speed, float) / np.abs(ow),
                r_margin=np.full(w.shape, ms), open_loop=g, k_inf=k_inf)


def _rhp_zeros(plant):
    import control

    sub = control.ss(plant)["gen_speed", "pitch_cmd"]
    # state-space (invariant) zeros: a transfer function's numerator of an OpenFAST-sized plant
    # (~100 states) has spurious roots, and leading coefficients ~ 0 give huge ones
    z = np.asarray(sub.zeros(), complex)
    return z[(z.real > 0) & np.isfinite(z) & (np.abs(z) < 1e6)]


def _poisson_kernel(z):
    x, y = float(z.real), float(z.imag)

    def kernel(om):  # both signs of ω folded onto ω ≥ 0
        return (x / (x * x + (om - y) ** 2) + x / (x * x + (om + y) ** 2)) / np.pi

    def cdf(om):  # its mass on [0, om]
        return (np.arctan((om - y) / x) + np.arctan((om + y) / x)) / np.pi

    return kernel, cdf


def _poisson_weights(omega, z):
    """Weights q with q @ f = (1/π)∫ f(|ω|)·Re z/((Re z)² + (ω − Im z)²) dω over the grid
    (ω of both signs), trapezoid rule, for z = x + iy with x > 0."""
    kernel, _ = _poisson_kernel(z)
    return trapezoid_weights(omega) * kernel(omega)


def _poisson_mass(omega, z):
    """The Poisson kernel's mass on the grid's span (closed form)."""
    _, cdf = _poisson_kernel(z)
    return float(cdf(omega[-1]) - cdf(omega[0]))


def _poisson_mean(omega, values, z, outside):
    """Poisson mean of ``values`` over the grid plus ``outside`` times the kernel's mass off it."""
    return float(_poisson_weights(omega, z) @ values + outside * (1.0 - _poisson_mass(omega, z)))


@dataclass(frozen=True)
class PitchFeasibility:
    """Verdict of :func:`pitch_feasibility` at one operating point.

    Parameters
    ----------
    feasible : bool
        Both necessary conditions hold for every plant case.
    omega : numpy.ndarray
        Frequencies checked, rad/s.
    pointwise : numpy.ndarray
        (n_omega,) True where the disks intersect for every case.
    binding : tuple of str
        Per frequency, the pair of specifications that cannot be met together there ("" where
        they can): "tower vs speed" or "tower vs margin".
    zeros : numpy.ndarray
        Right-half-plane zeros of P_{Ω,β} (1/s), nominal case.
    poisson_mean : numpy.ndarray
        Per plant case and right-half-plane zero (upper half-plane; in that order), the
        Poisson mean of ln s_max (must be ≥ 0).
    reasons : tuple of str
        One sentence per violated condition (empty when feasible).
    max_sensitivity : float
        The M_s used (-; inf for none).
    """

    feasible: bool
    omega: np.ndarray
    pointwise: np.ndarray
    binding: tuple
    zeros: np.ndarray
    poisson_mean: np.ndarray
    reasons: tuple
    max_sensitivity: float

    def summary(self) -> str:
        """One paragraph: the verdict and, if infeasible, why.

        Returns
        -------
        str
            "feasible (necessary conditions)" or "infeasible: " and the reasons.
        """
        if self.feasible:
            return ("feasible: the necessary conditions hold (pointwise at every frequency, and around the "
                    f"right-half-plane zeros {_fmt(self.zeros)} of P_Ω,β)")
        return "infeasible: " + "; ".join(self.reasons)


def _fmt(z):
    return ", ".join(f"{v.real:.3g}{v.imag:+.4g}j" for v in np.atleast_1d(z)) or "none"


def _bands(omega, mask):
    """Contiguous runs of ``mask`` as 'a-b rad/s' strings."""
    idx = np.flatnonzero(mask)
    if idx.size == 0:
        return []
    splits = np.flatnonzero(np.diff(idx) > 1)
    starts, ends = np.r_[idx[0], idx[splits + 1]], np.r_[idx[splits], idx[-1]]
    return [f"{omega[a]:.3g}-{omega[b]:.3g} rad/s" if a != b else f"{omega[a]:.3g} rad/s" for a, b in zip(starts, ends)]


@on_one_blas_thread
def pitch_feasibility(model, wind_speed, tower_spec, speed_spec, *, max_sensitivity=MAX_SENSITIVITY, omega=None,
                      cases=None) -> PitchFeasibility:
    """Whether a tower-load and a generator-speed specification can be met by pitch control.

    Checks the two necessary conditions of the module docstring (pointwise disk intersection;
    the Poisson condition at the right-half-plane zeros of P_{Ω,β}) for every plant case.

    Parameters
    ----------
    model : specdesign.turbine.TurbineModel
        The turbine (anything with ``linearize(wind_speed)`` giving a named plant).
    wind_speed : float
        Operating point, m/s.
    tower_spec, speed_spec : Specification or callable
        W_MyT and W_Ω: anything with ``response(omega)`` (a :class:`specdesign.spec.Specification`)
        or a callable ω → |W|; None for no constraint.
    max_sensitivity : float or None
        M_s on |S| of a pitch loop on Ω_g (-); 2.0 (6 dB) by default. None: no margin
        condition, and the verdict holds for any controller acting through the pitch (an
        ATD loop included).
    omega : array_like, optional
        Frequencies, rad/s, all > 0 (default :func:`specdesign.spec.default_omega`, refined around
        the right-half-plane zeros so the Poisson kernel is resolved).
    cases : sequence of float, optional
        Wind speeds (m/s) of the plant cases; default only ``wind_speed``.

    Returns
    -------
    PitchFeasibility
        The verdict, per-frequency bindings and the reasons.

    Examples
    --------
    >>> from specdesign.turbine import iea15mw
    >>> from specdesign import spec
    >>> model = iea15mw()
    >>> rosco_specs = spec.design_specifications(model, 19.0, speed_relax_db=0.0, tower_relax_db=0.0)
    >>> pitch_feasibility(model, 19.0, rosco_specs.base.system, rosco_specs.speed).feasible  # ROSCO meets its own
    True
    """
    checkers = pitch_checkers(model, wind_speed, speed_spec, max_sensitivity=max_sensitivity, omega=omega, cases=cases)
    w = checkers[0].omega
    return combine([c.check(_magnitude(tower_spec, w, "tower_spec")) for c in checkers])


@dataclass(frozen=True)
class PitchChecker:
    """The feasibility conditions of one plant case, precomputed for a given speed specification.

    Everything but the tower specification is fixed, so :meth:`check` is a few vector
    operations on the grid (≪ 1 ms): fast enough for a slider callback.

    Parameters
    ----------
    omega : numpy.ndarray
        Grid, rad/s (refined around the right-half-plane zeros of P_{Ω,β}).
    c : numpy.ndarray
        Centre of the tower disk for S (complex).
    inv_g : numpy.ndarray
        1/|P_{MyT,w} − K∞|, so that ρ = |W_MyT|/|P_{MyT,w} − K∞| (per N·m per m/s).
    r_speed, r_margin : numpy.ndarray
        Radii of the speed and margin disks about 0 (-).
    t_rosco : numpy.ndarray
        |T^ROSCO_{MyT,w}| on ``omega`` (N·m per m/s): a specification's reference.
    zeros : numpy.ndarray
        Right-half-plane zeros of P_{Ω,β} of this case (upper half-plane), 1/s.
    kernels : numpy.ndarray
        (n_zeros, n_omega) Poisson weights (trapezoid rule included) of each zero.
    outside : numpy.ndarray
        (n_zeros,) the kernel's mass off the grid times the bound on ln|S| there.
    max_sensitivity : float
        M_s (-; inf for none).
    """

    omega: np.ndarray
    c: np.ndarray
    inv_g: np.ndarray
    r_speed: np.ndarray
    r_margin: np.ndarray
    t_rosco: np.ndarray
    zeros: np.ndarray
    kernels: np.ndarray
    outside: np.ndarray
    max_sensitivity: float

    def check(self, w_tower) -> PitchFeasibility:
        """The verdict for a tower specification of magnitude ``w_tower`` on :attr:`omega`.

        Parameters
        ----------
        w_tower : array_like
            |W_MyT(jω)| on :attr:`omega`, N·m per m/s (``np.inf``: no constraint).

        Returns
        -------
        PitchFeasibility
            This case's verdict.
        """
        rho = np.asarray(w_tower, float) * self.inv_g
        ac = np.abs(self.c)
        r = np.minimum(self.r_speed, self.r_margin)
        bad = ac - rho > r  # the tower disk misses the disk about 0
        binding = np.where(bad, np.where(self.r_speed <= self.r_margin, "tower vs speed", "tower vs margin"), "")
        with np.errstate(divide="ignore"):
            s_max = np.log(np.minimum(r, ac + rho))
        means = self.kernels @ s_max + self.outside if self.zeros.size else np.zeros(0)
        return _verdict(self.omega, ~bad, binding, self.zeros, means, self.max_sensitivity)


def pitch_checkers(model, wind_speed, speed_spec, *, max_sensitivity=MAX_SENSITIVITY, omega=None, cases=None) -> list:
    """One :class:`PitchChecker` per plant case, on one grid.

    Parameters
    ----------
    model : specdesign.turbine.TurbineModel
        The turbine.
    wind_speed : float
        Operating point, m/s.
    speed_spec : Specification, callable or None
        W_Ω ((rad/s) per (m/s)), as in :func:`pitch_feasibility`.
    max_sensitivity : float or None
        M_s (-), or None for none.
    omega : array_like, optional
        Grid, rad/s, all > 0 (default :func:`specdesign.spec.default_omega` refined around the
        right-half-plane zeros of the nominal P_{Ω,β}).
    cases : sequence of float, optional
        Wind speeds (m/s) of the plant cases; default only ``wind_speed``.

    Returns
    -------
    list of PitchChecker
        Nominal case first when ``cases`` is None, else in the order given.
    """
    from .. import spec
    v = real_scalar(wind_speed, "wind_speed")
    ms = np.inf if max_sensitivity is None else positive_scalar(max_sensitivity, "max_sensitivity")
    speeds = [v] if cases is None else [real_scalar(c, f"cases[{i}]") for i, c in enumerate(cases)]
    # the grid checked before any plant is linearised; ω must be > 0 (the Poisson kernel and the
    # disks' radii divide by ω and by the plant's DC gain)
    w = spec.default_omega() if omega is None else as_omega(omega, "omega", allow_zero=False)
    plants = [model.linearize(x) for x in speeds]
    zeros0 = _rhp_zeros(plants[0])
    if omega is None and zeros0.size:
        w = refine_grid(w, zeros0, rel_width=0.2, rel_step=2e-4)
    ws = _magnitude(speed_spec, w, "speed_spec")
    R0 = plant_responses([model.linearize(v)], w, ("tower_base_my", "gen_speed", "tower_top_vel"), method="batched")
    t_rosco = np.abs(closed_map(R0, siso_response(spec.baseline_controller(model, v), w)[:, None], 0.0,
                                "tower_base_my"))[:, 0]
    out = []
    for plant in plants:
        d = sensitivity_disks(plant, w, np.ones(w.shape), ws, max_sensitivity)
        r = np.minimum(d["r_speed"], d["r_margin"])
        zs = _rhp_zeros(plant)
        zs = zs[zs.imag >= 0]
        # off the grid |S| ≤ M_s, or without it the speed bound at the grid's ends (S → 1 there)
        outside_bound = np.log(ms) if np.isfinite(ms) else float(np.log(max(r[0], r[-1])))
        kernels = np.array([_poisson_weights(w, z) for z in zs]).reshape(len(zs), w.size)
        outside = np.array([outside_bound * (1.0 - _poisson_mass(w, z)) for z in zs])
        out.append(PitchChecker(w, d["c"], 1.0 / np.abs(d["open_loop"]), d["r_speed"], d["r_margin"], t_rosco, zs,
                                kernels, outside, ms))
    return out


def combine(verdicts) -> PitchFeasibility:
    """One verdict from several plant cases' (on one grid): feasible only if every case is.

    Parameters
    ----------
    verdicts : sequence of PitchFeasibility
        From :meth:`PitchChecker.check`, nominal first.

    Returns
    -------
    PitchFeasibility
        Pointwise where every case is, the first binding pair per frequency, the zeros of the
        first case, every case's Poisson means and reasons.
    """
    verdicts = list(verdicts)
    first = verdicts[0]
    if len(verdicts) == 1:
        return first
    ok = np.logical_and.reduce([x.pointwise for x in verdicts])
    binding = tuple(next((b[i] for b in (x.binding for x in verdicts) if b[i]), "") for i in range(first.omega.size))
    reasons = tuple(dict.fromkeys(r for x in verdicts for r in x.reasons))
    return PitchFeasibility(feasible=all(x.feasible for x in verdicts), omega=first.omega, pointwise=ok, binding=binding,
                            zeros=first.zeros, poisson_mean=np.concatenate([x.poisson_mean for x in verdicts]),
                            reasons=reasons, max_sensitivity=first.max_sensitivity)


def _verdict(w, ok, binding, zeros, means, ms) -> PitchFeasibility:
    reasons = []
    if not ok.all():
        for kind in ("tower vs speed", "tower vs margin"):
            bands = _bands(w, binding == kind)
            if bands:
                what = "the generator-speed specification" if kind == "tower vs speed" else f"|S| ≤ M_s = {ms:g}"
                reasons.append(f"the tower-load specification cannot be met together with {what} at {', '.join(bands)} "
                               "(no complex S(jω) lies in both disks)")
    for z, m in zip(zeros, means):
        if m < 0:
            reasons.append(f"P_Ω,β has a right-half-plane zero at {_fmt(z)} 1/s, which pins T_Ω,w(z) to the open loop's "
                           f"(S(z) = 1, for any controller acting through the pitch); the specifications allow a Poisson "
                           f"mean of ln|S| of at most {m:.3g} < 0 there: relax the speed or the tower specification near "
                           f"{abs(z.imag):.3g} rad/s")
    return PitchFeasibility(feasible=not reasons, omega=w, pointwise=ok, binding=tuple(binding.tolist()),
                            zeros=np.asarray(zeros), poisson_mean=np.asarray(means, float), reasons=tuple(reasons),
                            max_sensitivity=ms)


def _magnitude(spec_like, omega, name):
    """|W(jω)| on ``omega`` from a Specification, an LTI, a callable or None (no constraint)."""
    if spec_like is None:
        return np.full(omega.shape, np.inf)
    if hasattr(spec_like, "response"):
        out = np.abs(np.asarray(spec_like.response(omega)))
    elif callable(spec_like) and not hasattr(spec_like, "ninputs"):
        raw = np.asarray(spec_like(omega))
        if not np.iscomplexobj(raw) and np.any(~(raw > 0)):  # a real value is a magnitude: never silently |·|
            raise ValueError(f"{name} returned values ≤ 0 or NaN; give |W(jω)| > 0 (linear, not dB) or W(jω) complex")
        out = np.abs(raw)
    else:
        out = np.abs(siso_response(spec_like, omega, name))
    out = np.broadcast_to(np.asarray(out, float), omega.shape)
    if np.any(~(out > 0)):
        raise ValueError(f"{name} must be > 0 at every frequency (a magnitude, np.inf for no constraint)")
    return out


@on_one_blas_thread
def pitch_frontier(model, wind_speed, speed_relax_db=(0.5, 1.5, 3.0, 4.5, 6.0, 8.0), *, max_sensitivity=MAX_SENSITIVITY,
                   max_pitch_rate_ratio=1.0, m=TOWER_M, omega=None, max_hf_gain_ratio=MAX_HF_GAIN_RATIO) -> dict:
    """The largest tower-base DEL reduction a pitch controller can promise, per speed relaxation.

    For each relaxation g (dB) of the generator-speed specification W_Ω = 10^(g/20)·|T^ROSCO_{Ω,w}|:

    - ``achievable``: the exact (Dirlik, 1 Hz) DEL reduction of the design of
      :func:`achievable_pitch`, a stabilising controller that meets W_Ω, M_s and the
      pitch-rate allowance on the grid (NaN where the solver finds none: at 0 dB only ROSCO's
      own integral action meets W_Ω at the lowest frequencies);
    - ``bound``: an upper bound no controller beats, from the pointwise smallest
      |T_{MyT,w}(jω)| = |P_{MyT,w} − K∞|·max(0, |c| − min(r_Ω, M_s)) (module docstring).

    Parameters
    ----------
    model : specdesign.turbine.TurbineModel
        The turbine.
    wind_speed : float
        Operating point, m/s.
    speed_relax_db : sequence of float
        Relaxations of the generator-speed specification, dB (≥ 0).
    max_sensitivity : float
        M_s (-).
    max_pitch_rate_ratio : float
        Allowed pitch-rate SD relative to ROSCO's (-), see :func:`achievable_pitch`.
    m : float
        Wöhler exponent of the tower-base S-N curve (-).
    omega : array_like, optional
        Frequency grid, rad/s (default :func:`specdesign.spec.default_omega`).
    max_hf_gain_ratio : float or None
        κ of the high-frequency gain bound on the designs (see :func:`achievable_pitch`;
        default :data:`~specdesign.feasibility.MAX_HF_GAIN_RATIO`, on; None: off; :data:`~specdesign.feasibility.HF_GAIN_RATIO` is the measured κ). The pointwise
        ``bound`` ignores it (it stays an upper bound).

    Returns
    -------
    dict
        ``speed_relax_db`` (dB), ``achievable`` and ``bound`` (DEL reductions, %), arrays
        with one value per relaxation, and ``designs`` (the :class:`AchievablePitch` records,
        None where none was found).

    Examples
    --------
    >>> from specdesign.turbine import iea15mw
    >>> f = pitch_frontier(iea15mw(), 19.0, (1.5, 6.0))
    >>> bool(f["achievable"][1] >= f["achievable"][0] and (f["bound"] >= f["achievable"]).all())
    True
    """
    from .. import spec

    g = np.atleast_1d(np.asarray(speed_relax_db, float))
    if g.ndim != 1 or g.size == 0 or not np.all(np.isfinite(g)) or np.any(g < 0):
        raise ValueError(f"speed_relax_db={speed_relax_db!r} must be relaxations ≥ 0 dB")
    ms = positive_scalar(max_sensitivity, "max_sensitivity")
    base = spec.baseline_analysis(model, wind_speed, m=m, omega=omega)
    w = base.omega
    plant = model.linearize(float(wind_speed))
    speed0 = np.abs(spec.speed_specification(model, float(wind_speed)).response(w))
    bound, designs = [], []
    youla = YoulaProblem(model, wind_speed, max_sensitivity=ms, max_pitch_rate_ratio=max_pitch_rate_ratio, base=base,
                         max_hf_gain_ratio=max_hf_gain_ratio)
    for gi in g:
        d = sensitivity_disks(plant, w, np.full(w.shape, np.inf), speed0 * 10 ** (gi / 20), ms)
        r = np.minimum(d["r_speed"], d["r_margin"])
        t_min = np.abs(d["open_loop"]) * np.maximum(0.0, np.abs(d["c"]) - r)
        d_min = spectral.damage_rate(w, t_min ** 2 * base.wind_psd, base.m, method=base.method)
        bound.append(float(spectral.del_reduction(100.0 * (1.0 - d_min / base.damage_rate), base.m)) if d_min > 0 else 100.0)
        try:
            designs.append(youla.solve(gi))
        except RuntimeError:
            designs.append(None)
    achievable = np.array([np.nan if x is None else x.del_reduction for x in designs])
    return {"speed_relax_db": g, "achievable": achievable, "bound": np.asarray(bound), "designs": tuple(designs)}
