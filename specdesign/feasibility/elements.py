"""A certified specification for a DEL target written in shaping elements (see :mod:`specdesign.feasibility`).

:func:`specification_for_target` certifies W_MyT = |T^cert_{MyT,w}|·slack: the certifying
design's own map, a transfer function of its order that a designer cannot read or edit by
element. :func:`element_specification` writes a certified tower specification as ROSCO's map
times a few shaping elements of :mod:`specdesign.spec` (a gain, a lag, a lead, notches; a
notch with a negative depth is a bump), chosen over the whole band:

    minimise    Σ_k w_k·e(ω_k)²                       (the least change from ROSCO, dB², w ∝ Δlog ω)
    subject to  promise(10^(e/20)) ≥ target            (exact Dirlik DEL reduction, 1 Hz)
                e(ω_j) ≥ r(ω_j)  at every ω_j          (above the certificate: W ≥ W^cert)

with e(ω) = 20·log10 |Π elements(jω)| and r the upper envelope (a running maximum over
±:data:`ENVELOPES` in ω, the widest first) of 20·log10(|W^cert|/|T^ROSCO_{MyT,w}|), W^cert a
certificate made for a larger target (:data:`HEADROOM_PP` above it: a specification above the
certificate promises less than the certificate's; a certificate whose controller is itself
unstable is skipped, as :func:`specdesign.qft.design_qft` refuses such a design). Where the certificate pays Bode's cost
(r > 0: the relaxations) the elements must rise too, so the cost sits explicitly inside the
specification; where r < 0 the certificate leaves room and the elements reduce only where ΔD%
makes that pay. The notches are seeded where ΔD%·room is largest and added one at a time
until the problem is solved (the constraints as penalties of growing weight, L-BFGS-B). The
pair is then re-checked by :func:`recertify` over every plant case, so the result is a
:class:`TargetSpecification` like any other: feasible by construction, its promise that of
the specification handed to the design, and editable by hand (``tower.add(...)``, then
:func:`recertify`). :func:`specdesign.spec.shape_to_target` with ``band="whole"`` is the
user's entry point to it.

Units: ω in rad/s, magnitudes in dB here, promises in % DEL.
"""
from __future__ import annotations

import contextlib
from dataclasses import replace

import numpy as np

__all__ = ["HEADROOM_PP", "MAX_NOTCHES", "PROMISE_MARGIN_PP", "ENVELOPE_LOSS_PP", "ENVELOPES", "FIT_OMEGA", "element_specification"]

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


def _element_db(omega, x, n_notch):
    """e(ω), dB, of [gain, lag, lead, notches] packed in x (log frequencies, see :func:`_unpack`);
    x of shape (p,) gives (n_omega,), a stack (k, p) gives (k, n_omega)."""
    x = np.asarray(x, float)
    xs = np.atleast_2d(x)
    g, lag_z, lag_p, lead_z, lead_p = (xs[:, i:i + 1] for i in range(5))
    w2 = (omega * omega)[None, :]
    e = g + 10 * np.log10((1 + w2 * np.exp(-2 * lag_z)) / (1 + w2 * np.exp(-2 * lag_p))) \
        + 10 * np.log10((1 + w2 * np.exp(-2 * lead_z)) / (1 + w2 * np.exp(-2 * lead_p)))
    if n_notch:
        p = xs[:, 5:].reshape(len(xs), n_notch, 3, 1)
        wn, depth, zp = np.exp(p[:, :, 0]), p[:, :, 1], np.exp(p[:, :, 2])
        zz = zp * 10 ** (-depth / 20)
        a = (wn * wn - w2[:, None, :]) ** 2
        e = e + np.sum(10 * np.log10((a + (2 * zz * wn * omega) ** 2) / (a + (2 * zp * wn * omega) ** 2)), axis=1)
    return e[0] if x.ndim == 1 else e


def _unpack(x, n_notch):
    """The :mod:`specdesign.spec` elements of a parameter vector."""
    from .. import spec

    out = [spec.Gain(float(x[0])), spec.LeadLag(float(np.exp(x[1])), float(np.exp(x[2]))),
           spec.LeadLag(float(np.exp(x[3])), float(np.exp(x[4])))]
    for wn, depth, zp in x[5:].reshape(n_notch, 3):
        out.append(spec.Notch(float(np.exp(wn)), float(depth), float(np.exp(zp))))
    return tuple(out)


