"""A certified specification for a DEL target written in shaping elements (see :mod:`specdesign.feasibility`).

:func:`specification_for_target` certifies W_MyT = |T^cert_{MyT,w}|·slack: the certifying
design's own map, a transfer function of its order that a designer cannot read or edit by
element. :func:`element_specification` writes a certified tower specification as ROSCO's map
times a few shaping elements of :mod:`specdesign.spec` (a gain, a lag, a lead, notches; a
notch with a negative depth is a bump), chosen over the whole band:

    minimise    Σ_k w_k·e(ω_k)²                       (the least change from ROSCO, dB², w ∝ Δlog ω)
    subject to  promise(10^(e/20)) ≥ target            (exact Dirlik DEL reduction, 1 Hz)
                e(ω_j) ≥ r(ω_j)  at every ω_j          (above the certificate: W ≥ W^cert)

with e(ω) = 20·log10 |Π elements(jω)| and r = 20·log10(|W^cert|/|T^ROSCO_{MyT,w}|) of a
certificate made for a larger target (:data:`HEADROOM_PP` above it: a specification above the
certificate promises less than the certificate's). Where the certificate pays Bode's cost
(r > 0: the relaxations) the elements must rise too, so the cost sits explicitly inside the
specification; where r < 0 the certificate leaves room and the elements reduce only where ΔD%
makes that pay. The notches are seeded where ΔD%·room is largest and added one at a time
(SLSQP, as :func:`specdesign.spec.shape_to_target`) until the problem is solved. The pair is
then re-checked by :func:`recertify` over every plant case, so the result is a
:class:`TargetSpecification` like any other: feasible by construction, its promise that of
the specification handed to the design, and editable by hand (``tower.add(...)``, then
:func:`recertify`).

Units: ω in rad/s, magnitudes in dB here, promises in % DEL.
"""
from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np

__all__ = ["HEADROOM_PP", "MAX_NOTCHES", "PROMISE_MARGIN_PP", "ENVELOPE_LOSS_PP", "ENVELOPE", "element_specification"]

#: Extra DEL reduction (percentage points) asked of the certificate, tried in turn: the elements
#: lie above its map, so they promise less than it does.
HEADROOM_PP = (3.0, 5.0, 7.0, 9.0, 11.0, 13.0, 15.0)
#: Most notches (reductions or bumps) placed besides the gain, the lag and the lead.
MAX_NOTCHES = 6
#: The fit aims this much (percentage points) above the target, room for the final lift.
PROMISE_MARGIN_PP = 0.3
#: What following the envelope with a few elements typically costs (percentage points; 3-5 pp at
#: 15-25 m/s on the IEA 15 MW): a certificate whose envelope promises less than the target plus
#: this is skipped for the next headroom without fitting.
ENVELOPE_LOSS_PP = 3.0
#: Half-width (in ln ω) of the running maximum taken of the certificate's ratio: the elements
#: follow its upper envelope, not the narrow pole-zero pattern at the tower mode.
ENVELOPE = 0.03


def _element_db(omega, x, n_notch):
    """e(ω), dB, of [gain, lag, lead, notches] packed in x (log frequencies, see :func:`_unpack`)."""
    g, lag_z, lag_p, lead_z, lead_p = x[0], np.exp(x[1]), np.exp(x[2]), np.exp(x[3]), np.exp(x[4])
    w2 = omega * omega
    e = g + 10 * np.log10((1 + w2 / lag_z**2) / (1 + w2 / lag_p**2)) + 10 * np.log10((1 + w2 / lead_z**2) / (1 + w2 / lead_p**2))
    if n_notch:
        p = x[5:].reshape(n_notch, 3)
        wn, depth, zp = np.exp(p[:, 0:1]), p[:, 1:2], np.exp(p[:, 2:3])
        zz = zp * 10 ** (-depth / 20)
        a = (wn * wn - w2[None, :]) ** 2
        e = e + np.sum(10 * np.log10((a + (2 * zz * wn * omega) ** 2) / (a + (2 * zp * wn * omega) ** 2)), axis=0)
    return e


