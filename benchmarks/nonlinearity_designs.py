"""Issue 7, design variants: is the nonlinear deviation a property of one QFT design or of
load reduction itself?  (docs/nonlinearity.md, section (h))

The acceptance compares the linear prediction of the tower-base DEL reduction (Dirlik on
|T|²S_W) with rainflow on the nonlinear simulation. With the default QFT designs rainflow
shows ≈ 2 pp more reduction than predicted, and sections A-(e) of docs/nonlinearity.md trace
that to the aerodynamic Ω×β curvature. Here the *design* is varied while the evaluation stays
fixed, to see whether any design freedom removes the deviation:

(i)   target     DEL-reduction target 20 / 25 / 30 / 35 % at 19 m/s (``design_qft(..., target)``).
(ii)  split      "nonlinear-consistent" load split: the tuner's cost gets an extra penalty
                 NW·(log ρ_low − a·log ρ_total)², a = 0.5, NW = 1000, where ρ is the design's
                 linear tower-base-moment variance (|T|²S_W) divided by ROSCO's, in total and
                 below 0.3 rad/s. Reason: the nonlinear extra variance lives below 0.3 rad/s
                 and scales as the square of the linear low-band variance, so the relative
                 nonlinear growth of the design is (ρ_low²/ρ_total) × ROSCO's; ρ_low = ρ_total^½
                 makes it equal to ROSCO's, and the deviation should vanish.
(iii) cost       two other tuning costs: penalise the generator-speed SD *change* 10·(gs − 1)²
                 instead of 0.1·gs², or pin the controller's low-frequency gain to ROSCO's
                 (100·Σ log²|C/C_ROSCO| at 0.005, 0.01, 0.02, 0.03 rad/s).

Every design is compared with ROSCO (tower damping off) on the same seeds, fixed controllers,
600 s records after a 60 s transient, dt = 0.02 s, m = 4. Each row splits the deviation
(rainflow, nonlinear − prediction) into
    spectral part  = rainflow on the linearised model − prediction (Dirlik's bias),
    nonlinear part = rainflow on the nonlinear model − rainflow on the linearised model,
with jackknife SEs over paired seeds, and also prints the nonlinear part the scaling law
predicts from the linear ρ's and ROSCO's measured nonlinear/linear DEL ratio g_R:
    g_D − 1 ≈ (g_R − 1)·ρ_low²/ρ_total,   NL part ≈ 100·(1 − r_lin)·(1 − g_D/g_R).

Seeds are 1000, 1001, … (``--seeds`` of them): disjoint from the 0..199 used by the tests and
benchmarks/acceptance.py, so this is an independent sample.

The cost changes are experiments, not library features: they patch
``TuningProblem.objective`` (:mod:`specdesign.qft.tuner`, with ``controller_polys`` of
:mod:`specdesign.qft.structure` and the private ``TuningProblem._t``) inside a context manager
that restores it, and nothing outside this script sees them.

Run:   python benchmarks/nonlinearity_designs.py                 # 60 seeds, 15 19 25 m/s (≈ 7 min, 2 cores)
       python benchmarks/nonlinearity_designs.py --quick         # 8 seeds, 19 m/s, smoke test (≈ 1 min)
       python benchmarks/nonlinearity_designs.py --parts split --speeds 19
"""
from __future__ import annotations

import argparse
import contextlib
import time
import warnings

import numpy as np

from specdesign import qft, validate
from specdesign.closedloop import siso_response
from specdesign.qft.structure import controller_polys
from specdesign.qft.tuner import TuningProblem
from specdesign.simulate import scheduled
from specdesign.turbine import iea15mw, rosco_baseline

M = 4.0
DUR, TRANS, DT, RDT = 600.0, 60.0, 0.02, 0.1  # the campaign defaults, spelled out for the linear runs
LOW_BAND = 0.3  # rad/s: the rotor-speed loop band, where the nonlinear extra load sits (doc section A)
SEED0 = 1000


# ----------------------------------------------------------------------------- cost patches
@contextlib.contextmanager
def extra_cost(term):
    """Add ``term(problem, x)`` to the QFT tuner's objective while the block runs.

    Both the exploration's penalty cost and the polish use ``TuningProblem.objective``; the cost's
    barrier values (≥ 1e10: unstable or not evaluable) come before the objective, so the extra
    term can never trade stability for anything.
    """
    orig = TuningProblem.objective

    def objective(self, x):
        extra = term(self, x)
        return float(orig(self, x) + extra) if np.isfinite(extra) else 1e12

    TuningProblem.objective = objective
    try:
        yield
    finally:
        TuningProblem.objective = orig


