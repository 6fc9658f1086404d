"""A certified specification for a DEL target written in shaping elements (see :mod:`specdesign.feasibility`).

:func:`specification_for_target` certifies W_MyT = |T^cert_{MyT,w}|·slack: the certifying
design's own map, a transfer function of its order that a designer cannot read or edit by
element. :func:`element_specification` writes a certified tower specification as ROSCO's map
times a few shaping elements of :mod:`specdesign.spec` (a gain, a lag, a lead, notches; a
notch with a negative depth is a bump), chosen over the whole band, in two steps:

1. **Follow.** r(ω) is the upper envelope (running maximum over ±``envelope`` in ln ω) of
   20·log10(|W^cert|/|T^ROSCO_{MyT,w}|), W^cert a certificate made for the target plus a
   little headroom (:data:`FOLLOW`). The elements e(ω) = 20·log10 |Π elements(jω)| follow it
   in weighted least squares (dB), weighted by ΔD% (plus 5 % of its peak) per unit of ln ω,
   a shortfall below r weighing :data:`BELOW_WEIGHT` times an excess:

       minimise over gain, lag, lead, notches   Σ_k u_k·(e_k − r_k)²·(BELOW_WEIGHT if e_k < r_k else 1)

   (smooth: L-BFGS-B with the analytic Jacobian of e converges to its tolerance). Notches are
   seeded where the certificate rises (bumps it must follow) and where ΔD%·room peaks, and
   added one at a time, each fit warm-started from the last, until the elements themselves
   promise the target (or one more notch adds less than :data:`FOLLOW_GAIN_DB` of room). The
   gain is then shifted uniformly until the exact Dirlik promise on :data:`FIT_OMEGA` is the
   target plus :data:`PROMISE_MARGIN_PP` (a monotone root).
2. **Certify.** :meth:`CertificateSearch.for_tower` makes the Youla design meet these elements
   (|T_MyT| ≤ |W_MyT| on its grid, a convex constraint) at the least speed relaxation of a
   ladder, closes it around every plant case and checks the pair on the dense grid; where a
   case exceeds W_MyT the nominal design keeps farther below it there and is made again.

So the specification is feasible by construction (its certificate meets it at every plant
case), its promise is that of the specification handed to the design, and it is editable
(``tower.add(...)``, then :func:`recertify`). Each step is a continuous function of the input (a
convex design, a fit on inputs rounded to :data:`FIT_INPUT_DB`, which a non-convex fit needs to
return the same elements, a monotone root), so a rounding error in the operating point moves the
result by a rounding error. When no (headroom, envelope) of :data:`FOLLOW`
certifies, the elements are instead fitted *above* the envelope of certificates made for
larger targets (:data:`HEADROOM_PP`), each then feasible through that certificate: maximise
promise(s + g) − :data:`REGULARISATION`·mean(e²) with g the log-sum-exp of r − s at
:data:`SMOOTHING_DB` (the least gain above r for a shape s), then settle the gain as above.
This fallback is slower (a chain of non-convex fits per headroom) and its elements follow a
certificate for a larger target, so it needs a more relaxed speed map.
:func:`specdesign.feasibility.shape_whole_band` is the user's entry point.

Units: ω in rad/s, magnitudes in dB here, promises in % DEL.
"""
from __future__ import annotations

import inspect
from dataclasses import replace

import numpy as np

from .. import spectral
from .._blas import on_one_blas_thread
from .._checks import del_target, margin_db, search_options
from ..closedloop import (
    UNSTABLE_CONTROLLER_RATE,
    lightly_damped,
    refine_grid,
    siso_response,
    system_roots,
)
from ..fatigue import TOWER_M
from .target import (
    DENSE_POINTS_PER_WIDTH,
    MAX_RELAX_DB,
    SLACK_DB,
    SPEED_SLACK_DB,
    TARGET_REDUCTION,
    TOLERANCE_DB,
    CertificateSearch,
    recertify,
)

__all__ = ["BELOW_WEIGHT", "ENVELOPES", "ENVELOPE_LOSS_PP", "FIT_INPUT_DB", "FIT_OMEGA", "FIT_SENS_REL", "FOLLOW",
           "FOLLOW_GAIN_DB", "HEADROOM_PP", "MAX_ITERATIONS", "MAX_NOTCHES", "PROMISE_MARGIN_PP", "REGULARISATION", "SMOOTHING_DB",
           "element_specification"]