def _one_blas_thread():
    """A context limiting BLAS to one thread, when threadpoolctl is installed (a scikit-learn
    dependency; without it the fit is only slower). scipy's L-BFGS-B makes small BLAS calls
    every iteration: on this shared 2-core machine a multi-threaded OpenBLAS spends 4 ms per
    iteration synchronising its threads (13 ms per evaluation of a 20-variable Rosenbrock at
    load 7, 0.1 ms with one thread), 3/4 of the whole element fit."""
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:
        return contextlib.nullcontext()
    return threadpool_limits(1, user_api="blas")


#: The penalty continuation's weights (promise μ, certificate μ_v), stage by stage: the last
#: weighs the certificate 100× more, since what is left below it is lifted by a uniform gain
#: (≈ 0.1 pp of promise per 0.01 dB) while the narrow violations sit beside the tower mode.
_STAGES = ((1.0, 1.0), (100.0, 100.0), (1e4, 1e4), (1e4, 1e6))


def _fit(base, grid, r, target, n_notch, seeds):
    """Penalty continuation (L-BFGS-B) for one number of notches: (x, promise) of a point above
    ``r`` that aims at ``target`` (the caller judges the promise)."""
    from scipy.optimize import minimize

    from .. import spec, spectral

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

    def promises(e_db):
        """Exact DEL promises (%) of a stack of e(ω) on the baseline grid: what promise_of gives,
        without Eq. (10), for the point and its finite-difference neighbours at once."""
        d = spectral.damage_rate(omega, base.psd * 10 ** (e_db / 10), base.m, method=base.method)
        return spectral.del_reduction(100 * (1 - d / base.damage_rate), base.m)

    upper = np.array([b[1] for b in bounds])
    step = np.sqrt(np.finfo(float).eps)

    # the constraints as penalties of growing weight (_STAGES): SLSQP stalls on the narrow
    # features of r near the tower mode (a bump between two dips), a continuation does not
    aim = target + PROMISE_MARGIN_PP
    for mu, mu_v in _STAGES:
        def cost(x, mu=mu, mu_v=mu_v):
            # forward differences as L-BFGS-B's own (step √eps·max(1, |x|), backwards at an upper
            # bound), evaluated as one stack: the damage of p + 1 spectra is one matrix product
            h = step * np.maximum(1.0, np.abs(x))
            h = np.where(x + h > upper, -h, h)
            xs = np.vstack([x, x + np.diag(h)])
            eo = _element_db(omega, xs, n_notch)
            below = np.maximum(r - _element_db(grid, xs, n_notch), 0.0)
            f = (eo**2 @ weights + mu_v * (below**2 @ gw) + mu * np.maximum(0.0, aim - promises(eo)) ** 2)
            return float(f[0]), (f[1:] - f[0]) / h

        with _one_blas_thread():
            x = minimize(cost, x, jac=True, method="L-BFGS-B", bounds=bounds, options={"maxiter": 500}).x
    # what the penalty leaves below the certificate is lifted by the gain, then judged
    x[0] += max(0.0, float(np.max(r - _element_db(grid, x, n_notch)))) + 1e-3
    return x, promise(x)


