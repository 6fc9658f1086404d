"""The plant cases' margin in a certified tower specification, as a gain and a few bumps (see :mod:`specdesign.feasibility`).

A certificate closed around the plant cases (v ± 0.5, 1 m/s) gives each case a tower map whose
ratio to that case's ROSCO map exceeds the nominal ratio by

    p(ω) = max(0, max_i 20·log10[(|T_i|/|T^ROSCO_i|) / (|T_0|/|T^ROSCO_0|)])  dB,

and W_MyT = T_0 · slack · M must lie above every case's map, W_i = T^ROSCO_i·W/T^ROSCO_0, so
|M(jω)| ≥ p(ω) in dB. A uniform M (the largest excess, max p) is the simplest and the most
costly: p lives near the tower mode (up to 2.7 dB at 1.13 rad/s at 15 m/s on the IEA 15 MW,
where the v − 1 m/s case's resonance moves) and in the wind band (0.6-0.8 dB around 0.1 rad/s),
and is a few tenths of a dB elsewhere, yet each dB everywhere costs ~12 % of the remaining DEL.
:func:`case_margin` writes M as a gain and up to :data:`MARGIN_BUMPS` bumps (a
:class:`specdesign.spec.Notch` of negative depth, ≥ 1 at every frequency) that follow p from
above where ΔD% weighs, then lifts the gain by the largest shortfall left on the check's grid, so
|M| ≥ p there exactly. It keeps the number of bumps (0 to MARGIN_BUMPS, 0 being the uniform
margin) whose specification promises most, so it never promises less than the uniform margin.

Units: ω in rad/s, magnitudes in dB here, promises in % DEL.
"""
from __future__ import annotations

import numpy as np
from scipy.optimize import minimize

__all__ = ["DEFAULT_MARGIN_BUMPS", "MARGIN_BELOW_WEIGHT", "MARGIN_BUMPS", "MARGIN_SEED_SPACING", "MARGIN_ZETA_BOUNDS", "case_margin", "shaping_db"]

#: Most bumps worth allowing: the tower mode, the wind band's hump (~0.1 rad/s) and one more
#: (a fourth added nothing at 19 m/s on the IEA 15 MW).
MARGIN_BUMPS = 3
#: Bumps the certificate searches allow by default (``margin_bumps``): :data:`MARGIN_BUMPS`, what
#: the 25 % target under the measured high-frequency gain bound needs at 15-25 m/s
#: (docs/feasibility.md); 0 is the uniform margin (max p everywhere) of the earlier pairs.
DEFAULT_MARGIN_BUMPS = MARGIN_BUMPS
#: Weight of a shortfall of the bumps below p relative to an excess in their least-squares fit
#: (dB²): the shortfall left is what the gain is lifted by everywhere, so it is made small.
MARGIN_BELOW_WEIGHT = 10.0
#: Least distance between two bumps' seeds, in ln ω (a factor 2): the tower mode's excess and the
#: wind band's are a decade apart, and one bump covers a feature ±50 % wide.
MARGIN_SEED_SPACING = np.log(2.0)
#: Bounds of a bump's pole damping ratio ζ_p (-): 0.005 follows a case's resonance moved by
#: 1 % of its frequency, 1.5 a hump over a decade.
MARGIN_ZETA_BOUNDS = (0.005, 1.5)
#: Bounds of a bump's height, dB (the Notch's depth is minus it).
_HEIGHT_BOUNDS_DB = (0.0, 20.0)
#: Floor of the fit's ΔD% weight, as a fraction of its peak (the shape still follows p where
#: ΔD% is nil, a little), as in :mod:`specdesign.feasibility.elements`.
_WEIGHT_FLOOR = 0.05
#: L-BFGS-B's tolerances (relative change of the cost, projected gradient) and iteration guard:
#: the fit runs to convergence, so the margin moves continuously with the certificate.
_FTOL, _GTOL, _MAXITER = 1e-14, 1e-10, 5000


def _bumps_db(omega, x):
    """Σ of the bumps' magnitudes (dB) on ``omega``, x = [ln ω_n, height dB, ln ζ_p] per bump."""
    w2 = omega * omega
    out = np.zeros(omega.shape)
    for ln_wn, height, ln_z in np.reshape(x, (-1, 3)):
        wn2, z2 = np.exp(2 * ln_wn), np.exp(2 * ln_z)
        a, b = (wn2 - w2) ** 2, 4 * wn2 * w2 * z2
        out += 10 * np.log10((a + b * 10 ** (height / 10)) / (a + b))
    return out


def _seeds(omega, p, weight, n):
    """Up to ``n`` bump centres (rad/s): the largest local maxima of p·weight, each at least
    :data:`MARGIN_SEED_SPACING` in ln ω from those before it."""
    score = p * weight
    peaks = [i for i in range(1, omega.size - 1) if p[i] > 0 and score[i] >= score[i - 1] and score[i] >= score[i + 1]]
    out = []
    for i in sorted(peaks, key=lambda i: (-score[i], i)):
        if len(out) == n:
            break
        if all(abs(np.log(omega[i] / w)) >= MARGIN_SEED_SPACING for w in out):
            out.append(float(omega[i]))
    return out