def _tuner_rho(prob, x):
    """(ρ_total, ρ_low) of the candidate x on the tuner's grid, nominal plant (linear, |T|²S_W)."""
    nb, db, na, da = controller_polys(x)
    s = 1j * prob.wf[:, None]
    c = np.polyval(nb, s) / np.polyval(db, s)
    k = np.polyval(na, s) / np.polyval(da, s)
    low = prob.wf < LOW_BAND
    if "_nl_rosco_var" not in prob.__dict__:  # ROSCO's variances: once per design problem
        c0 = siso_response(prob.rosco[prob.nom], prob.wf)[:, None]
        p0 = np.abs(prob._t(prob.Rf, c0, 0.0, "tower_base_my")[:, prob.nom]) ** 2 * prob.S
        prob._nl_rosco_var = (np.trapezoid(p0, prob.wf), np.trapezoid(p0[low], prob.wf[low]))
    p = np.abs(prob._t(prob.Rf, c, k, "tower_base_my")[:, prob.nom]) ** 2 * prob.S
    v_tot, v_low = prob._nl_rosco_var
    return np.trapezoid(p, prob.wf) / v_tot, np.trapezoid(p[low], prob.wf[low]) / v_low


def split_penalty(nw=1000.0, a=0.5):
    """NW·(log ρ_low − a·log ρ_total)²: pushes the design towards ρ_low = ρ_total^a."""
    def term(prob, x):
        rt, rl = _tuner_rho(prob, x)
        return nw * (np.log(rl) - a * np.log(rt)) ** 2
    return term


def speed_change_cost(w=10.0):
    """Replace the default 0.1·gs² by w·(gs − 1)² (gs = gen-speed SD ratio vs ROSCO): penalise a
    *change* of the speed regulation rather than rewarding a smaller SD."""
    def term(prob, x):
        gs = prob.performance(x)[2]
        return w * (gs - 1.0) ** 2 - 0.1 * gs ** 2
    return term


def dc_gain_cost(w=100.0, omegas=(0.005, 0.01, 0.02, 0.03)):
    """w·Σ log²|C_β/C_ROSCO| at low ω: keep ROSCO's slow speed regulation (the Ω, β excursions
    that drive the Ω×β curvature) and let the design act only above it."""
    om = np.asarray(omegas, float)

    def term(prob, x):
        nb, db, _, _ = controller_polys(x)
        c = np.polyval(nb, 1j * om) / np.polyval(db, 1j * om)
        return w * float(np.sum(np.log(np.abs(c / siso_response(prob.rosco[prob.nom], om))) ** 2))
    return term


# ----------------------------------------------------------------------------- evaluation
def _variances(model, c, v):
    """(total, low-band) variance of the linear tower-base moment, |T|²S_W on the prediction grid."""
    p = validate.linear_prediction(model, c, v, m=M, omega=validate.prediction_grid(DUR), record_length=DUR)
    low = p.omega < LOW_BAND
    return np.trapezoid(p.psd, p.omega), np.trapezoid(p.psd[low], p.omega[low])


def evaluate(model, d, seeds):
    """Prediction, nonlinear and linearised-model rainflow of design d vs ROSCO on the same seeds."""
    v = d.wind_speed
    ctrls = {"ROSCO": rosco_baseline(model, v),
             "QFT": scheduled(model, {v: d.pitch_controller}, atd={v: d.atd_controller}, name="QFT")}
    # the linearised twin runs the linearised model on exactly the campaign's wind series
    camp = validate.run_campaign(ctrls, [v], seeds, model=model, duration=DUR, dt=DT, record_dt=RDT,
                                 transient=TRANS, m=M, linear_twin=True, progress=False)
    acc = validate.acceptance(camp, "QFT", "ROSCO")
    r_lin = float(acc.rainflow_linear[0])

    def pooled(values, n):  # seed-pooled DEL (damage average), as validate pools it
        return float(np.mean(values["tower_del"][camp.index(n)][0] ** M) ** (1 / M))

    g = {n: pooled(camp.values, n) / pooled(camp.linear_values, n) for n in ctrls}
    (vt_q, vl_q), (vt_r, vl_r) = _variances(model, ctrls["QFT"], v), _variances(model, ctrls["ROSCO"], v)
    rho_t, rho_l = vt_q / vt_r, vl_q / vl_r
    g_law = 1 + (g["ROSCO"] - 1) * rho_l ** 2 / rho_t
    return dict(v=v, target=d.target_reduction, pred=float(acc.predicted[0]), rf=float(acc.rainflow[0]),
                dev=float(acc.deviation[0]), se=float(acc.se[0]), spec=float(acc.spectral_deviation[0]),
                spec_se=float(acc.se_spectral[0]), nl=float(acc.nonlinear_deviation[0]), nl_se=float(acc.se_nonlinear[0]),
                nl_law=100 * (1 - r_lin / 100) * (1 - g_law / g["ROSCO"]),
                g_rosco=g["ROSCO"], g_qft=g["QFT"], rho_low=rho_l, rho_tot=rho_t,
                gs=d.gen_speed_sd_change, rate=d.pitch_rate_sd_change, ok=d.success)