def _unpack(x, n_notch):
    """The :mod:`specdesign.spec` elements of a parameter vector."""
    from .. import spec

    out = [spec.Gain(float(x[0])), spec.LeadLag(float(np.exp(x[1])), float(np.exp(x[2]))),
           spec.LeadLag(float(np.exp(x[3])), float(np.exp(x[4])))]
    for wn, depth, zp in x[5:].reshape(n_notch, 3):
        out.append(spec.Notch(float(np.exp(wn)), float(depth), float(np.exp(zp))))
    return tuple(out)


def _fit(base, grid, r, target, n_notch, seeds):
    """Penalty continuation (L-BFGS-B) for one number of notches; (x, promise) of a point above
    ``r`` that promises ``target``, or None."""
    from scipy.optimize import minimize

    from .. import spec

    omega = base.omega
    weights = np.gradient(np.log(omega))
    weights = weights / weights.sum()
    gw = np.gradient(np.log(grid))
    gw = 100 * gw / gw.sum()
    lo, hi = np.log(grid[0]), np.log(grid[-1])
    hf, lf = grid > 1.5, grid < 0.05
    lead_db = float(max(np.max(r[hf]), 0.0) + 0.5) if np.any(hf) else 0.5
    lag_db = float(max(np.max(r[lf]), 0.0) + 0.5) if np.any(lf) else 0.5
    # the gain lifts DC by lag_db, the lag returns to 0 dB by 0.05 rad/s, the lead lifts above 1.5 rad/s
    x = [lag_db, np.log(0.05), np.log(0.05 * 10 ** (-lag_db / 20)), np.log(1.5), np.log(1.5 * 10 ** (lead_db / 20))]
    bounds = [(-20.0, 20.0), (lo, hi), (lo, hi), (lo, hi), (lo, hi)]
    for wn, depth in seeds[:n_notch]:
        x += [np.log(wn), depth, np.log(0.3 if depth > 0 else 0.05)]
        bounds += [(lo, hi), (-20.0, 40.0), (np.log(0.01), np.log(1.5))]
    x = np.asarray(x, float)

    def promise(x):
        return spec.promise_of(10 ** (_element_db(omega, x, n_notch) / 20), base).exact_del

    # the constraints as penalties of growing weight: SLSQP stalls on the narrow features of r
    # near the tower mode (a bump between two dips), a continuation does not
    aim = target + PROMISE_MARGIN_PP
    for mu in (1.0, 100.0, 1e4):
        def cost(x, mu=mu):
            below = np.maximum(r - _element_db(grid, x, n_notch), 0.0)
            return float(np.sum(weights * _element_db(omega, x, n_notch) ** 2) + mu * np.sum(gw * below**2)
                         + mu * max(0.0, aim - promise(x)) ** 2)

        x = minimize(cost, x, method="L-BFGS-B", bounds=bounds, options={"maxiter": 500}).x
    # what the penalty leaves below the certificate is lifted by the gain, then judged
    x[0] += max(0.0, float(np.max(r - _element_db(grid, x, n_notch)))) + 1e-3
    p = promise(x)
    return (x, p) if p >= target else None


def _seeds(base, grid, r):
    """Notch centres and depths (dB): first the certificate's rises above 0 dB between the lag and
    the lead (bumps the elements must follow), then the peaks of ΔD%·room (reductions that pay),
    each list largest first."""
    sens = np.interp(grid, base.omega, base.sensitivity)
    band = (grid > 0.05) & (grid < 1.5)

    def peaks(s):
        k = [i for i in range(1, len(grid) - 1) if s[i] > 0 and s[i] >= s[i - 1] and s[i] >= s[i + 1]]
        return sorted(k, key=lambda i: -s[i])

    out = []
    for k in peaks(np.where(band & (r > 0.1), r * (sens + sens.max() * 1e-3), 0.0)) + peaks(sens * np.maximum(-r, 0.0)):
        if all(abs(np.log(grid[k] / w)) > 0.02 for w, _ in out):
            out.append((float(grid[k]), float(np.clip(-r[k] - (0.3 if r[k] > 0 else 0.0), -15.0, 30.0))))
    return out


