"""Can a specification pair be met by pitch control at all? Checked before any loop shaping.

With the collective pitch as the only actuator, every closed-loop wind map of *any* linear
controller (on the generator speed, with an active tower damping loop, of any order) is
T_{y,w} = P_{y,w} + P_{y,β}·T_{β,w}: one complex number per frequency is free. Written with
S = T_{Ω,w}/P_{Ω,w} (the sensitivity 1/(1 + C·P_{Ω,β}) of a controller C on Ω_g alone):

    T_{Ω,w}   = P_{Ω,w}·S
    T_{MyT,w} = K∞ + (P_{MyT,w} − K∞)·S,     K∞ = P_{MyT,w} − P_{MyT,β}·P_{Ω,w}/P_{Ω,β}

(K∞ is T_{MyT,w} for C → ∞, S = 1 the open loop). So each specification is a disk for S:

    speed   |T_{Ω,w}| ≤ |W_Ω|      ⇔  |S| ≤ r_Ω = |W_Ω|/|P_{Ω,w}|
    margin  |S| ≤ M_s               (the pitch loop's robustness; None: not imposed)
    tower   |T_{MyT,w}| ≤ |W_MyT|  ⇔  |S − c| ≤ ρ,  c = −K∞/(P_{MyT,w} − K∞),  ρ = |W_MyT|/|P_{MyT,w} − K∞|

Two necessary conditions follow, for every plant case:

1. **Pointwise**: at each ω the disks intersect, |c| − ρ ≤ min(r_Ω, M_s). Where they do
   not, no controller acting through the pitch meets the specifications at that frequency,
   whatever its measurements; the check says which specification binds against the tower's.
2. **Interpolation** (the right-half-plane zeros z of P_{Ω,β}; the IEA 15 MW has a lightly
   damped pair at the tower mode): T_{Ω,w}(z) = P_{Ω,w}(z), i.e. S(z) = 1, for every
   controller, and for a stable plant the Poisson integral gives
   (1/π)∫ ln|S(jω)|·Re z/((Re z)² + (ω − Im z)²) dω ≥ ln|S(z)| = 0 over ω ∈ ℝ. With
   |S| ≤ s_max(ω) = min(r_Ω, M_s, |c| + ρ) pointwise, the same mean of ln s_max must be
   ≥ 0: the specifications may not ask for |S| < 1 around Im z.

Both are necessary, not sufficient: a design can still fail on causality elsewhere (Bode's
integral spreads the cost over a band), on robustness between plant cases, or on the
structure it is given (design_qft's sixth-order pitch controller and first-order ATD).

What *can* be promised is found by design, not by check: :func:`achievable_pitch` optimises
over every stabilising pitch controller at once (the Youla parametrisation of the stable
plant, C = Y/(1 − P_{Ω,β}Y) with Y stable, in which every closed-loop map is affine in Y) the
tower-base damage predicted by the paper's Eq. (10), subject to the generator-speed
specification and |S| ≤ M_s on the grid: a convex problem (cvxpy). Its |T_{MyT,w}| is a
specification that is feasible by construction, with the exact (Dirlik) promise.
:func:`pitch_frontier` tabulates, per speed relaxation, that achievable promise beside the
pointwise upper bound of condition 1 (the smallest |T_{MyT,w}| inside the speed and margin
disks at every frequency): the true frontier lies between the two.
:func:`specification_for_target` inverts the frontier: the smallest speed relaxation whose
design promises a requested DEL reduction, and the specification pair it certifies.

Units: ω in rad/s, magnitudes linear (dB only in messages), DEL reductions in %.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._checks import as_omega, positive_scalar

__all__ = ["PitchFeasibility", "pitch_feasibility", "PitchChecker", "pitch_checkers", "combine", "AchievablePitch",
           "achievable_pitch", "pitch_frontier", "TargetSpecification", "specification_for_target", "sensitivity_disks"]


def sensitivity_disks(plant, omega, w_tower, w_speed, max_sensitivity=2.0):
    """The disks of the complex sensitivity S(jω) that each specification allows.

    Parameters
    ----------
    plant : control.LTI
        Named plant (inputs ``wind``, ``pitch_cmd``; outputs ``gen_speed``, ``tower_base_my``).
    omega : array_like
        Frequencies, rad/s.
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
    from .closedloop import frequency_response

    w = as_omega(omega, "omega")
    ms = np.inf if max_sensitivity is None else positive_scalar(max_sensitivity, "max_sensitivity")
    a = frequency_response(plant, w, "tower_base_my", "wind")
    yb = frequency_response(plant, w, "tower_base_my", "pitch_cmd")
    ow = frequency_response(plant, w, "gen_speed", "wind")
    ob = frequency_response(plant, w, "gen_speed", "pitch_cmd")
    k_inf = a - yb * ow / ob
    g = a - k_inf  # = P_{MyT,β}·P_{Ω,w}/P_{Ω,β}
    return dict(c=-k_inf / g, rho=np.asarray(w_tower, float) / np.abs(g), r_speed=np.asarray(w_speed, float) / np.abs(ow),
                r_margin=np.full(w.shape, ms), open_loop=g, k_inf=k_inf)


