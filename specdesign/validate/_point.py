"""One wind speed of a campaign: every controller on the same seeds, simulated and
post-processed (indicators, Welch spectra, linear and Volterra predictions). Called by
:func:`specdesign.validate.run_campaign`, locally or on an executor (so module level)."""
from __future__ import annotations

import warnings

import numpy as np

from .. import wind as wmod
from .._blas import on_one_blas_thread
from ..closedloop import ClosedLoopUnstableWarning, unstable_message, unstable_poles
from ..simulate import (
    SimulationDivergedError,
    SimulationResult,
    simulate,
    turbine_plant,
    wind_series,
)
from ..simulate.checks import checked_loop
from ._loop import has_linear_form, rotor_radius
from .metrics import INDICATORS, indicators
from .prediction import closed_loop_response, linear_prediction, prediction_grid
from .stats import welch_psd
from .volterra import volterra_response

#: outputs whose Welch spectra and predicted spectra a campaign keeps
SPECTRA = ("gen_speed", "tower_base_my")


def _nan_point(out, omega, n_seeds, linear_twin, volterra):
    """Every entry of one controller NaN (unstable, or its simulation diverged)."""
    nan = np.full(n_seeds, np.nan)
    for k in INDICATORS:
        out["values"].setdefault(k, []).append(nan)
        if linear_twin:
            out["linear"].setdefault(k, []).append(nan)
        if volterra:
            out["volterra"].setdefault(k, []).append(nan)
    out["pred"].append(np.nan)
    for k in SPECTRA:
        out["welch"][k].append(np.full((n_seeds, omega.size), np.nan))
        out["ppsd"][k].append(np.full(omega.size, np.nan))