#: The fallback's extra DEL reductions (percentage points) asked of the certificate, tried in
#: turn: the elements lie above its map, so they promise less than it does.
HEADROOM_PP = (3.0, 5.0, 7.0, 9.0, 11.0, 13.0, 15.0)
#: Most notches (reductions or bumps) placed besides the gain, the lag and the lead.
MAX_NOTCHES = 6
#: The specification promises this much (percentage points) above the target: room for the
#: promise recomputed on another grid (the issue's independent check is within 0.5 pp).
PROMISE_MARGIN_PP = 0.1
#: Least loss (percentage points) of following the envelope with a few elements: an envelope
#: that promises less than the target plus this is not fitted (1.7-3.8 pp lost at 19 and 25 m/s on
#: the IEA 15 MW; fitting 0-6 notches costs 1-3 s, a new certificate 1.3-3.5 s, so a close
#: envelope is tried).
ENVELOPE_LOSS_PP = 1.0
#: Grid of the fit and of the promise (rad/s; the same density per decade as the default design
#: grid): wider than the design grid's 0.01-10 rad/s, as the elements are free outside it, and a
#: lead that rises above 10 rad/s (Bode's cost pushed out of the band the promise sees) gave
#: away 0.6 pp of promise on the issue's 0.005-20 rad/s check at 19 m/s.
FIT_OMEGA = np.geomspace(0.005, 20.0, 480)
#: Half-widths (in ln ω) of the running maximum taken of the certificate's ratio, tried in turn
#: for each headroom: the elements follow its upper envelope, not the narrow pole-zero pattern
#: at the tower mode. At 25 m/s on the IEA 15 MW the ±3 % envelope fills the certificate's dips
#: beside the tower mode and gives away 7 pp of promise, the ±1 % one about 1 pp.
ENVELOPES = (0.03, 0.01)


