"""OpenFAST's response to the pitch command against the reduced model's, and QuadraticMPC's loop gain
on each: why the MPC rides the rate limit in OpenFAST (docs/openfast.md).

Run: python benchmarks/openfast_pitch_sweep.py [--store FILE] [--activity-weights 0.1,1,10]

A multisine pitch command (9 sines of 1.2e-3 rad, 0.63-6.28 rad/s, each a whole number of periods
in 40 s; random phases, seed 0; the sum's largest rate stays under the rate limit) about the
19 m/s trim, steady wind (the deck's shear), the shipped IEA 15 MW monopile deck with its sea, sent
through the forwarding library (DLL_DT = 0.02 s) by a Python controller that plays it open loop;
55 s, one OpenFAST process (niced). Each output's phasor at each frequency is fitted by least
squares over 15-55 s (sines, cosines, offset and drift), divided by the command's: the frequency
response H(jω) of the command to the generator speed, the tower-top acceleration and the measured
pitch (what the MPC's Kalman filter reads). Printed beside the reduced model's (``iea15mw().
linearize(19.0)``, pitch-command input), and the loop gain L(jω) = C(jω)·H(jω) at the pitch
command, C the MPC's unconstrained control law at 19 m/s (its Kalman filter and the QP's
minimiser, a linear discrete system at ts = 0.1 s, with the hold of its command): the closed loop
is 1/(1 − L) (positive feedback as written: u = C y), so |1 − L| is the distance to instability.
The same beside OpenFAST's own linearisation of the deck (``linearize_deck``'s cache: the rotor,
the foundation and the first tower fore-aft mode, quasi-steady aerodynamics, no pitch actuator) and
for the MPC whose internal model it is (docs/openfast.md, "The MPC on OpenFAST's linearisation").
The record goes to --store (JSON) and is read back when there.
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
from openfast_forward_variants import openfast_linear_model

from specdesign.export import ForwardServer, forwarded
from specdesign.mpc import QuadraticMPC, unconstrained_law
from specdesign.openfast import iea15mw_monopile, run_case, write_case
from specdesign.turbine import iea15mw

#: Harmonics of 1/(40 s) excited: ω = 2πk/40 rad/s (0.63-6.28 rad/s; 3P at 19 m/s is 2.38 rad/s, k = 15.1, left out).
HARMONICS = np.array([4, 8, 12, 14, 17, 20, 24, 30, 40])
OMEGA = 2 * np.pi * HARMONICS / 40.0
#: Amplitude of each sine (rad): their rates sum to 0.032 rad/s, under the 0.0349 rad/s limit.
AMPLITUDE = 1.2e-3
PHASES = np.random.default_rng(0).uniform(0.0, 2 * np.pi, HARMONICS.size)
#: Simulated time (s) and the fitted window (s).
TMAX, WINDOW = 55.0, (15.0, 55.0)
DT = 0.02


class Multisine:
    """Open-loop pitch: the starting pitch plus the multisine, ramped in over 2-7 s."""

    name = "multisine"

    def start(self, dt, wind, pitch, torque):
        self.beta0 = float(pitch[0])

    def __call__(self, t, y):
        ramp = min(max((t - 2.0) / 5.0, 0.0), 1.0)
        return np.array([self.beta0 + ramp * AMPLITUDE * np.sum(np.sin(OMEGA * t + PHASES))])


def record(store: Path, model) -> list:
    """[(t, measurements, command), ...] of the run (read back from ``store`` when there)."""
    if store.exists():
        return json.loads(store.read_text())
    op = model.trim(19.0)
    fwd = forwarded(Multisine(), dt=DT, model=model, pitch_rate_limit=model.pitch_rate_limit)
    folder = store.with_suffix("")
    with ForwardServer(fwd, record=True) as srv:
        case = write_case(iea15mw_monopile(), folder, tmax=TMAX, wind_speed=19.0, library=fwd.library,
                          parameters=srv.write(store.with_suffix(".IN")), controller_dt=DT, dt_out=DT,
                          initial_pitch=op.pitch, initial_rotor_speed=op.rotor_speed)
        run_case(case, None, nice=10)
    srv.raise_error()
    rows = [(t, y, p) for t, y, p, _ in srv.records]
    store.write_text(json.dumps(rows))
    return rows


def phasors(t, x, blade_passing):
    """Complex amplitude of x at each OMEGA over WINDOW (x ≈ Im(Z e^{iωt}) + offset + drift), the
    blade-passing lines (3P, 6P at ``blade_passing`` rad/s: 6P is 0.04 rad/s from 4.71 rad/s) fitted beside."""
    sel = (t >= WINDOW[0] - 1e-9) & (t < WINDOW[1] - 1e-9)
    tt = t[sel]
    w = np.r_[OMEGA, blade_passing]
    X = np.column_stack([np.sin(np.outer(tt, w)), np.cos(np.outer(tt, w)), np.ones_like(tt), tt - tt.mean()])
    c = np.linalg.lstsq(X, x[sel], rcond=None)[0]
    return c[:OMEGA.size] + 1j * c[w.size:w.size + OMEGA.size]


def control_law(model, activity_weight):
    """C(jω) of QuadraticMPC at 19 m/s, unconstrained, from its measurements to its command (with the hold)."""
    mpc = QuadraticMPC(model, ts=0.1, operating_point="initial pitch", activity_weight=activity_weight)
    A, B, C, D = unconstrained_law(mpc, 19.0)

    def at(w):
        z = np.exp(1j * w * mpc.ts)
        hold = (1 - 1 / z) / (1j * w * mpc.ts)
        return (C @ np.linalg.solve(z * np.eye(A.shape[0]) - A, B) + D) * hold
    return mpc.measured, at


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--store", default="/tmp/specdesign_pitch_sweep/sweep.json")
    ap.add_argument("--activity-weights", default="0.1,1,10")
    args = ap.parse_args()
    store = Path(args.store)
    store.parent.mkdir(parents=True, exist_ok=True)
    model = iea15mw()
    rows = record(store, model)
    t = np.array([r[0] for r in rows])
    y = {k: np.array([r[1][k] for r in rows]) for k in rows[0][1]}
    inside = (t >= WINDOW[0]) & (t < WINDOW[1])
    bp = np.array([3.0, 6.0]) * np.mean(y["gen_speed"][inside])  # rotor speed (gearbox ratio 1)
    U = phasors(t, np.array([r[2] for r in rows]), bp)
    lin = openfast_linear_model(iea15mw_monopile(), model)  # OpenFAST's linearisation of the deck
    P, PL = model.linearize(19.0), lin.linearize(19.0)
    H = {}
    print("response to the pitch command: OpenFAST (multisine, steady 19 m/s) | reduced model | OpenFAST's "
          "linearisation; |H| and phase (deg)")
    for k in ("gen_speed", "tower_top_acc", "pitch"):
        H[k] = phasors(t, y[k], bp) / U
        print(k)
        for i, w in enumerate(OMEGA):
            p, pl = (S(1j * w)[S.output_labels.index(k), S.input_labels.index("pitch_cmd")] for S in (P, PL))
            print(f"  {w:5.2f} rad/s | {abs(H[k][i]):8.3g} {np.degrees(np.angle(H[k][i])):5.0f} | "
                  f"{abs(p):8.3g} {np.degrees(np.angle(p)):5.0f} | {abs(pl):8.3g} {np.degrees(np.angle(pl)):5.0f}")
    for internal, S in (("reduced model", P), ("OpenFAST's linearisation", PL)):
        for q in (float(x) for x in args.activity_weights.split(",")):
            measured, C = control_law(model if S is P else lin, q)
            print(f"QuadraticMPC on the {internal}, q_Δ = {q:g}: loop gain L = C·H, |L| phase (deg), |1 − L|: "
                  f"its model | OpenFAST")
            for i, w in enumerate(OMEGA):
                c = C(w)
                lr = c @ np.array([S(1j * w)[S.output_labels.index(o), S.input_labels.index("pitch_cmd")]
                                   for o in measured])
                lo = c @ np.array([H[o][i] for o in measured])
                print(f"  {w:5.2f} rad/s | {abs(lr):6.2f} {np.degrees(np.angle(lr)):5.0f} {abs(1 - lr):5.2f} | "
                      f"{abs(lo):6.2f} {np.degrees(np.angle(lo)):5.0f} {abs(1 - lo):5.2f}")


if __name__ == "__main__":
    main()