def _seeds(base, grid, r):
    """Notch centres and depths (dB): first the certificate's rises between the lag and the lead
    (above 0 dB, or 3 dB above its minimum within ±5 %: the narrow bump between two dips beside
    the tower mode), bumps the elements must follow, then the peaks of ΔD%·room (reductions that
    pay), each list largest first."""
    from scipy.ndimage import minimum_filter1d

    sens = np.interp(grid, base.omega, base.sensitivity)
    band = (grid > 0.05) & (grid < 1.5)
    rise = r - minimum_filter1d(r, size=max(3, round(0.1 / np.log(grid[1] / grid[0]))), mode="nearest")

    def peaks(s):
        k = [i for i in range(1, len(grid) - 1) if s[i] > 0 and s[i] >= s[i - 1] and s[i] >= s[i + 1]]
        return sorted(k, key=lambda i: -s[i])

    out = []
    bumps = np.where(band & ((r > 0.1) | (rise > 3.0)), (np.maximum(r, 0.0) + rise) * (sens + sens.max() * 1e-3), 0.0)
    for k in peaks(bumps) + peaks(sens * np.maximum(-r, 0.0)):
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
        Grid of the promise and the fit, rad/s, and of the certificate's design (default: the
        fit and the promise on :data:`FIT_OMEGA`, the certificate on its own default grid).
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
        element specification reaches the target: the message lists, per headroom and
        envelope, what the certificate's envelope and the fitted elements promised (the
        envelope binds when it promises less than the target plus :data:`ENVELOPE_LOSS_PP`),
        and, when no certificate exists for a larger target, the reason from
        :func:`specification_for_target` (the speed relaxation it would need, the best promise).

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
    from ..qft import UNSTABLE_CONTROLLER_RATE
    from .target import recertify, specification_for_target

    t = del_target(target_reduction)
    heads = np.atleast_1d(np.asarray(headroom_pp, float))
    if heads.ndim != 1 or heads.size == 0 or not np.all(np.isfinite(heads)) or np.any(heads <= 0):
        raise ValueError(f"headroom_pp={headroom_pp!r} must be positive percentage points")
    if int(max_notches) != max_notches or max_notches < 0:
        raise ValueError(f"max_notches={max_notches!r} must be a whole number ≥ 0")
    v = model.check_wind_speed(wind_speed)
    base = spec.baseline_analysis(model, v, m=m, omega=FIT_OMEGA if omega is None else omega)
    grid = np.geomspace(base.omega[0], base.omega[-1], 2 * base.omega.size)
    t0 = np.abs(np.asarray(ct.frequency_response(base.system, grid).complex).reshape(-1))
    tried, why = [], ""
    for h in heads:
        if t + h >= 100:
            break
        try:
            cert = specification_for_target(model, v, t + float(h), m=m, omega=omega, **target_options)
        except ValueError as e:
            why = str(e)
            break
        poles = np.asarray(ct.poles(cert.design.controller(model)))
        if poles.size and poles.real.max() > UNSTABLE_CONTROLLER_RATE:
            # design_qft refuses a controller that is itself unstable (a saturated pitch opens
            # the loop) and reduces its design from this certificate: the next headroom
            p = poles[np.argmax(poles.real)]
            tried.append(f"{h:g} pp: the certificate's controller is unstable (pole {p.real:.4f}{p.imag:+.4f}j 1/s)")
            continue
        ratio = 20 * np.log10(np.abs(cert.tower.response(grid)) / t0)
        for env in ENVELOPES:  # the widest envelope first: the fewest, widest elements
            r = maximum_filter1d(ratio, size=max(1, int(round(2 * env / np.log(grid[1] / grid[0])))), mode="nearest")
            reach = spec.promise_of(10 ** (np.interp(base.omega, grid, r) / 20), base).exact_del
            tried.append(f"{h:g} pp, ±{100 * env:g} %: envelope {reach:.1f} %")
            if reach < t + ENVELOPE_LOSS_PP:  # elements above r promise at most what r does
                continue
            seeds = _seeds(base, grid, r)
            fits = []
            for n in range(min(int(max_notches), len(seeds)) + 1):  # the fewest notches that do
                fit = _fit(base, grid, r, t, n, seeds)
                fits.append(fit[1])
                if fit[1] < t:
                    continue
                tower = spec.Specification(base.system, _unpack(fit[0], n), name="W_tower_base_my")
                try:
                    ts = recertify(model, cert, tower=tower)
                    # the promise on the fit's grid, which sees the elements' cost beyond the certificate's grid
                    return replace(ts, promise=spec.promise_of(tower, base), target_reduction=t)
                except ValueError as e:  # between grid points: said, and the next structure tried
                    why = str(e)
            tried[-1] += f", elements up to {max(fits):.1f} %"
    raise ValueError(f"no element specification above a certified one promises {t:g} % at {v:g} m/s with up to "
                     f"{max_notches} notches (headroom, envelope half-width: promise "
                     f"{'; '.join(tried) if tried else 'none tried'}; an envelope must promise ≥ target + "
                     f"{ENVELOPE_LOSS_PP:g} pp to be fitted)" + (f": {why}" if why else ""))