#: Temperatures (dB) of the smooth maximum that sets the gain during the fit, in turn (each stage
#: warm-started from the last): 0.1 dB smooths the contacts with the certificate's narrow
#: features; the last lies above the exact maximum by at most 0.02·ln(n_grid) dB, and the result
#: is built with the exact maximum.
SMOOTHING_DB = (0.1, 0.02)
#: Weight of the least change from ROSCO in the fit (percentage points of promise per dB² of the
#: log-frequency mean of e²): it only settles what the promise leaves free (where ΔD% is nil).
REGULARISATION = 1e-3
#: Most L-BFGS-B iterations per smoothing stage, a guard: a stage stops on its projected gradient
#: (1e-4 % of promise per unit of parameter) or on a relative change of its cost below 1e-10.
MAX_ITERATIONS = 2000
#: (extra DEL reduction asked of the certificate, pp; half-width in ln ω of the upper envelope of
#: its ratio to ROSCO's map) of the certificates the elements follow, tried in turn: a plant
#: case's tower resonance lies a few per cent from the nominal one, so elements that dip into
#: the certificate's narrow dips would ask the cases for what they cannot give, and at some
#: speeds (23 m/s on the IEA 15 MW) a case still exceeds the first pair by 20-30 dB at its own
#: resonance, where another certificate's envelope passes.
FOLLOW = ((1.0, 0.03), (3.0, 0.01), (5.0, 0.03), (3.0, 0.06))
#: Weight of a shortfall of the elements below the certificate's map relative to an excess.
BELOW_WEIGHT = 10.0
#: Band of the notch centres, rad/s: where the tower load's fatigue lives (ΔD% of the IEA 15 MW
#: is negligible above a few rad/s). A centre at the edge of the fit's grid (10 rad/s) is a flat
#: direction of the fit, changing the promise by nothing, and under a 1e-9 m/s change of the
#: wind speed the fit landed there or not, moving the design's prediction by 0.7 pp at 25 m/s.
NOTCH_BAND = (0.01, 5.0)
#: Least improvement (dB of room) for which one more notch is kept.
FOLLOW_GAIN_DB = 0.05
#: L-BFGS-B's stopping tolerances in the promise fit (:func:`_fit`): projected gradient (% of
#: promise per unit of parameter) and relative change of the cost; tight enough that the fit
#: runs to convergence (a continuous function of its input), not to :data:`MAX_ITERATIONS`.
FIT_GTOL, FIT_FTOL = 1e-4, 1e-10
#: The same for the least-squares fit that follows the envelope (:func:`_follow`: a cost in dB²
#: with weights summing to 1), also run to convergence.
FOLLOW_GTOL, FOLLOW_FTOL = 1e-8, 1e-12
#: L-BFGS-B's memory in both fits (corrections kept; scipy's default is 10): each notch's centre,
#: depth and damping act together on e(ω), and a longer memory models that coupling.
LBFGS_MEMORY = 30
#: Largest uniform gain shift searched, dB: no promise changes beyond ±80 dB of gain (the
#: bracket search of :func:`_shift_to` and :func:`_settle` stops there).
SHIFT_CAP_DB = 80.0
#: Absolute (dB) and relative tolerances of the gain root (brentq): far below any promise's
#: resolution, so the settled gain is the root to rounding.
ROOT_XTOL_DB, ROOT_RTOL = 1e-12, 1e-14
#: Corners of the starting lag and lead, rad/s: the lag returns the DC level to 0 dB by 0.05 rad/s,
#: below the tower mode's band, and the lead lifts above 1.5 rad/s, above the IEA 15 MW's tower mode
#: (1.06 rad/s); the notches are seeded between them.
LAG_OMEGA, LEAD_OMEGA = 0.05, 1.5
#: Room (dB) the starting lag and lead leave above the certificate's ratio.
START_MARGIN_DB = 0.5
#: Bounds of the gain, dB, and of a notch's depth, dB (negative: a bump), in the fits.
GAIN_BOUNDS_DB, NOTCH_DEPTH_BOUNDS_DB = (-20.0, 20.0), (-20.0, 40.0)
#: Bounds of a notch's pole damping ratio (-) in the fits, and its start for a notch and for a bump.
NOTCH_ZETA_BOUNDS, NOTCH_ZETA_START, BUMP_ZETA_START = (0.01, 1.5), 0.3, 0.05
#: Floor of the fit's ΔD% weight, as a fraction of its peak: where ΔD% is nil the elements still
#: follow the certificate a little (5 %).
WEIGHT_FLOOR = 0.05
#: Points of the dense check of the elements against the certificate (:func:`_dense_ratio`),
#: before its refinement around the lightly damped roots.
DENSE_POINTS = 2000
#: Notch seeds (:func:`_seeds`): a rise of the certificate's ratio is r above SEED_ABOVE_DB, or
#: SEED_RISE_DB above its minimum over a window SEED_WINDOW wide in ln ω (±5 %: the narrow bump
#: between two dips beside the tower mode); bumps are ranked by rise·(ΔD% + SEED_SENS_FLOOR·peak),
#: so one where ΔD% is nil still ranks; two seeds lie at least SEED_SPACING apart in ln ω (2 %).
SEED_ABOVE_DB, SEED_RISE_DB, SEED_WINDOW, SEED_SENS_FLOOR, SEED_SPACING = 0.1, 3.0, 0.1, 1e-3, 0.02
#: A bump is seeded this far (dB) above the ratio it follows, and every seed's depth is clipped to
#: SEED_DEPTH_DB (negative: a bump), inside the fits' :data:`NOTCH_DEPTH_BOUNDS_DB`.
SEED_BUMP_LIFT_DB, SEED_DEPTH_DB = 0.3, (-15.0, 30.0)
#: Quanta of the envelope fit's inputs (:func:`_followed`): the envelope r rounded to
#: FIT_INPUT_DB dB, ΔD% (its weight and the notch seeds) divided by its peak and rounded to
#: FIT_SENS_REL (a 1e-9 m/s step moves it by ~3e-12 of its peak). The fit is
#: non-convex and its parameters degenerate (the lag's and the lead's zeros coincide at its
#: minima: Gauss-Newton Hessians of condition 1e16-1e18), so L-BFGS-B stops where its cost is
#: flat to rounding, 1e-6-3e-5 from where a 1e-8 dB change of r stops it, and the next notch's
#: fit, warm-started there, fell into another local minimum: at 25 m/s on the IEA 15 MW under the
#: default high-frequency gain bound, 25 and 25 − 1e-9 m/s (r 1.8e-8 dB apart) gave 5 and 4
#: notches and predictions 0.49 pp apart. On rounded inputs the fit is the same computation, so a
#: rounding error of the operating point changes the elements only when it carries one of the
#: 480 values across a rounding boundary (for a 1e-9 m/s step, r moves ≤ 2e-8 dB: at most
#: 480·2e-8/0.01 ≈ 1e-3 of such steps); 0.01 dB is far below what the elements resolve (they
#: follow r to within tenths of a dB) and the promise is settled on the unrounded elements.
FIT_INPUT_DB = 0.01
#: ΔD% (the fit's weights and notch seeds) is rounded to this fraction of its peak, for the same
#: reason as :data:`FIT_INPUT_DB`.
FIT_SENS_REL = 1e-6
_DB = 10 / np.log(10)  # 10·log10(x) = _DB·ln(x)
_ORDERS = (0.0, 0.75, 1.0, 1.5, 2.0, 4.0)  # the moments spectral.SpectralStats holds, in its order


def _element_db(omega, x, n_notch, jac=False):
    """e(ω), dB, of [gain, lag, lead, notches] packed in x (log frequencies, see :func:`_unpack`),
    and with ``jac`` its Jacobian ∂e/∂x (n_omega, p), analytic (each element a log-magnitude)."""
    x = np.asarray(x, float)
    w2 = omega * omega
    e = np.full(omega.shape, x[0])
    d = np.empty((omega.size, x.size)) if jac else None
    if jac:
        d[:, 0] = 1.0
    for i, sign in zip(range(1, 5), (1.0, -1.0, 1.0, -1.0)):  # lag zero, lag pole, lead zero, lead pole
        q = w2 * np.exp(-2 * x[i])
        e += sign * _DB * np.log1p(q)
        if jac:
            d[:, i] = -2 * sign * _DB * q / (1 + q)
    if n_notch:  # all notches at once, (n_notch, n_omega)
        log_wn, depth, log_zp = (x[5 + j::3][:, None] for j in range(3))
        wn2, zp2 = np.exp(2 * log_wn), np.exp(2 * log_zp)
        a = (wn2 - w2) ** 2
        bp = 4 * wn2 * w2 * zp2
        bz = bp * 10 ** (-depth / 10)
        az, ap = a + bz, a + bp
        e += _DB * np.sum(np.log(az / ap), axis=0)
        if jac:
            da = 4 * wn2 * (wn2 - w2)
            d[:, 5::3] = (_DB * ((da + 2 * bz) / az - (da + 2 * bp) / ap)).T
            d[:, 6::3] = (-bz / az).T
            d[:, 7::3] = (2 * _DB * (bz / az - bp / ap)).T
    return e, d