HEADER = ("| variant | speed | target | predicted | rainflow | deviation | spectral part | nonlinear part "
          "| NL part, scaling law | NL/L DEL ROSCO, design | ρ_low | ρ_total | gen-speed SD | pitch-rate SD | specs met |\n"
          "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")


def row(name, r):
    return (f"| {name} | {r['v']:g} m/s | {r['target']:g} % | {r['pred']:.2f} % | {r['rf']:.2f} % "
            f"| {r['dev']:+.2f} ± {r['se']:.2f} pp | {r['spec']:+.2f} ± {r['spec_se']:.2f} pp "
            f"| {r['nl']:+.2f} ± {r['nl_se']:.2f} pp | {r['nl_law']:+.2f} pp | {r['g_rosco']:.3f}, {r['g_qft']:.3f} "
            f"| {r['rho_low']:.3f} | {r['rho_tot']:.3f} | {r['gs']:+.1f} % | {r['rate']:+.1f} % "
            f"| {'yes' if r['ok'] else 'no'} |")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seeds", type=int, default=60, help="paired seeds, numbered from 1000 (default 60)")
    ap.add_argument("--speeds", type=float, nargs="+", default=[15.0, 19.0, 25.0], help="wind speeds of (ii), (iii), m/s")
    ap.add_argument("--targets", type=float, nargs="+", default=[20.0, 25.0, 30.0, 35.0], help="targets of (i), %%")
    ap.add_argument("--target-speed", type=float, default=19.0, help="wind speed of (i), m/s")
    ap.add_argument("--parts", nargs="+", default=["target", "split", "cost"], choices=["target", "split", "cost"])
    ap.add_argument("--quick", action="store_true", help="8 seeds, 19 m/s, targets 20/25 %%: a smoke test")
    args = ap.parse_args()
    if args.quick:
        args.seeds, args.speeds, args.targets = 8, [19.0], [20.0, 25.0]
    # design_qft warns on a missed spec or a low tower-mode damping: the table reports d.success; others still show
    warnings.filterwarnings("ignore", message="design_qft")
    model = iea15mw()
    seeds = np.arange(SEED0, SEED0 + args.seeds)
    print(f"seeds {seeds[0]}..{seeds[-1]} ({seeds.size}), {DUR:g} s records, dt {DT:g} s, m = {M:g}", flush=True)

    # (variant name, wind speed, target, cost term or None); the default design is shared by the parts
    jobs = []
    if "target" in args.parts:
        jobs += [("default" if t == 25.0 else f"target {t:g} %", args.target_speed, t, None) for t in args.targets]
    if "split" in args.parts or "cost" in args.parts:
        jobs += [("default", v, 25.0, None) for v in args.speeds]
    if "split" in args.parts:
        jobs += [("split a=0.5, NW=1000", v, 25.0, split_penalty(1000.0, 0.5)) for v in args.speeds]
    if "cost" in args.parts:
        jobs += [("cost 10·(gs−1)²", v, 25.0, speed_change_cost()) for v in args.speeds]
        jobs += [("cost DC gain = ROSCO", v, 25.0, dc_gain_cost()) for v in args.speeds]

    results, done = [], set()
    t_start = time.time()
    for name, v, target, term in jobs:
        if (name, v, target) in done:
            continue
        done.add((name, v, target))
        t0 = time.time()
        with extra_cost(term) if term is not None else contextlib.nullcontext():
            d = qft.design_qft(model, v, spec=qft.spec_notch(target))
        t1 = time.time()
        r = evaluate(model, d, seeds)
        results.append((name, r))
        print(row(name, r), f"[design {t1 - t0:.0f} s, simulation {time.time() - t1:.0f} s]", flush=True)

    print(f"\ntotal {time.time() - t_start:.0f} s\n")
    sections = [("(i) target at %g m/s" % args.target_speed, lambda n, r: r["v"] == args.target_speed and not n.startswith(("split", "cost"))),
                ("(ii) nonlinear-consistent split vs default", lambda n, r: n == "default" or n.startswith("split")),
                ("(iii) other tuning costs vs default", lambda n, r: n == "default" or n.startswith("cost"))]
    for title, keep in sections:
        rows = [(n, r) for n, r in results if keep(n, r)]
        if title.startswith("(i) "):
            rows.sort(key=lambda nr: nr[1]["target"])
        else:
            rows.sort(key=lambda nr: (nr[1]["v"], nr[0] != "default"))
            rows = [(n, r) for n, r in rows if n != "default" or r["target"] == 25.0]
            if not any(n != "default" for n, _ in rows):
                continue
        seen, out = set(), []
        for n, r in rows:
            if (n, r["v"], r["target"]) not in seen:
                seen.add((n, r["v"], r["target"]))
                out.append(row(n, r))
        if out:
            print(title + "\n\n" + HEADER + "\n" + "\n".join(out) + "\n")


if __name__ == "__main__":
    main()