# BLAS on one thread in every task, wherever it runs: a campaign's results must not depend on
# the thread count of the process running it (a dask worker's differs from the client's, and a
# threaded BLAS reduction may sum in another order)
@on_one_blas_thread
def campaign_point(model, controllers, v, seeds, duration, dt, record_dt, transient, m, predict,
                    turbulence_class, keep_series, nperseg, linear_twin=False, volterra=0, torque_control="auto"):
    """One wind speed, every controller, the same seeds: indicators, per-seed spectra, predictions.

    The results of a seed do not depend on the other seeds of the call (the wind of a run
    depends on (v, seed) only and the runs of a batch do not interact), which is what lets
    a resumed campaign run only its missing seeds. ``torque_control`` goes to the simulator
    for the compiled controllers; a callable one commands the torque itself (or holds the
    trim torque), so it runs with "auto" unless None is asked.
    """
    n_keep = len(seeds) if keep_series is True else int(keep_series)
    radius = rotor_radius(model)
    wdt = record_dt
    wind = wind_series(radius, [v], seeds, transient + duration + wdt, wdt, turbulence_class)
    out = {"values": {}, "linear": {}, "volterra": {}, "pred": [], "welch": {k: [] for k in SPECTRA},
           "ppsd": {k: [] for k in SPECTRA}, "series": {}, "unstable": []}
    omega = welch_psd(np.zeros((1, int(round(duration / record_dt)))), record_dt, nperseg)[0]
    sw = None
    plant = turbine_plant(model)
    for name, c in controllers.items():
        # the answer run_campaign's up-front check (check_campaign_step) already has
        bad = np.zeros(0)
        if has_linear_form(c):
            bad = checked_loop(plant, c, v, dt) if plant.linearize is not None else unstable_poles(model, c, v)
        if bad.size:
            warnings.warn(unstable_message(c, v, bad) + f"; campaign results of {name!r} at {v:g} m/s are NaN",
                          ClosedLoopUnstableWarning, stacklevel=3)
        r = None
        if not bad.size:  # an unstable loop is not simulated: nothing of it would be a result
            tc = torque_control if has_linear_form(c) or torque_control is None else "auto"
            try:
                r = simulate(model, c, [v], seeds=seeds, wind=wind, wind_dt=wdt, duration=duration, dt=dt,
                             record_dt=record_dt, transient=transient, torque_control=tc)
            except SimulationDivergedError as err:
                warnings.warn(f"controller {name!r}: {err}; campaign results of {name!r} at {v:g} m/s are NaN",
                              ClosedLoopUnstableWarning, stacklevel=3)
                bad = np.array([np.nan])
        out["unstable"].append(bool(bad.size))
        if r is None:
            _nan_point(out, omega, len(seeds), linear_twin, volterra)
            continue
        ind = indicators(r.outputs, r.dt, m)
        for k, val in ind.as_dict().items():
            out["values"].setdefault(k, []).append(val[0])
        if linear_twin:
            lin = {k: np.full((1, len(seeds)), np.nan) for k in INDICATORS}
            if has_linear_form(c):
                try:
                    rl = simulate(model, c, [v], seeds=seeds, wind=wind, wind_dt=wdt, duration=duration, dt=dt,
                                  record_dt=record_dt, transient=transient, linear=True)
                    lin = indicators(rl.outputs, rl.dt, m).as_dict()
                except SimulationDivergedError as err:  # keep the nonlinear results: only the twin is NaN
                    warnings.warn(f"controller {name!r}: {err}; the linear twin of {name!r} at {v:g} m/s is NaN",
                                  ClosedLoopUnstableWarning, stacklevel=3)
            for k, val in lin.items():
                out["linear"].setdefault(k, []).append(val[0])
        if volterra:
            if has_linear_form(c):
                vol = _volterra_indicators(model, c, v, wind[0], wdt, volterra, transient, r, m)
            else:
                vol = {k: np.full((1, len(seeds)), np.nan) for k in INDICATORS}
            for k, val in vol.items():
                out["volterra"].setdefault(k, []).append(val[0])
        for k in SPECTRA:
            omega, p = welch_psd(r[k][0], r.dt, nperseg)
            out["welch"][k].append(p)  # (S, nω) per seed: the campaign averages the cells it assembles
        if predict and has_linear_form(c):
            pr = linear_prediction(model, c, v, m=m, omega=prediction_grid(duration), turbulence_class=turbulence_class,
                                   record_length=duration)
            out["pred"].append(pr.del_)
            if sw is None:  # the same for every controller at this speed (its disc coherence is costly)
                sw = wmod.rotor_effective_spectrum(omega, v, radius, turbulence_class=turbulence_class)
            pos = omega > 0  # an integrating controller makes T singular at ω = 0: leave DC out
            for k in SPECTRA:
                pp = np.full(omega.size, np.nan)
                pp[pos] = np.abs(closed_loop_response(model, c, v, omega[pos], k)) ** 2 * sw[pos]
                out["ppsd"][k].append(pp)
        else:
            out["pred"].append(np.nan)
            for k in SPECTRA:
                out["ppsd"][k].append(np.full(omega.size, np.nan))
        if n_keep:
            outs = {k: a[:, :n_keep] for k, a in r.outputs.items()}
            out["series"][name] = SimulationResult(time=r.time, wind_speeds=r.wind_speeds, seeds=seeds[:n_keep],
                                                   outputs=outs, dt=r.dt, sim_dt=r.sim_dt, controller=name)
    out["omega"] = omega
    return out


def _volterra_indicators(model, controller, v, wind, wdt, order, transient, sim, m):
    """Indicators of the Volterra prediction over the records of the simulation ``sim``
    (same wind, same window: the wind sample at ``transient`` is the first record sample)."""
    outs = ("tower_base_my", "gen_speed", "power", "pitch") + (("blade_root_my",) if "blade_root_my" in sim.outputs else ())
    terms = volterra_response(model, controller, v, wind, wdt, order=order, outputs=outs)
    op = model.trim(v)
    y0 = dict(zip(model.output_names, model.evaluate_outputs(op.x, v, op.pitch, op.gen_torque)))
    i0, n = int(round(transient / wdt)), sim.outputs["tower_base_my"].shape[-1]
    series = {o: (y0[o] + terms[o].sum(axis=0)[..., i0:i0 + n])[None] for o in outs}
    return indicators(series, sim.dt, m).as_dict()