class _Promise:
    """The exact DEL promise (%) of a shaping e(ω) (dB) on the baseline grid and its gradient.

    What :func:`specdesign.spec.promise_of` gives (Dirlik on |10^(e/20)·T|²S_W, DEL at 1 Hz),
    with ∂promise/∂e: the damage depends on e only through the spectral moments, linear in
    10^(e/10)·S, so the gradient is the moments' derivatives (complex step on the six moments,
    one stacked damage evaluation) mapped back through the moment matrix."""

    def __init__(self, base):
        w = base.omega
        self.a = spectral.trapezoid_weights(w)[:, None] * w[:, None] ** np.asarray(_ORDERS)
        self.m, self.method, self.stats = base.m, base.method, spectral.SpectralStats
        self.psd = base.psd / (base.psd @ self.a[:, 0])  # unit variance: no damage overflows at any m
        self.d0 = float(np.real(self._damage(self.psd @ self.a)[0]))
        self.steps = np.vstack([np.zeros(len(_ORDERS)), 1j * np.eye(len(_ORDERS))])

    def _damage(self, mom):
        mom = np.atleast_2d(mom)
        return self.stats(*(mom[:, j] for j in range(len(_ORDERS)))).damage_rate(self.m, self.method)

    def __call__(self, e, grad=True):
        psd = self.psd * 10 ** (e / 10)
        mom = psd @ self.a
        if not grad:
            return 100 * (1 - (float(np.real(self._damage(mom)[0])) / self.d0) ** (1 / self.m))
        h = 1e-30 * np.abs(mom)  # complex step: no difference is taken, so a step far below rounding is exact
        d = self._damage(mom[None, :] + self.steps * h)
        d_e = float(d[0].real)
        ratio = (d_e / self.d0) ** (1 / self.m)
        dd_de = (self.a @ (d[1:].imag / h)) * psd / _DB  # ∂D/∂e_k, e in dB
        return 100 * (1 - ratio), -(100 / self.m) * ratio / d_e * dd_de


def _unpack(x, n_notch):
    """The :mod:`specdesign.spec` elements of a parameter vector."""
    from .. import spec

    out = [spec.Gain(float(x[0])), spec.LeadLag(float(np.exp(x[1])), float(np.exp(x[2]))),
           spec.LeadLag(float(np.exp(x[3])), float(np.exp(x[4])))]
    for wn, depth, zp in x[5:].reshape(n_notch, 3):
        out.append(spec.Notch(float(np.exp(wn)), float(depth), float(np.exp(zp))))
    return tuple(out)


def _fit(promise, grid, r, n_notch, x, bounds):
    """The shape of most promise above ``r`` for ``n_notch`` notches, from ``x``: (x, promise).

    ``grid`` holds the promise's grid at its even points (see :func:`_fit_grid`). The gain is not a variable: for a shape s(ω) (the elements without it) the least gain that
    keeps s + g ≥ r on ``grid`` is g = max(r − s), so the fit is unconstrained but for the
    parameter bounds. It maximises promise(s + g) − :data:`REGULARISATION`·mean(e²) with the
    maximum smoothed (log-sum-exp at :data:`SMOOTHING_DB`, which lies above it: every iterate is
    above ``r``), by L-BFGS-B with the analytic gradient, run to its gradient tolerance; the
    gain returned is the exact maximum, so the result is a continuous function of the input.
    """
    from scipy.optimize import minimize

    wk = np.gradient(np.log(grid[::2]))
    wk = wk / wk.sum()
    x = np.asarray(x, float).copy()
    x[0] = 0.0
    for tau in SMOOTHING_DB:
        def cost(th, tau=tau):
            th = np.r_[0.0, th[1:]]
            s, ds = _element_db(grid, th, n_notch, jac=True)
            z = (r - s) / tau
            pk = np.exp(z - z.max())
            g = tau * (z.max() + np.log(pk.sum()))
            pk /= pk.sum()
            de = ds[::2] - pk @ ds  # ∂e/∂θ on the promise's grid, the gain following
            e = s[::2] + g
            p, dp = promise(e)
            grad = (2 * REGULARISATION * wk * e - dp) @ de
            grad[0] = 0.0
            return REGULARISATION * float(wk @ e**2) - p, grad

        x = minimize(cost, x, jac=True, method="L-BFGS-B", bounds=bounds,
                     options={"maxiter": MAX_ITERATIONS, "gtol": FIT_GTOL, "ftol": FIT_FTOL, "maxcor": LBFGS_MEMORY}).x
    x[0] = 0.0
    s = _element_db(grid, x, n_notch)[0]
    x[0] = float(np.max(r - s))
    return x, promise(s[::2] + x[0], grad=False)