def _rhp_zeros(plant):
    import control

    sub = control.ss(plant)["gen_speed", "pitch_cmd"]
    z = np.asarray(control.tf(sub).zeros(), complex)
    # the numerator of a channel carries spurious huge roots (leading coefficients ~ 0)
    return z[(z.real > 0) & (np.abs(z) < 1e6)]


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
    from .spectral import trapezoid_weights

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


def pitch_feasibility(model, wind_speed, tower_spec, speed_spec, *, max_sensitivity=2.0, omega=None,
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
        Frequencies, rad/s (default :func:`specdesign.spec.default_omega`, refined around
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


def pitch_checkers(model, wind_speed, speed_spec, *, max_sensitivity=2.0, omega=None, cases=None) -> list:
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
        Grid, rad/s (default :func:`specdesign.spec.default_omega` refined around the
        right-half-plane zeros of the nominal P_{Ω,β}).
    cases : sequence of float, optional
        Wind speeds (m/s) of the plant cases; default only ``wind_speed``.

    Returns
    -------
    list of PitchChecker
        Nominal case first when ``cases`` is None, else in the order given.
    """
    from . import spec
    from .closedloop import refine_grid, t_tower_wind
    from .rosco import rosco_baseline

    v = float(wind_speed)
    ms = np.inf if max_sensitivity is None else positive_scalar(max_sensitivity, "max_sensitivity")
    speeds = [v] if cases is None else [float(c) for c in cases]
    plants = [model.linearize(x) for x in speeds]
    w = spec.default_omega() if omega is None else as_omega(omega, "omega")
    zeros0 = _rhp_zeros(plants[0])
    if omega is None and zeros0.size:
        w = refine_grid(w, zeros0, rel_width=0.2, rel_step=2e-4)
    ws = _magnitude(speed_spec, w, "speed_spec")
    t_rosco = np.abs(t_tower_wind(model.linearize(v), rosco_baseline(model, v), w))
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
        from .closedloop import siso_response

        out = np.abs(siso_response(spec_like, omega, name))
    out = np.broadcast_to(np.asarray(out, float), omega.shape)
    if np.any(~(out > 0)):
        raise ValueError(f"{name} must be > 0 at every frequency (a magnitude, np.inf for no constraint)")
    return out


def pitch_frontier(model, wind_speed, speed_relax_db=(0.5, 1.5, 3.0, 4.5, 6.0, 8.0), *, max_sensitivity=2.0,
                   max_pitch_rate_ratio=1.0, m=4.0, omega=None) -> dict:
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
    from . import spec, spectral

    g = np.atleast_1d(np.asarray(speed_relax_db, float))
    if g.ndim != 1 or g.size == 0 or not np.all(np.isfinite(g)) or np.any(g < 0):
        raise ValueError(f"speed_relax_db={speed_relax_db!r} must be relaxations ≥ 0 dB")
    ms = positive_scalar(max_sensitivity, "max_sensitivity")
    base = spec.baseline_analysis(model, wind_speed, m=m, omega=omega)
    w = base.omega
    plant = model.linearize(float(wind_speed))
    speed0 = np.abs(spec.speed_specification(model, float(wind_speed)).response(w))
    bound, designs = [], []
    for gi in g:
        d = sensitivity_disks(plant, w, np.full(w.shape, np.inf), speed0 * 10 ** (gi / 20), ms)
        r = np.minimum(d["r_speed"], d["r_margin"])
        t_min = np.abs(d["open_loop"]) * np.maximum(0.0, np.abs(d["c"]) - r)
        d_min = spectral.damage_rate(w, t_min ** 2 * base.wind_psd, base.m, method=base.method)
        bound.append(float(spectral.del_reduction(100.0 * (1.0 - d_min / base.damage_rate), base.m)) if d_min > 0 else 100.0)
        try:
            designs.append(achievable_pitch(model, wind_speed, gi, max_sensitivity=ms,
                                            max_pitch_rate_ratio=max_pitch_rate_ratio, base=base))
        except RuntimeError:
            designs.append(None)
    achievable = np.array([np.nan if x is None else x.del_reduction for x in designs])
    return {"speed_relax_db": g, "achievable": achievable, "bound": np.asarray(bound), "designs": tuple(designs)}


#: Poles (rad/s) of the Youla basis: real poles spanning the wind band, and lightly damped pairs
#: (ζ = 0.2) around the tower mode, where the specification is shaped.
YOULA_REAL_POLES = np.geomspace(0.03, 10.0, 6)
YOULA_PAIRS = (0.9, 1.02, 1.1, 1.25)


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


def achievable_pitch(model, wind_speed, speed_relax_db=0.0, *, max_sensitivity=2.0, max_pitch_rate_ratio=1.0,
                     m=4.0, omega=None, base=None) -> AchievablePitch:
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
        (a quadratic constraint; 1.0: no more pitch activity than ROSCO).
    m : float
        Wöhler exponent (-).
    omega : array_like, optional
        Grid, rad/s (default :func:`specdesign.spec.default_omega`).
    base : specdesign.spec.Baseline, optional
        ROSCO's baseline at ``wind_speed`` if already computed (its grid is used).

    Returns
    -------
    AchievablePitch
        The design, its maps and its exact promise.

    Raises
    ------
    RuntimeError
        If the solver finds no solution.
    """
    import cvxpy as cp

    from . import spec, spectral
    from .closedloop import frequency_response, siso_response
    from .rosco import rosco_baseline

    g = float(speed_relax_db)
    kappa = positive_scalar(max_pitch_rate_ratio, "max_pitch_rate_ratio")
    if not (np.isfinite(g) and g >= 0):
        raise ValueError(f"speed_relax_db={speed_relax_db!r} must be a relaxation ≥ 0 dB")
    ms = positive_scalar(max_sensitivity, "max_sensitivity")
    if base is None:
        base = spec.baseline_analysis(model, wind_speed, m=m, omega=omega)
    w = base.omega
    plant = model.linearize(float(wind_speed))
    a = frequency_response(plant, w, "tower_base_my", "wind")
    ow = frequency_response(plant, w, "gen_speed", "wind")
    ob = frequency_response(plant, w, "gen_speed", "pitch_cmd")
    gy = frequency_response(plant, w, "tower_base_my", "pitch_cmd") * ow
    w_speed = np.abs(spec.speed_specification(model, float(wind_speed)).response(w)) * 10 ** (g / 20)
    phi = _youla_basis(1j * w)
    t_ref2 = np.abs(base.t_response) ** 2
    weight = np.maximum(base.sensitivity, 0.0) + 1e-3 * base.sensitivity.max()

    # solve in orthonormal coordinates of the basis on the grid (the raw basis is collinear)
    q, rr = np.linalg.qr(np.vstack([phi.real, phi.imag]))
    phi_o = q[: w.size] + 1j * q[w.size:]
    y = cp.Variable(phi.shape[1])
    tc, tl = a, -gy[:, None] * phi_o
    sc, sl = np.ones_like(ob), -ob[:, None] * phi_o
    t_re = tc.real + tl.real @ y
    t_im = tc.imag + tl.imag @ y
    s_re = sc.real + sl.real @ y
    s_im = sc.imag + sl.imag @ y
    scale = np.sqrt(weight / t_ref2)
    objective = cp.sum_squares(cp.multiply(scale, t_re)) + cp.sum_squares(cp.multiply(scale, t_im))
    s_bound = np.minimum(ms, w_speed / np.abs(ow))  # |S| ≤ M_s and |P_{Ω,w}S| ≤ W_Ω
    constraints = [cp.norm(cp.vstack([s_re, s_im]), 2, axis=0) <= s_bound]
    # pitch-rate activity: the rate spectrum |ω·T_{β,w}|²S_W, T_{β,w} = −P_{Ω,w}Y, integrated
    # (trapezoid weights), at most κ² times ROSCO's
    from .spectral import trapezoid_weights

    tw = trapezoid_weights(w)
    c_ref = siso_response(rosco_baseline(model, float(wind_speed)), w)
    rate_ref = float(np.sum(tw * np.abs(w * c_ref * ow / (1 + c_ref * ob)) ** 2 * base.wind_psd))
    rl = (w * ow)[:, None] * phi_o * np.sqrt(tw * base.wind_psd / rate_ref)[:, None]  # scaled to ROSCO's: O(1)
    constraints.append(cp.sum_squares(rl.real @ y) + cp.sum_squares(rl.imag @ y) <= kappa ** 2)
    prob = cp.Problem(cp.Minimize(objective), constraints)
    prob.solve()
    if y.value is None or prob.status not in ("optimal", "optimal_inaccurate"):
        raise RuntimeError(f"achievable_pitch at {wind_speed:g} m/s: the solver returned {prob.status!r}")
    yv = phi_o @ np.asarray(y.value, float)
    coef = np.linalg.solve(rr, np.asarray(y.value, float))
    sens = 1 - ob * yv
    t_tower = a - gy * yv
    t_speed = ow * sens
    d = spectral.damage_rate(w, np.abs(t_tower) ** 2 * base.wind_psd, base.m, method=base.method)
    red = float(spectral.del_reduction(100.0 * (1.0 - d / base.damage_rate), base.m))
    excess = float(20 * np.log10(np.max(np.abs(t_speed) / w_speed)))
    return AchievablePitch(float(wind_speed), g, ms, w, coef, t_tower, t_speed, sens, red, excess, str(prob.status))


@dataclass(frozen=True)
class TargetSpecification:
    """A specification pair that promises a DEL reduction and is feasible by construction.

    Parameters
    ----------
    tower : specdesign.spec.Specification
        W_MyT: the certifying design's T_{MyT,w} times ``slack_db`` (a transfer function of
        the order of the design).
    speed : specdesign.spec.Specification
        W_Ω: ROSCO's T_{Ω,w} relaxed by ``speed_relax_db``.
    promise : specdesign.spec.Promise
        The tower specification's promise against ROSCO (exact Dirlik and Eq. (10)).
    speed_relax_db : float
        The smallest relaxation (dB, to the bisection's tolerance) whose design reaches the target.
    slack_db : float
        How far above the certifying design the tower specification lies, dB.
    design : AchievablePitch
        The certificate: a stabilising pitch controller that meets both specifications.
    target_reduction : float
        The DEL reduction asked for, %.
    """

    tower: object
    speed: object
    promise: object
    speed_relax_db: float
    slack_db: float
    design: AchievablePitch
    target_reduction: float


def specification_for_target(model, wind_speed, target_reduction=25.0, *, slack_db=0.5, speed_relax_db=None,
                             max_sensitivity=2.0, max_pitch_rate_ratio=1.0, max_relax_db=12.0, tolerance_db=0.05,
                             m=4.0, omega=None) -> TargetSpecification:
    """The feasible specification pair that promises ``target_reduction`` with the least speed relaxation.

    Bisection on the relaxation g of ROSCO's generator-speed map: the smallest g whose
    :func:`achievable_pitch` design, with its tower map raised by ``slack_db`` (room for a
    designer's own controller), still promises ``target_reduction`` % DEL (exact Dirlik, 1 Hz).
    Or, with ``speed_relax_db`` given, the other way round: the design at that relaxation and
    the largest slack that still promises the target (the most room for a low-order design).
    The pair returned is met by that design, so it is feasible, and its promise is the
    promise of the specification handed to the design step.

    Parameters
    ----------
    model : specdesign.turbine.TurbineModel
        The turbine.
    wind_speed : float
        Operating point, m/s.
    target_reduction : float
        Tower-base DEL reduction the specification must promise, % (0-100).
    slack_db : float
        W_MyT lies this far above the certifying design's |T_{MyT,w}|, dB (≥ 0); ignored with
        ``speed_relax_db``.
    speed_relax_db : float, optional
        A fixed relaxation of the speed map, dB: the slack is then the largest that keeps
        the promise ≥ ``target_reduction`` (bisection to ``tolerance_db``).
    max_sensitivity : float
        M_s (-).
    max_pitch_rate_ratio : float
        Pitch-rate SD allowance relative to ROSCO's (-).
    max_relax_db : float
        Largest speed relaxation tried, dB.
    tolerance_db : float
        Bisection tolerance on the relaxation, dB.
    m : float
        Wöhler exponent (-).
    omega : array_like, optional
        Grid, rad/s (default :func:`specdesign.spec.default_omega`).

    Returns
    -------
    TargetSpecification
        The pair, its promise and its certificate.

    Raises
    ------
    ValueError
        For a target outside (0, 100) or a negative slack, or when even ``max_relax_db`` does
        not reach the target (the message gives the promise reached there).

    Examples
    --------
    >>> from specdesign.turbine import iea15mw
    >>> t = specification_for_target(iea15mw(), 19.0, 25.0)
    >>> bool(t.promise.exact_del >= 25.0 and t.speed_relax_db < 1.0)
    True
    """
    from . import spec

    t = float(target_reduction)
    if not 0 < t < 100:
        raise ValueError(f"target_reduction={target_reduction!r} must be a DEL reduction in % strictly between 0 and 100")
    slack = float(slack_db)
    if not (np.isfinite(slack) and slack >= 0):
        raise ValueError(f"slack_db={slack_db!r} must be a finite margin ≥ 0 dB")
    base = spec.baseline_analysis(model, wind_speed, m=m, omega=omega)

    def reached(g):
        try:
            d = achievable_pitch(model, wind_speed, g, max_sensitivity=max_sensitivity,
                                 max_pitch_rate_ratio=max_pitch_rate_ratio, base=base)
        except RuntimeError:
            return None, -np.inf
        return d, _slack_promise(d, base, slack)

    if speed_relax_db is not None:
        g = float(speed_relax_db)
        design, _ = reached(g)
        if design is None:
            raise ValueError(f"no pitch design meets the speed map relaxed by {g:g} dB at {float(wind_speed):g} m/s")

        def promise_with(sl):
            return _slack_promise(design, base, sl)

        if promise_with(0.0) < t:
            raise ValueError(f"no pitch specification promises {t:g} % at {float(wind_speed):g} m/s with the speed map "
                             f"relaxed by {g:g} dB (best {promise_with(0.0):.1f} % with no slack); relax it more")
        lo, hi = 0.0, 40.0
        while hi - lo > tolerance_db:
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if promise_with(mid) >= t else (lo, mid)
        return _target_result(model, wind_speed, design, base, lo, g, t)
    hi_design, hi_red = reached(float(max_relax_db))
    if hi_red < t:
        raise ValueError(f"no pitch specification promises {t:g} % at {float(wind_speed):g} m/s with the speed map "
                         f"relaxed up to {max_relax_db:g} dB (best {hi_red:.1f} % with {slack:g} dB slack); lower the "
                         "target or the slack, or allow more pitch activity")
    lo, hi = 0.0, float(max_relax_db)
    best = hi_design
    while hi - lo > tolerance_db:
        mid = 0.5 * (lo + hi)
        d, red = reached(mid)
        if red >= t:
            hi, best = mid, d
        else:
            lo = mid
    return _target_result(model, wind_speed, best, base, slack, hi, t)


def _slack_promise(design, base, slack_db):
    """Exact DEL promise (%) of a design's |T_{MyT,w}| raised by ``slack_db`` (the shaping |W|/|T^ROSCO|)."""
    from . import spec

    return spec.promise_of(10 ** (slack_db / 20) * np.abs(design.t_tower) / np.abs(base.t_response), base).exact_del


def _target_result(model, wind_speed, design, base, slack, g, target):
    import control

    from . import spec
    from .closedloop import closed_loop

    plant = model.linearize(float(wind_speed))
    # kept as a state space: the polynomial coefficients of a ~25th-order map carry no digits
    t_sys = control.minreal(closed_loop(plant, design.controller(model), warn=False)["tower_base_my", "wind"],
                            verbose=False)
    tower = spec.Specification(t_sys, (spec.Gain(slack),), name="W_tower_base_my")
    speed = spec.speed_specification(model, float(wind_speed), margin_db=g)
    return TargetSpecification(tower, speed, spec.promise_of(tower, base), g, slack, design, target)