def element_specification(model, wind_speed, target_reduction=25.0, *, headroom_pp=HEADROOM_PP,
                          max_notches=MAX_NOTCHES, m=4.0, omega=None, **target_options):
    """A certified tower specification for ``target_reduction``, as ROSCO's map times shaping elements.

    See the module docstring for the problem solved.

    Parameters
    ----------
    model : specdesign.turbine.TurbineModel
        The turbine.
    wind_speed : float
        Operating point, m/s.
    target_reduction : float
        Tower-base DEL reduction the specification must promise, % (0-100).
    headroom_pp : sequence of float
        Extra reductions (percentage points) asked of the certificate, tried in turn.
    max_notches : int
        Most notches placed (≥ 0).
    m : float
        Wöhler exponent (-).
    omega : array_like, optional
        Grid of the promise and the fit, rad/s (default :func:`specdesign.spec.default_omega`).
    **target_options
        Passed to :func:`specification_for_target` for the certificate (e.g. ``slack_db``,
        ``case_offsets``, ``max_sensitivity``).

    Returns
    -------
    TargetSpecification
        ``tower`` a :class:`specdesign.spec.Specification` on ROSCO's T_{MyT,w} with the
        elements (Gain, lag LeadLag, lead LeadLag, Notches), ``speed`` the certificate's, the
        promise (≥ ``target_reduction``) and the certificate, re-checked at every plant case.

    Raises
    ------
    ValueError
        For a target outside (0, 100) or a bad ``headroom_pp``/``max_notches``; or when no
        certificate with headroom exists (the reason from :func:`specification_for_target`) or
        no element specification above it reaches the target (the best promise is given).

    Examples
    --------
    >>> from specdesign.turbine import iea15mw
    >>> ts = element_specification(iea15mw(), 19.0, 25.0)   # doctest: +SKIP
    >>> [type(e).__name__ for e in ts.tower.elements]        # doctest: +SKIP
    ['Gain', 'LeadLag', 'LeadLag', 'Notch', 'Notch']
    """
    import control as ct
    from scipy.ndimage import maximum_filter1d

    from .. import spec
    from .._checks import del_target
    from .target import recertify, specification_for_target

    t = del_target(target_reduction)
    heads = np.atleast_1d(np.asarray(headroom_pp, float))
    if heads.ndim != 1 or heads.size == 0 or not np.all(np.isfinite(heads)) or np.any(heads <= 0):
        raise ValueError(f"headroom_pp={headroom_pp!r} must be positive percentage points")
    if int(max_notches) != max_notches or max_notches < 0:
        raise ValueError(f"max_notches={max_notches!r} must be a whole number ≥ 0")
    v = model.check_wind_speed(wind_speed)
    base = spec.baseline_analysis(model, v, m=m, omega=omega)
    best, why = -np.inf, ""
    for h in heads:
        if t + h >= 100:
            break
        try:
            cert = specification_for_target(model, v, t + float(h), m=m, omega=omega, **target_options)
        except ValueError as e:
            why = str(e)
            break
        grid = np.geomspace(base.omega[0], base.omega[-1], 800)
        t0 = np.abs(np.asarray(ct.frequency_response(base.system, grid).complex).reshape(-1))
        r = maximum_filter1d(20 * np.log10(np.abs(cert.tower.response(grid)) / t0),
                             size=max(1, int(round(2 * ENVELOPE / np.log(grid[1] / grid[0])))), mode="nearest")
        best = max(best, spec.promise_of(10 ** (np.interp(base.omega, grid, r) / 20), base).exact_del)
        if best < t + ENVELOPE_LOSS_PP:  # elements above r promise at most what r does: more headroom
            continue
        seeds = _seeds(base, grid, r)
        for n in range(min(int(max_notches), len(seeds)) + 1):  # the fewest notches that do
            fit = _fit(base, grid, r, t, n, seeds)
            if fit is None:
                continue
            tower = spec.Specification(base.system, _unpack(fit[0], n), name="W_tower_base_my")
            try:
                return replace(recertify(model, cert, tower=tower), target_reduction=t)
            except ValueError as e:  # between grid points: said, and the next structure tried
                why = str(e)
    raise ValueError(f"no element specification above a certified one promises {t:g} % at {v:g} m/s with up to "
                     f"{max_notches} notches and headroom {tuple(heads.tolist())} pp"
                     + (f" (the certificates' envelopes promised up to {best:.1f} %)" if np.isfinite(best) else "")
                     + (f": {why}" if why else ""))