def _follow(grid, r, weight, n_notch, x, bounds):
    """The elements that follow ``r`` (dB) for ``n_notch`` notches, from ``x``: weighted least
    squares in dB, a shortfall below ``r`` weighing :data:`BELOW_WEIGHT` times an excess (the
    design must then do better than the certificate there). Smooth, so L-BFGS-B converges to
    its tolerance and the result moves continuously with ``r``."""
    from scipy.optimize import minimize

    def cost(th):
        e, de = _element_db(grid, th, n_notch, jac=True)
        d = e - r
        k = weight * np.where(d < 0, BELOW_WEIGHT, 1.0)
        return float(k @ (d * d)), (2 * k * d) @ de

    return minimize(cost, x, jac=True, method="L-BFGS-B", bounds=bounds,
                    options={"maxiter": MAX_ITERATIONS, "gtol": FOLLOW_GTOL, "ftol": FOLLOW_FTOL, "maxcor": LBFGS_MEMORY}).x


def _shift_to(promise, e, aim):
    """The uniform shift δ (dB) with promise(e + δ) = ``aim`` (the promise falls as δ grows)."""
    from scipy.optimize import brentq

    lo, hi = -1.0, 1.0
    while promise(e + lo, grad=False) < aim:
        lo *= 2
        if lo < -SHIFT_CAP_DB:
            return lo
    while promise(e + hi, grad=False) > aim:
        hi *= 2
        if hi > SHIFT_CAP_DB:
            return hi
    return brentq(lambda g: promise(e + g, grad=False) - aim, lo, hi, xtol=ROOT_XTOL_DB, rtol=ROOT_RTOL)


def _fit_grid(omega):
    """The fit's grid: ``omega`` (the promise's, at the even points) with the geometric mean of
    each pair of neighbours between them, so that e(ω) is evaluated once for the promise and
    the certificate's envelope."""
    mid = np.sqrt(omega[1:] * omega[:-1])
    return np.insert(omega, np.arange(1, omega.size), mid)


def _settle(promise, omega, x, n_notch, lift_db, aim):
    """x with its gain lifted by ``lift_db`` and then raised until the promise is ``aim`` (when it
    is above): (x, promise). A uniform gain lowers the promise monotonically and keeps every
    element above the certificate."""
    from scipy.optimize import brentq

    x = x.copy()
    x[0] += lift_db
    e = _element_db(omega, x, n_notch)[0]
    p = promise(e, grad=False)
    if p > aim:
        hi = 1.0
        while promise(e + hi, grad=False) > aim:
            hi *= 2
            if hi > SHIFT_CAP_DB:  # bounded as _shift_to's search: above any promise's reach
                break
        dx = brentq(lambda g: promise(e + g, grad=False) - aim, 0.0, hi, xtol=ROOT_XTOL_DB, rtol=ROOT_RTOL)
        x[0] += dx
        p = promise(e + dx, grad=False)
    return x, p


def _start(grid, r):
    """The gain, lag and lead to start from, and their bounds: the lag returns the DC level to
    0 dB by 0.05 rad/s, the lead lifts above 1.5 rad/s by what the certificate needs there."""
    lo, hi = np.log(grid[0]), np.log(grid[-1])
    hf, lf = grid > LEAD_OMEGA, grid < LAG_OMEGA
    lead_db = float(max(np.max(r[hf]), 0.0) + START_MARGIN_DB) if np.any(hf) else START_MARGIN_DB
    lag_db = float(max(np.max(r[lf]), 0.0) + START_MARGIN_DB) if np.any(lf) else START_MARGIN_DB
    x = [lag_db, np.log(LAG_OMEGA), np.log(LAG_OMEGA * 10 ** (-lag_db / 20)), np.log(LEAD_OMEGA),
         np.log(LEAD_OMEGA * 10 ** (lead_db / 20))]
    return np.asarray(x, float), [GAIN_BOUNDS_DB] + [(lo, hi)] * 4


def _dense_ratio(cert, base):
    """20·log10(|W^cert|/|T^ROSCO|) on 2000 points over the baseline grid's span, refined around
    the lightly damped roots of both maps: the final check of the elements (between the fit's
    grid points a narrow dip of the certificate's ratio could rise above them)."""
    roots = np.concatenate([system_roots(cert.tower.baseline), system_roots(base.system)])
    w = refine_grid(np.geomspace(base.omega[0], base.omega[-1], DENSE_POINTS), lightly_damped(roots),
                    points_per_width=DENSE_POINTS_PER_WIDTH)
    return w, 20 * np.log10(np.abs(cert.tower.response(w)) / np.abs(siso_response(base.system, w)))


