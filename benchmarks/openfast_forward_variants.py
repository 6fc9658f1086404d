"""Why the forwarded QuadraticMPC rides the pitch-rate limit in OpenFAST: one short run per variant
(docs/openfast.md, "Why the MPC rides the rate limit").

Run: python benchmarks/openfast_forward_variants.py VARIANT [--duration 40] [--transient 20] [--store DIR]

19 m/s, TurbSim seed 0 (NTM B, a 60 s field), the shipped IEA 15 MW monopile deck, one OpenFAST
process (niced), 40 s recorded after 20 s, the campaign's indicators. The MPC is QuadraticMPC
(ts = 0.1 s, operating point estimated online) forwarded at DLL_DT = 0.02 s with the turbine's
pitch-rate limit, behind a wrapper that (a) applies the variant's measurement filters at every call
and (b) writes what it received and commanded to ``<store>/<variant>.log`` (one JSON line per call),
from which the spectra of the command's rate are printed. VARIANT is ``rosco`` (ROSCO as shipped)
or ``base`` or any combination of:

- ``spd<w>``: generator speed through a second-order low-pass, corner w rad/s, damping 0.7
  (``spd1.0081`` is the deck's ROSCO speed filter, F_LPFCornerFreq of its DISCON.IN);
- ``acc<w>``: the same on the tower-top acceleration;
- ``noacc``: the Kalman filter reads generator speed and pitch only;
- ``qw<x>``: speed weight q_Ω = x (default 100); ``act<x>``: pitch-activity weight q_Δ = x (0.1);
- ``wa<w>``: the MPC's internal model with a pitch actuator of natural frequency w rad/s (the
  reduced model's is 3.14 rad/s, ROSCO's PA_CornerFreq; the deck simulates none, PA_Mode = 0);
- ``oflin``: the MPC's internal model (prediction and LPV Kalman filter, scheduled on its own wind
  estimate over the linearised speeds) is OpenFAST's linearisation of the deck at 15-25 m/s
  (:func:`openfast_linear_model`: no pitch actuator, as the deck), with the reduced model's pitch
  limits and rate limit.

With ``--reduced`` the same controller runs on the reduced model instead (``run_campaign`` without
``plant``: its own rotor-effective wind of seed 0, 19 m/s), no log.

E.g. ``... act10`` (q_Δ = 10) or ``... spd1.0081`` (ROSCO's speed filter).
"""
from __future__ import annotations

import argparse
import json
import re
import time
from dataclasses import replace
from itertools import pairwise
from pathlib import Path

import numpy as np
from openfast_table3 import openfast_model
from scipy import signal

from specdesign import validate
from specdesign.export import forwarded
from specdesign.mpc import QuadraticMPC
from specdesign.openfast import iea15mw_monopile
from specdesign.turbine import iea15mw

#: The call interval (s), ServoDyn's DLL_DT.
DT = 0.02
#: Command-rate spectrum bands (rad/s) printed.
BANDS = (0.0, 1.5, 3.0, 5.0, 8.0, 12.0, 31.4)
#: The campaign's indicators printed.
INDICATORS = ("tower_del", "blade_del", "gen_speed_sd", "mean_power", "pitch_sd", "pitch_rate_sd", "pitch_travel",
              "rate_limit_time")


def openfast_linear_model(deck, model, **kwargs):
    """Table 3's design model, OpenFAST's linearisations of ``deck`` (:func:`openfast_table3.openfast_model`,
    read from ``linearize_deck``'s cache; ``kwargs`` go to it, e.g. ``blade_moments=True``), with
    ``model``'s pitch limits and rate limit, which a linearisation does not carry: the model the
    ``oflin`` MPC is built on."""
    return replace(openfast_model(deck, **kwargs), pitch_min=model.pitch_min, pitch_max=model.pitch_max,
                   pitch_rate_limit=model.pitch_rate_limit)


class Logged:
    """A controller behind measurement filters, logging every call (a debugging wrapper, not for campaigns).

    Parameters
    ----------
    inner : callable
        The controller (the simulator's contract).
    log : str
        File written from ``start``: a JSON header, then ``[t, y as received, filtered signals, command]``
        per call.
    filters : dict
        Signal → ``(b, a)`` discrete filter at the call interval, started at steady state on the
        first sample.
    """

    def __init__(self, inner, log, filters):
        self.inner, self.log, self.filters = inner, str(log), dict(filters)
        self.name = inner.name

    @property
    def ts(self):
        return self.inner.ts

    def start(self, dt, wind, pitch, torque):
        self._zi = {}
        Path(self.log).write_text(json.dumps({"dt": dt, "wind": float(wind[0]), "pitch": float(pitch[0])}) + "\n")
        self.inner.start(dt, wind, pitch, torque)

    def __call__(self, t, y):
        seen = dict(y)
        for k, (b, a) in self.filters.items():
            x = float(y[k][0])
            if k not in self._zi:
                self._zi[k] = signal.lfilter_zi(b, a) * x
            out, self._zi[k] = signal.lfilter(b, a, [x], zi=self._zi[k])
            seen[k] = np.array([out[0]])
        cmd = self.inner(t, seen)
        with open(self.log, "a") as f:  # no handle kept: the server's copy of the controller is never closed
            f.write(json.dumps([t, {k: float(v[0]) for k, v in y.items()},
                                {k: float(seen[k][0]) for k in self.filters}, float(np.ravel(cmd)[0])]) + "\n")
        return cmd


def lowpass2(corner, damping, dt):
    """Second-order low-pass, Tustin at dt (ROSCO's SecLPFilter): (b, a)."""
    return signal.bilinear([corner**2], [1.0, 2 * damping * corner, corner**2], fs=1 / dt)