def _half_width(omega, p, i, floor):
    """Half-width (in ln ω) of p's peak at index ``i`` at half its height above ``floor``: a bump's
    ζ_p to start from (a resonance's half-power half-width in ln ω is about ζ)."""
    half = 0.5 * (p[i] + floor)
    lo, hi = i, i
    while lo > 0 and p[lo] > half:
        lo -= 1
    while hi < omega.size - 1 and p[hi] > half:
        hi += 1
    return 0.5 * np.log(omega[hi] / omega[lo])


def _fit(omega, p, u, seeds, centres):
    """[gain dB, bumps...] following p from above in weighted least squares, then lifted so that it
    lies on or above p at every point of ``omega``; the bumps' centres within ``centres`` (rad/s).

    Two stages: the gain and heights with the centres and widths at their seeds (each bump on its
    peak of p), then everything from there (a free first stage can move a narrow bump off its
    peak, where its height has no gradient left). Returns both, lifted."""
    floor = float(np.median(p))
    x = [floor]
    bounds = [(-1.0, max(float(p.max()), 0.0) + 1.0)]
    for w in seeds:
        i = int(np.argmin(np.abs(omega - w)))
        zeta = float(np.clip(_half_width(omega, p, i, floor), *MARGIN_ZETA_BOUNDS))
        x += [np.log(w), float(np.clip(p[i] - floor, 0.05, _HEIGHT_BOUNDS_DB[1])), np.log(zeta)]
        bounds += [tuple(np.log(centres)), _HEIGHT_BOUNDS_DB, tuple(np.log(MARGIN_ZETA_BOUNDS))]
    x = np.asarray(x, float)

    def cost(th):
        d = th[0] + _bumps_db(omega, th[1:]) - p
        return float((u * np.where(d < 0, MARGIN_BELOW_WEIGHT, 1.0)) @ (d * d))

    options = {"ftol": _FTOL, "gtol": _GTOL, "maxiter": _MAXITER}
    free = np.r_[0, np.arange(2, x.size, 3)]  # the gain and the heights
    fixed = x.copy()

    def cost_a(th):
        y = fixed.copy()
        y[free] = th
        return cost(y)

    xa = x.copy()
    xa[free] = minimize(cost_a, x[free], method="L-BFGS-B", bounds=[bounds[j] for j in free], options=options).x
    xb = minimize(cost, xa, method="L-BFGS-B", bounds=bounds, options=options).x
    out = []
    for y in (xa, xb):
        y = y.copy()
        y[0] += float(np.max(p - y[0] - _bumps_db(omega, y[1:])))
        out.append(y)
    return out


def case_margin(omega, excess_db, weight_omega, weight, promise, max_bumps=MARGIN_BUMPS):
    """The plant cases' margin M: a gain and bumps with |M(jω)| ≥ the cases' excess on ``omega``.

    Parameters
    ----------
    omega : array_like
        The check's grid, rad/s (increasing).
    excess_db : array_like
        The cases' largest excess p(ω) over the nominal ratio to ROSCO's map on ``omega``, dB
        (clipped at 0).
    weight_omega, weight : array_like
        The fit's weight (ΔD%, -) on its own grid (rad/s, increasing: the promise's, which holds
        the bumps' centres): where the bumps follow p closely.
    promise : callable
        promise(elements) → the tower specification's promise (%) with the margin ``elements``.
    max_bumps : int
        Most bumps (0: the uniform margin, without a fit).

    Returns
    -------
    tuple
        (``spec.Gain``, ``spec.Notch``, ...) bumps of negative depth: of 0 to ``max_bumps``
        bumps, the one whose ``promise`` is largest (0 bumps: the uniform margin max p).
    """
    from .. import spec

    w = np.asarray(omega, float)
    p = np.maximum(np.asarray(excess_db, float), 0.0)
    best = (spec.Gain(float(p.max())),)
    if max_bumps == 0:
        return best
    s = np.interp(w, weight_omega, np.maximum(weight, 0.0), left=0.0, right=0.0)
    s = s + _WEIGHT_FLOOR * s.max()
    u = s * np.gradient(np.log(w))
    u = u / u.sum()
    # the centres on the weight's grid (the promise's): a notch outside it has no promise there
    centres = (float(weight_omega[0]), float(weight_omega[-1]))
    inside = (w >= centres[0]) & (w <= centres[1])
    seeds = _seeds(w[inside], p[inside], s[inside], int(max_bumps))
    best_promise = promise(best)
    for k in range(1, len(seeds) + 1):
        for x in _fit(w, p, u, seeds[:k], centres):
            elements = (spec.Gain(float(x[0])),) + tuple(spec.Notch(float(np.exp(a)), -float(h), float(np.exp(z)))
                                                         for a, h, z in np.reshape(x[1:], (-1, 3)))
            got = promise(elements)
            if got > best_promise:
                best, best_promise = elements, got
    return best


def shaping_db(elements, omega):
    """The magnitude of a product of shaping elements, in dB.

    Parameters
    ----------
    elements : sequence
        :mod:`specdesign.spec` shaping elements (e.g. :func:`case_margin`'s).
    omega : array_like
        Frequencies, rad/s.

    Returns
    -------
    numpy.ndarray
        20·log10 |Π elements(jω)|, dB, shaped like ``omega``.
    """
    out = np.zeros(np.shape(omega))
    for e in elements:
        out += 20 * np.log10(np.abs(e.response(omega)))
    return out