def _seeds(omega, sensitivity, grid, r):
    """Notch centres and depths (dB): first the certificate's rises between the lag and the lead
    (above 0 dB, or 3 dB above its minimum within ±5 %: the narrow bump between two dips beside
    the tower mode), bumps the elements must follow, then the peaks of ΔD%·room (reductions that
    pay), each list largest first."""
    from scipy.ndimage import minimum_filter1d

    sens = np.interp(grid, omega, sensitivity)
    band = (grid > LAG_OMEGA) & (grid < LEAD_OMEGA)
    rise = r - minimum_filter1d(r, size=max(3, round(SEED_WINDOW / np.log(grid[1] / grid[0]))), mode="nearest")

    def peaks(s):
        k = [i for i in range(1, len(grid) - 1) if s[i] > 0 and s[i] >= s[i - 1] and s[i] >= s[i + 1]]
        return sorted(k, key=lambda i: -s[i])

    out = []
    bumps = np.where(band & ((r > SEED_ABOVE_DB) | (rise > SEED_RISE_DB)),
                     (np.maximum(r, 0.0) + rise) * (sens + sens.max() * SEED_SENS_FLOOR), 0.0)
    for k in peaks(bumps) + peaks(sens * np.maximum(-r, 0.0)):
        if all(abs(np.log(grid[k] / w)) > SEED_SPACING for w, _ in out):
            out.append((float(grid[k]), float(np.clip(-r[k] - (SEED_BUMP_LIFT_DB if r[k] > 0 else 0.0), *SEED_DEPTH_DB))))
    return out


def _unstable_pole(design, model):
    """The rightmost pole (1/s) of a certificate's controller when it is itself unstable (real
    part above :data:`specdesign.closedloop.UNSTABLE_CONTROLLER_RATE`), else None: design_qft refuses
    such a controller (a saturated pitch opens the loop) and reduces its design from it."""
    import control as ct

    poles = np.asarray(ct.poles(design.controller(model)))
    if poles.size and poles.real.max() > UNSTABLE_CONTROLLER_RATE:
        return complex(poles[np.argmax(poles.real)])
    return None


def _followed(search, base, promise, t, aim, max_notches, for_target, headroom_pp, envelope):
    """The elements that follow the upper envelope (±``envelope`` in ln ω) of the certificate for
    ``t`` + ``headroom_pp``, shifted to promise ``aim`` and certified themselves
    (:meth:`CertificateSearch.for_tower`). Raises ValueError as ``for_tower`` does, and when
    the certifying controller is itself unstable."""
    from scipy.ndimage import maximum_filter1d

    from .. import spec
    cert = search.for_target(t + headroom_pp, **for_target)
    w = base.omega
    r = 20 * np.log10(np.abs(cert.tower.response(w)) / np.abs(siso_response(base.system, w)))
    # its upper envelope: a plant case's resonance lies a few per cent from the nominal one, so
    # elements that dip into the certificate's narrow dips would ask the cases for what they cannot give
    r = maximum_filter1d(r, size=max(1, round(2 * envelope / np.log(w[1] / w[0]))), mode="nearest")
    # the fit's inputs rounded (FIT_INPUT_DB): a non-convex fit, the same on the same inputs
    r = FIT_INPUT_DB * np.round(r / FIT_INPUT_DB)
    sens = np.maximum(base.sensitivity, 0.0)
    sens = FIT_SENS_REL * np.round(sens / (sens.max() * FIT_SENS_REL))  # peak 1: a scale-free weight
    weight = (sens + WEIGHT_FLOOR * sens.max()) * np.gradient(np.log(w))
    weight = weight / weight.sum()
    seeds = _seeds(w, sens, w, r)
    x, bounds = _start(w, r)
    # notch centres on the design grid (0.01-10 rad/s): the pair's promise is also evaluated there
    lo, hi = max(bounds[1][0], np.log(NOTCH_BAND[0])), min(bounds[1][1], np.log(NOTCH_BAND[1]))
    best = None
    for n in range(min(int(max_notches), len(seeds)) + 1):  # the fewest notches that follow it
        if n:  # warm start: the n − 1 solution and the next seed
            wn, depth = seeds[n - 1]
            x = np.r_[x, np.log(wn), depth, np.log(NOTCH_ZETA_START if depth > 0 else BUMP_ZETA_START)]
            bounds = bounds + [(lo, hi), NOTCH_DEPTH_BOUNDS_DB, (np.log(NOTCH_ZETA_BOUNDS[0]), np.log(NOTCH_ZETA_BOUNDS[1]))]
        x = _follow(w, r, weight, n, x, bounds)
        delta = _shift_to(promise, _element_db(w, x, n)[0], aim)
        if best is None or delta > best[0] + FOLLOW_GAIN_DB:
            best = (delta, x.copy(), n)
        if delta >= 0.0:  # the fit itself promises the aim: no more notches needed
            break
    delta, x, n = best
    x[0] += delta
    tower = spec.Specification(base.system, _unpack(x, n), name="W_tower_base_my")
    ts = search.for_tower(tower, t, **{k: x for k, x in for_target.items() if k == "speed_slack_db"})
    p = _unstable_pole(ts.design, search.model)
    if p is not None:
        raise ValueError(f"its certificate's controller is unstable (pole {p.real:.4f}{p.imag:+.4f}j 1/s)")
    return replace(ts, promise=spec.promise_of(tower, base), target_reduction=t)