def controllers_of(variant, model, deck, log):
    """The campaign's controllers dict of a variant."""
    if variant == "rosco":
        return {"ROSCO": deck.fst.with_name(deck.name + "_DISCON.IN")}
    kw, filters, mdl = {}, {}, model
    for tag, key in (("spd", "gen_speed"), ("acc", "tower_top_acc")):
        m = re.search(tag + r"([0-9.]+)", variant)
        if m:
            filters[key] = lowpass2(float(m.group(1)), 0.7, DT)
    if "noacc" in variant:
        kw["measured"] = ("gen_speed", "pitch")
    for tag, key in (("qw", "speed_weight"), ("act", "activity_weight")):
        m = re.search(tag + r"([0-9.]+)", variant)
        if m:
            kw[key] = float(m.group(1))
    m = re.search(r"wa([0-9.]+)", variant)
    if m:
        mdl = replace(model, actuator_omega=float(m.group(1)))
    if "oflin" in variant:
        mdl = openfast_linear_model(deck, model)
        kw["wind_speeds"] = mdl.wind_speeds
    ctl = Logged(QuadraticMPC(mdl, ts=0.1, **kw), log, filters)
    return {"MPC_" + variant: forwarded(ctl, dt=DT, model=model, pitch_rate_limit=model.pitch_rate_limit)}


def command_rate_bands(log, transient, rate_limit):
    """(rate SD rad/s, fraction at the limit, share of the rate's variance per band) of the 0.1 s command."""
    rec = [json.loads(line) for line in Path(log).read_text().splitlines()[1:]]
    t = np.array([r[0] for r in rec])
    u = np.array([r[3] for r in rec])[t >= transient][::5]  # the MPC's samples (ts = 5 calls)
    rate = np.diff(u) / 0.1
    f, p = signal.welch(rate - rate.mean(), fs=10.0, nperseg=rate.size // 2)
    w = 2 * np.pi * f
    share = [np.sum(p[(w >= a) & (w < b)]) / np.sum(p) for a, b in pairwise(BANDS)]
    return rate.std(), np.mean(np.abs(rate) > 0.99 * rate_limit), share


def route_check(camp, log, transient):
    """The server's measurements against OpenFAST's outputs of the same run, at the 0.1 s output instants."""
    rec = [json.loads(line) for line in Path(log).read_text().splitlines()[1:]]
    t = np.array([r[0] for r in rec])
    y = {k: np.array([r[1][k] for r in rec]) for k in rec[0][1]}
    series = next(iter(camp.series.values()))
    out = {k: np.ravel(v) for k, v in series.outputs.items()}
    idx = np.searchsorted(np.round(t, 6), np.round(transient + np.asarray(series.time), 6))
    for k in ("gen_speed", "pitch", "power"):
        for lag in (0, 1):  # calls: the pitch measured is the actuator's output of the previous step
            a, b = y[k][idx + lag], out[k]
            print(f"  route: {k:10s} lag {lag} call(s): mean ratio {np.mean(a / b):.5f}, RMS difference "
                  f"{100 * np.sqrt(np.mean((a - b) ** 2)) / b.std():.1f} % of its SD")
    acc = y["tower_top_acc"][idx]
    bb, aa = signal.butter(2, [0.8 / (2 * np.pi), 1.4 / (2 * np.pi)], btype="band", fs=10.0)
    r = np.corrcoef(signal.filtfilt(bb, aa, acc), signal.filtfilt(bb, aa, out["tower_base_my"]))[0, 1]
    print(f"  route: tower-top acceleration mean {acc.mean():.4f} m/s², SD {acc.std():.3f} m/s²; against the "
          f"tower-base moment in 0.8-1.4 rad/s: correlation {r:.2f}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("variant")
    ap.add_argument("--duration", type=float, default=40.0)
    ap.add_argument("--transient", type=float, default=20.0)
    ap.add_argument("--store", default="/tmp/specdesign_openfast_variants")
    ap.add_argument("--reduced", action="store_true", help="run on the reduced model instead of OpenFAST")
    args = ap.parse_args()
    model, deck = iea15mw(), iea15mw_monopile()
    store = Path(args.store)
    store.mkdir(parents=True, exist_ok=True)
    log = store / f"{args.variant}{'_reduced' if args.reduced else ''}.log"
    controllers = controllers_of(args.variant, model, deck, log)
    t0 = time.perf_counter()
    if args.reduced:
        camp = validate.run_campaign(controllers, [19.0], [0], duration=args.duration, transient=args.transient,
                                     progress=False)
    else:
        camp = validate.run_campaign(controllers, [19.0], [0], plant=deck, duration=args.duration,
                                     transient=args.transient, store=store / args.variant, record_dt=0.1,
                                     keep_series=True, openfast={"processes": 1, "nice": 10}, progress=False)
    print(f"{args.variant}: {args.duration:g} s after {args.transient:g} s, 19 m/s, seed 0, "
          f"{'reduced model' if args.reduced else 'OpenFAST'}, wall {time.perf_counter() - t0:.0f} s, unstable "
          f"{bool(camp.unstable[0, 0])}")
    for k in INDICATORS:
        print(f"  {k:16s} {camp.values[k][0, 0, 0]:.4g}")
    if args.variant != "rosco" and not args.reduced and log.exists():
        sd, limit, share = command_rate_bands(log, args.transient, model.pitch_rate_limit)
        print(f"  command (0.1 s samples): rate SD {sd:.4g} rad/s, at the limit {100 * limit:.0f} %; share of the "
              "rate's variance per band (rad/s): " + ", ".join(f"{a:g}-{b:g} {100 * s:.0f} %"
                                                               for a, b, s in zip(BANDS[:-1], BANDS[1:], share)))
        route_check(camp, log, args.transient)


if __name__ == "__main__":
    main()