def _fit_above(model, cert, base, promise, grid, t0, t, aim, max_notches, headroom_pp, tried):
    """The fallback at one headroom: elements fitted above the upper envelope of ``cert``'s
    ratio to ROSCO's map (the widest envelope of :data:`ENVELOPES` first, the fewest notches
    that promise ``aim``), settled and recertified through ``cert``. Returns (the
    TargetSpecification, None), or (None, the last recertification error or None) when none
    certifies; appends what each envelope promised to ``tried``."""
    from scipy.ndimage import maximum_filter1d

    from .. import spec
    h, why = headroom_pp, None
    ratio = 20 * np.log10(np.abs(cert.tower.response(grid)) / t0)
    dense = None
    for env in ENVELOPES:  # the widest envelope first: the fewest, widest elements
        r = maximum_filter1d(ratio, size=max(1, round(2 * env / np.log(grid[1] / grid[0]))), mode="nearest")
        reach = promise(np.interp(base.omega, grid, r), grad=False)
        tried.append(f"{h:g} pp, ±{100 * env:g} %: envelope {reach:.1f} %")
        if reach < aim + ENVELOPE_LOSS_PP:  # elements above r promise at most what r does
            continue
        seeds = _seeds(base.omega, base.sensitivity, grid, r)
        x, bounds = _start(grid, r)
        fits = []
        lo, hi = max(bounds[1][0], np.log(NOTCH_BAND[0])), min(bounds[1][1], np.log(NOTCH_BAND[1]))
        for n in range(min(int(max_notches), len(seeds)) + 1):  # the fewest notches that do
            if n:  # warm start: the n − 1 solution and the next seed
                wn, depth = seeds[n - 1]
                x = np.r_[x, np.log(wn), depth, np.log(NOTCH_ZETA_START if depth > 0 else BUMP_ZETA_START)]
                bounds = bounds + [(lo, hi), NOTCH_DEPTH_BOUNDS_DB, (np.log(NOTCH_ZETA_BOUNDS[0]), np.log(NOTCH_ZETA_BOUNDS[1]))]
            x, best = _fit(promise, grid, r, n, x, bounds)
            fits.append(best)
            if best < aim:
                continue
            if dense is None:
                dense = _dense_ratio(cert, base)
            lift = max(0.0, float(np.max(dense[1] - _element_db(dense[0], x, n)[0])))
            xs, got = _settle(promise, base.omega, x, n, lift, aim)
            if got < t:
                continue
            tower = spec.Specification(base.system, _unpack(xs, n), name="W_tower_base_my")
            try:
                ts = recertify(model, cert, tower=tower)
                # the promise on the fit's grid, which sees the elements' cost beyond the certificate's grid
                return replace(ts, promise=spec.promise_of(tower, base), target_reduction=t), None
            except ValueError as e:  # between grid points: said, and the next structure tried
                why = str(e)
        tried[-1] += f", elements up to {max(fits):.1f} %"
    return None, why


@on_one_blas_thread  # L-BFGS-B's small BLAS calls: 10× faster on one thread (specdesign._blas)
def element_specification(model, wind_speed, target_reduction=TARGET_REDUCTION, *, headroom_pp=HEADROOM_PP,
                          max_notches=MAX_NOTCHES, m=TOWER_M, omega=None, **target_options):
    """A certified tower specification for ``target_reduction``, as ROSCO's map times shaping elements.

    See the module docstring for the problem solved.

    Parameters
    ----------
    model, wind_speed, target_reduction
        The turbine, the operating point (m/s) and the tower-base DEL reduction to promise (%),
        as :func:`specification_for_target` takes them.
    headroom_pp : sequence of float
        Extra reductions (percentage points) asked of the certificates of the fallback (elements
        above their envelope), tried in turn after :data:`FOLLOW`.
    max_notches : int
        Most notches placed (≥ 0).
    m : float
        Wöhler exponent (-).
    omega : array_like, optional
        Grid of the promise and the fit, rad/s, and of the certificate's design (default: the
        fit and the promise on :data:`FIT_OMEGA`, the certificate on its own default grid).
    **target_options
        Options of the certificate, as for :func:`specification_for_target` (e.g. ``slack_db``,
        ``case_offsets``, ``max_sensitivity``, ``speed_slack_db``); one :class:`CertificateSearch`
        serves every certificate, each speed relaxation solved once.

    Returns
    -------
    TargetSpecification
        ``tower`` a :class:`specdesign.spec.Specification` on ROSCO's T_{MyT,w} with the
        elements (Gain, lag LeadLag, lead LeadLag, Notches), ``speed`` ROSCO's T_{Ω,w} relaxed
        by what the certificate needs over the plant cases, the promise (≥
        ``target_reduction``, exact Dirlik on :data:`FIT_OMEGA`) and the certificate that meets
        both at every plant case.

    Raises
    ------
    ValueError
        For a target outside (0, 100) or a bad ``headroom_pp``/``max_notches``; or when no
        element specification reaches the target: the message lists why each followed
        certificate could not be certified (per speed relaxation: no design, or by how much a
        plant case exceeded the elements, where) and, per headroom and envelope of the
        fallback, what the certificate's envelope and the fitted elements promised (the
        envelope binds when it promises less than the target plus :data:`PROMISE_MARGIN_PP` +
        :data:`ENVELOPE_LOSS_PP`),
        and, when no certificate exists for a larger target, the reason from
        :func:`specification_for_target` (the speed relaxation it would need, the best promise).

    Examples
    --------
    >>> from specdesign.turbine import iea15mw
    >>> ts = element_specification(iea15mw(), 19.0, 25.0)   # doctest: +SKIP
    >>> [type(e).__name__ for e in ts.tower.elements]        # doctest: +SKIP
    ['Gain', 'LeadLag', 'LeadLag', 'Notch', 'Notch']
    """
    from .. import spec
    t = del_target(target_reduction)
    heads = np.atleast_1d(np.asarray(headroom_pp, float))
    if heads.ndim != 1 or heads.size == 0 or not np.all(np.isfinite(heads)) or np.any(heads <= 0):
        raise ValueError(f"headroom_pp={headroom_pp!r} must be positive percentage points")
    if isinstance(max_notches, (bool, np.bool_)) or int(max_notches) != max_notches or max_notches < 0:
        raise ValueError(f"max_notches={max_notches!r} must be a whole number ≥ 0")
    # the certificate's options checked here, before the baseline and the search are built (a
    # tolerance ≤ 0 would otherwise only stop the first bisection, forever)
    margin_db(target_options.get("slack_db", SLACK_DB), "slack_db")
    margin_db(target_options.get("speed_slack_db", SPEED_SLACK_DB), "speed_slack_db")
    search_options(target_options.get("tolerance_db", TOLERANCE_DB), target_options.get("max_relax_db", MAX_RELAX_DB),
                   target_options.get("speed_relax_db"))
    v = model.check_wind_speed(wind_speed)
    base = spec.baseline_analysis(model, v, m=m, omega=FIT_OMEGA if omega is None else omega)
    promise = _Promise(base)
    grid = _fit_grid(base.omega)
    t0 = np.abs(siso_response(base.system, grid))
    aim = t + PROMISE_MARGIN_PP
    # the certificate's options, split between the search and its targets as their signatures do
    search_keys = set(inspect.signature(CertificateSearch).parameters) - {"model", "wind_speed", "m", "omega"}
    target_keys = set(inspect.signature(CertificateSearch.for_target).parameters) - {"self", "target_reduction"}
    unknown = sorted(set(target_options) - search_keys - target_keys)
    if unknown:
        raise TypeError(f"element_specification got unknown option(s) {unknown}; the certificate's are "
                        f"{sorted(search_keys | target_keys)}")
    search = CertificateSearch(model, v, m=m, omega=omega,
                               **{k: x for k, x in target_options.items() if k in search_keys})
    for_target = {k: x for k, x in target_options.items() if k in target_keys}
    tried, why = [], ""
    for h, env in FOLLOW:
        if t + h >= 100:
            break
        try:
            return _followed(search, base, promise, t, aim, max_notches, for_target, h, env)
        except ValueError as e:
            tried.append(f"following the {h:g} pp certificate (±{100 * env:g} %): {e}")
    for h in heads:
        if t + h >= 100:
            break
        try:
            cert = search.for_target(t + float(h), **for_target)
        except ValueError as e:
            why = str(e)
            break
        p = _unstable_pole(cert.design, model)
        if p is not None:  # design_qft would refuse the design reduced from it: the next headroom
            tried.append(f"{h:g} pp: the certificate's controller is unstable (pole {p.real:.4f}{p.imag:+.4f}j 1/s)")
            continue
        ts, failed = _fit_above(model, cert, base, promise, grid, t0, t, aim, max_notches, h, tried)
        if ts is not None:
            return ts
        why = failed if failed is not None else why
    raise ValueError(f"no element specification above a certified one promises {t:g} % at {v:g} m/s with up to "
                     f"{max_notches} notches (headroom, envelope half-width: promise "
                     f"{'; '.join(tried) if tried else 'none tried'}; an envelope must promise ≥ target + "
                     f"{PROMISE_MARGIN_PP + ENVELOPE_LOSS_PP:g} pp to be fitted)" + (f": {why}" if why else ""))
