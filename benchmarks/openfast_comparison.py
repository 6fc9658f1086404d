"""Issue 31's comparison in OpenFAST: ROSCO, ROSCO with its tower damper, the QFT+ATD designs and
the quadratic MPC whose internal model is OpenFAST's linearisation of the deck, at 2 speeds × 4
seeds × 600 s by default, against both baselines with paired SEs.

    nohup nice -n 10 python benchmarks/openfast_comparison.py --processes 2 > comparison.log 2>&1 &
    python benchmarks/openfast_comparison.py --speeds 19 --seeds 1 --duration 60 --transient 20 --out /tmp/smoke  # a smoke run (its own store: other settings)
    python benchmarks/openfast_comparison.py --rule-only    # the MPC's activity weight by its rule, no run

The shipped IEA 15 MW monopile deck with TurbSim winds (IEC Kaimal NTM class B), every controller
on the same seeds, ``run_campaign(..., plant=deck)``; resumable: every finished run is kept in
``--out``/runs (a folder per run) and a second call runs only what is missing. ``--out`` is by
default Table 3's store (``openfast_table3.STORE``, in the repository): the ROSCO and QFT+ATD runs that
``openfast_table3.py --plant openfast`` made on the same seeds are found there (by their
libraries' and parameter files' digests and the run settings) and not run again. The controllers:

- ``ROSCO``: ROSCO's compiled DISCON with the deck's DISCON.IN (its tower damper off, as shipped);
- ``ROSCO+TD``: the same with ROSCO's fore-aft tower damper on (``TD_Mode = 1``, ``FA_KI`` by the
  rule of ``benchmarks/openfast_table3.py``'s :func:`rosco_td_discon`);
- ``ROSCO+TD+3P``: ROSCO+TD with ROSCO's own notch filter at 3P (``F_GenSpdNotch_N``,
  ``F_TwrTopNotch_N``), the filter QFT+ATD+3P is tuned with (``openfast_table3.rosco_notch_values``):
  ROSCO's answer to that design. ROSCO 2.10.6 notches the generator speed with it, not the tower
  damper's input (its tower-top notch filters the floating feedback's signal only);
- ``QFT+ATD``: the paper's structure (PI + notch + low-pass and a tower damper on the tower-top
  velocity) designed per speed to the DEL target on OpenFAST's linearisations of the deck (the
  model the MPCs below predict with: both sides know the plant equally) and exported as a DISCON
  library, exactly as ``openfast_table3.py --plant openfast`` makes and exports it (its functions
  are called), so these are Table 3's runs;
- ``QFT+ATD+3P``: the same design with a notch at 3P on both measurements
  (``qft.three_p_notch``, tuned with it: ``design_qft(..., measurement_filter=...)``), which keeps
  the rotational sampling's 3P out of the pitch (docs/openfast.md, the pitch's band table);
- ``QFT+ATD+3P+LP``: the same with a second-order low-pass at ``openfast_table3.ROLLOFF`` rad/s
  on the measurements too (``qft.three_p_notch(model) * qft.rolloff(ROLLOFF)``), for what lies
  above 3P;
- ``MPC-OFlin``: :class:`specdesign.mpc.QuadraticMPC` (ts = 0.1 s, horizon 5 s, the class's weights)
  whose prediction model and LPV Kalman filter are OpenFAST's linearisations of the deck at
  15-25 m/s (:func:`openfast_forward_variants.openfast_linear_model`; no pitch actuator, as the
  deck; the operating point estimated from its own wind estimate, never told the mean wind),
  forwarded to Python at DLL_DT = 0.02 s with the turbine's pitch-rate limit;
- ``MPC-OFlin-rule``: the same with the pitch-activity weight q_Δ chosen by :func:`activity_weight_rule`
  on that model (docs/openfast.md, "The MPC on OpenFAST's linearisation");
- ``excursion MPC-OFlin-rule``: :class:`specdesign.mpc.HealthMPC` with the reduced-model
  comparison's excursion penalty (``health_weight`` = 10, the class's T_s = 0.2 s and 6 s horizon)
  and the rule's q_Δ (the rule's loop gain is the quadratic MPC's law; the excursion term only
  adds to its cost), on the same linearisations made with the blades' collective out-of-plane root
  moment (``linearize_deck(..., blade_moments=True)``: ``blade_root_my``, RootMyc1-3), which it
  predicts and reads from avrSWAP(30-32);
- ``health-aware MPC-OFlin-rule``: :func:`specdesign.mpc.health_aware_mpc` (seed 002's
  accumulated-moment term, ``stress_weight`` = 30, which derates), the same model and q_Δ;
- ``economic MPC-OFlin-rule``: :class:`specdesign.mpc.EconomicMPC` (seed 000's Eq. 4 surrogate,
  T_s = 0.2 s, N = 50: the reduced-model comparison's) on the quadratic MPC's model and the rule's
  q_Δ, its tower-base term fitted (:func:`specdesign.mpc.fatigue_terms_from_records`, 10 s
  windows, priced relative) on ROSCO's OpenFAST records in Table 3's store at
  :data:`ECON_FIT_SPEEDS` (:func:`economic_terms`: no evaluated wind in the fit); the blade term
  of the reduced-model comparison is left out: the records keep blade 1's root moment
  (RootMyb1), not the collective out-of-plane moment (RootMyc) the linearisation predicts;
- ``H∞``: :func:`specdesign.hinf.design_hinf` at the speed with its defaults (the certified pair
  for the DEL target, pitch only, under the high-frequency gain bound: the reduced-model
  comparison's H∞, docs/comparison.md) on OpenFAST's linearisations, exported as QFT+ATD is;
- ``H∞+ATD``: ``design_hinf`` on exactly the specifications the QFT+ATD design met
  (:func:`specdesign.hinf.spec_from_qft`), generator speed and tower-top velocity measured (the
  paper's structure's sensors), exported the same way. On OpenFAST's linearisations at 17 and
  19 m/s this design's controller is unstable with its generator-speed integral action reversed
  and C_β 34-41 dB over the high-frequency gain bound (``design_hinf`` warns; docs/comparison.md):
  choose it explicitly to run it anyway.

The printed tables are ``benchmarks/openfast_report.py``'s: per speed and controller the paired
changes against ROSCO and against ROSCO+TD (tower-base and blade-root DEL, generator-speed SD,
mean power; jackknife SE over the paired seeds from two seeds up), the pitch-rate SD, pitch travel
and time at the rate limit, OpenFAST's CPU and wall time per run, and the tower-base moment's
variance by band.
"""
from __future__ import annotations

import functools
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))  # the sibling scripts whose functions are reused

from openfast_forward_variants import openfast_linear_model
from openfast_report import report
from openfast_table3 import (
    ROSCO_TD,
    ROSCO_TD_3P,
    STORE,
    STRUCTURES,
    campaign_arguments,
    designs,
    export_design,
    measurement_filter,
    openfast_model,
    rosco_td_discon,
)

from specdesign import hinf, turbine, validate
from specdesign.export import forwarded
from specdesign.mpc import (
    EconomicMPC,
    HealthMPC,
    QuadraticMPC,
    fatigue_terms_from_records,
    health_aware_mpc,
    loop_gain,
)
from specdesign.openfast import find_openfast, iea15mw_monopile

#: The activity weights the rule tries, smallest first (half decades from the class's 0.1).
RULE_GRID = (0.1, 0.3, 1.0, 3.0, 10.0, 30.0, 100.0)
#: The rule's requirements on the MPC's unconstrained loop on OpenFAST's linearisation, at every
#: linearised speed: modulus margin min|1 − L| ≥ 0.5 (|S| ≤ 2), and |L| ≤ 0.5 above 1.5 rad/s,
#: where the linearisation (the rotor, the foundation and the first tower fore-aft mode at
#: 1.07 rad/s; no blade modes, quasi-steady aerodynamics) is not OpenFAST's response to the pitch
#: (3P at 2.4 rad/s, the blades' first flap modes, unsteady aerodynamics: docs/openfast.md).
MODULUS_MARGIN, BAND, BAND_GAIN = 0.5, 1.5, 0.5
#: The wind speeds of the comparison (m/s): 19 m/s is the paper's and the demo's, where Table 3's
#: campaign also ran ROSCO's tower damper; 17 m/s the one below it.
SPEEDS = (17.0, 19.0)
#: The controllers the campaign runs, in the order it runs them at each speed.
#: The fixed-structure QFT designs a comparison can run (``openfast_table3.STRUCTURES``' keys).
FIXED = ("atd", "atd_3p", "atd_3p_lp")
CONTROLLERS = ("ROSCO", ROSCO_TD, ROSCO_TD_3P, *(STRUCTURES[st][0] for st in FIXED), "MPC-OFlin", "MPC-OFlin-rule",
               "excursion MPC-OFlin-rule", "health-aware MPC-OFlin-rule", "economic MPC-OFlin-rule", "H∞", "H∞+ATD")
#: Run only when named: H∞+ATD (unstable, sign-reversed on OpenFAST's linearisations) and the
#: roll-off variant (run at 19 m/s only: docs/openfast.md).
NOT_BY_DEFAULT = ("H∞+ATD", STRUCTURES["atd_3p_lp"][0])
#: The forwarded MPCs (built by :func:`mpcs`).
MPCS = ("MPC-OFlin", "MPC-OFlin-rule", "excursion MPC-OFlin-rule", "health-aware MPC-OFlin-rule",
        "economic MPC-OFlin-rule")
#: The blade-load MPCs' weights: the reduced-model comparison's (benchmarks/comparison.py).
EXCURSION_WEIGHT, STRESS_WEIGHT = 10.0, 30.0
#: The H∞ designs (name: export folder prefix in the store).
HINF = {"H∞": "export_hinf_", "H∞+ATD": "export_hinf_atd_"}
#: The sample time (s) and forwarding interval (s, ServoDyn's DLL_DT) of the MPCs.
TS, DT = 0.1, 0.02
#: The economic MPC's sample time (s) and horizon (steps): the reduced-model comparison's.
ECON_TS, ECON_HORIZON = 0.2, 50
#: The speeds (m/s) of ROSCO's OpenFAST runs whose kept records fit the economic MPC's tower term:
#: Table 3's that are not the comparison's (:data:`SPEEDS`), so that no evaluated wind is in the fit.
ECON_FIT_SPEEDS = (15.0, 21.0, 23.0, 25.0)


def economic_terms(runs) -> tuple:
    """The economic MPC's priced tower-base term, fitted on the kept tower-base moment records of
    ROSCO's OpenFAST ``runs`` at :data:`ECON_FIT_SPEEDS` (Table 3's store: its seed-0 runs keep
    their series) in windows of its horizon (ECON_TS · ECON_HORIZON s), priced relative."""
    fit = [r for r in runs if r.controller == "ROSCO" and r.wind_speed in ECON_FIT_SPEEDS and "tower_base_my" in r.series]
    if not fit:
        raise SystemExit(f"the economic MPC's fit needs ROSCO's kept records at {ECON_FIT_SPEEDS} m/s in {STORE}: "
                         "run openfast_table3.py --plant openfast first")
    dts = {r.meta["settings"]["record_dt"] for r in fit}
    if len(dts) != 1:
        raise SystemExit(f"ROSCO's kept records are sampled at several intervals {sorted(dts)} s")
    terms = fatigue_terms_from_records({"tower_base_my": [r.series["tower_base_my"] for r in fit]}, dts.pop(),
                                       ECON_TS * ECON_HORIZON)
    for t in terms:
        print(f"economic MPC's {t.output} term on ROSCO's OpenFAST records at {', '.join(f'{v:g}' for v in ECON_FIT_SPEEDS)} "
              f"m/s: a = {t.fit.a:.2f}, b = {t.fit.b:.2f}, residual SD {t.fit.residual_std:.2f} (ln D)")
    return terms


def activity_weight_rule(lt, grid=RULE_GRID) -> tuple[float, list]:
    """The smallest q_Δ of ``grid`` whose unconstrained loop on ``lt`` meets :data:`MODULUS_MARGIN`
    and :data:`BAND_GAIN` above :data:`BAND` at every linearised speed (the last of the grid if none
    does), and the rows (q_Δ, speed m/s, min|1 − L|, max |L| above the band) it looked at."""
    w = np.linspace(0.01, np.pi / TS, 3000)  # rad/s, up to the sampled loop's Nyquist frequency
    rows = []
    for q in grid:
        mpc = QuadraticMPC(lt, ts=TS, activity_weight=q, wind_speeds=lt.wind_speeds)
        ok = True
        for v in lt.wind_speeds:
            L = loop_gain(mpc, float(v), w)
            margin, band = float(np.abs(1 - L).min()), float(np.abs(L[w >= BAND]).max())
            rows.append((q, float(v), margin, band))
            ok &= margin >= MODULUS_MARGIN and band <= BAND_GAIN
        if ok:
            return q, rows
    return grid[-1], rows


def mpcs(lt, lt_blade, reduced, q_rule, terms, chosen=MPCS) -> dict:
    """The ``chosen`` forwarded MPCs on OpenFAST's linearisation: the quadratic MPC with the class's
    weights and with q_Δ by the rule (on ``lt``), the excursion and the health-aware MPC with q_Δ by
    the rule (on ``lt_blade``, the same linearisations with the blades' root moments; a callable
    giving it, called only when one of them is chosen), the economic MPC with q_Δ by the rule on
    ``lt`` priced by ``terms`` (a callable giving them, called only when it is chosen)."""
    made, lt_blade = {}, functools.cache(lt_blade)
    for label, q in (("MPC-OFlin", 0.1), ("MPC-OFlin-rule", q_rule)):
        made[label] = lambda q=q: QuadraticMPC(lt, ts=TS, activity_weight=q, wind_speeds=lt.wind_speeds,
                                               name=f"quadratic MPC on OpenFAST's linearisation, q_Δ = {q:g}")
    made["excursion MPC-OFlin-rule"] = lambda: HealthMPC(
        lt_blade(), health_weight=EXCURSION_WEIGHT, activity_weight=q_rule, wind_speeds=lt.wind_speeds,
        name=f"excursion MPC on OpenFAST's linearisation, q_Δ = {q_rule:g}")
    made["health-aware MPC-OFlin-rule"] = lambda: health_aware_mpc(
        lt_blade(), stress_weight=STRESS_WEIGHT, activity_weight=q_rule, wind_speeds=lt.wind_speeds,
        name=f"health-aware MPC on OpenFAST's linearisation, q_Δ = {q_rule:g}")
    made["economic MPC-OFlin-rule"] = lambda: EconomicMPC(
        lt, terms(), ts=ECON_TS, horizon=ECON_HORIZON, activity_weight=q_rule, wind_speeds=lt.wind_speeds,
        name=f"economic MPC on OpenFAST's linearisation, q_Δ = {q_rule:g}")
    return {label: forwarded(made[label](), dt=DT, model=reduced, pitch_rate_limit=reduced.pitch_rate_limit)
            for label in MPCS if label in chosen}


def hinf_designs(model, v, qft_atd, chosen) -> dict:
    """The chosen :data:`HINF` designs at ``v`` m/s on ``model``: ``H∞`` by ``design_hinf``'s
    defaults, ``H∞+ATD`` on the specifications ``qft_atd`` (the QFT+ATD design at ``v``) met."""
    out = {}
    if "H∞" in chosen:
        out["H∞"] = hinf.design_hinf(model, v)
    if "H∞+ATD" in chosen:
        out["H∞+ATD"] = hinf.design_hinf(model, v, spec=hinf.spec_from_qft(qft_atd),
                                         measurements=("gen_speed", "tower_top_vel"))
    for name, d in out.items():
        print(f"{name} at {v:g} m/s on OpenFAST's linearisation: {d.controller.nstates} states, promise "
              f"{d.promised_del_reduction:.1f} %, linear prediction {d.predicted_del_reduction:.1f} % tower DEL reduction, "
              f"tower mode ζ {d.tower_damping_ratio:.3f} (ROSCO {d.baseline_tower_damping_ratio:.3f}), peak sensitivity "
              f"at the actuator {d.peak_sensitivity:.2f}, C_β {d.hf_excess_db:+.1f} dB against the high-frequency gain "
              f"bound, controller's unstable poles {list(np.round(d.controller_unstable_poles, 3)) or 'none'}, "
              f"generator-speed integral action {'as ROSCO' if d.speed_integral_sign > 0 else 'REVERSED'}", flush=True)
    return out


def main() -> None:
    ap = campaign_arguments(__doc__.split("\n")[0], ",".join(f"{v:g}" for v in SPEEDS))
    ap.add_argument("--out", default=str(STORE),
                    help="store (default: Table 3's, whose ROSCO and QFT+ATD runs are reused)")
    ap.add_argument("--rule-only", action="store_true", help="print the MPC's activity-weight rule and stop")
    ap.add_argument("--controllers", default=",".join(c for c in CONTROLLERS if c not in NOT_BY_DEFAULT),
                    help="the controllers to run, comma-separated (default: all but H∞+ATD and QFT+ATD+3P+LP, "
                         "%(default)s; choose from "
                         f"{', '.join(CONTROLLERS)}); the report covers every run in the store at these speeds")
    args = ap.parse_args()
    chosen = [c.strip() for c in args.controllers.split(",") if c.strip()]
    unknown = sorted(set(chosen) - set(CONTROLLERS))
    if unknown or not chosen:
        ap.error(f"--controllers: unknown {unknown or 'none given'}; choose from {', '.join(CONTROLLERS)}")
    speeds = [float(x) for x in args.speeds.split(",")]
    t0 = time.monotonic()
    deck, reduced = iea15mw_monopile(), turbine.iea15mw()
    mpc_names = set(MPCS) & set(chosen)
    if mpc_names or args.rule_only:
        lt = openfast_linear_model(deck, reduced)
        q_rule, rows = activity_weight_rule(lt)
        print(f"activity weight by the rule (modulus margin >= {MODULUS_MARGIN:g}, |L| <= {BAND_GAIN:g} above {BAND:g} "
              f"rad/s at every linearised speed): q_Δ = {q_rule:g}")
        print("| q_Δ | wind (m/s) | min abs(1 − L) | max abs(L) above the band |\n|---|---|---|---|")
        for q, v, margin, band in rows:
            print(f"| {q:g} | {v:g} | {margin:.2f} | {band:.2f} |")
        if args.rule_only:
            return
    out = Path(args.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    install = find_openfast()
    discon_in = deck.fst.with_name(f"{deck.name}_DISCON.IN")
    # Table 3's designs: on OpenFAST's linearisations, named and exported as openfast_table3.py does
    # (only what a chosen controller needs is designed, exported or written: a library another
    # campaign's runs have loaded is never touched for nothing)
    fixed = [st for st in FIXED if STRUCTURES[st][0] in chosen or (st == "atd" and "H∞+ATD" in chosen)]
    design_model = openfast_model(deck, speeds) if fixed or {"H∞", ROSCO_TD_3P} & set(chosen) else None
    made = {st: designs(design_model, speeds, args.target, st) for st in fixed}
    # the blade-load MPCs predict the blades' root moment: the same linearisations with it (a
    # separate cache entry, so the model the quadratic MPCs' stored runs were made with stays theirs)
    forwarded_mpcs = mpcs(lt, lambda: openfast_linear_model(deck, reduced, blade_moments=True), reduced, q_rule,
                          lambda: economic_terms(validate.read_openfast_runs(STORE / "runs")), chosen) if mpc_names else {}
    # ROSCO's parameter files are the same at every speed: written once
    roscos = {"ROSCO": lambda: discon_in, ROSCO_TD: lambda: rosco_td_discon(discon_in, out),
              ROSCO_TD_3P: lambda: rosco_td_discon(discon_in, out, measurement_filter(design_model, "atd_3p"))}
    roscos = {name: make() for name, make in roscos.items() if name in chosen}
    for v in speeds:
        controllers = {name: c for name, c in forwarded_mpcs.items() if name in chosen} | roscos
        for st in fixed:
            label, prefix = STRUCTURES[st]
            if label in chosen:
                controllers[label] = export_design(made[st][v]["design"], out / f"{prefix}{v:g}", f"{label} {v:g} m/s",
                                                   reduced)
        for name, d in hinf_designs(design_model, v, made.get("atd", {}).get(v, {}).get("design"), chosen).items():
            controllers[name] = export_design(d, out / f"{HINF[name]}{v:g}", f"{name} {v:g} m/s", reduced)
        controllers = {name: controllers[name] for name in CONTROLLERS if name in controllers}  # the run order
        validate.run_campaign(controllers, [v], args.seeds, plant=deck, duration=args.duration,
                              transient=args.transient, store=out / "runs", progress=True,
                              openfast={"processes": args.processes, "nice": args.nice, "install": install})
    runs = validate.read_openfast_runs(out / "runs")
    runs = [r for r in runs if r.wind_speed in speeds and r.meta["settings"]["duration"] == args.duration
            and r.meta["settings"]["transient"] == args.transient]
    print(f"\nOpenFAST v{install.version}, {len(speeds)} speeds × {args.seeds} seeds × "
          f"{args.duration + args.transient:g} s: {(time.monotonic() - t0) / 60:.1f} min wall\n")
    print(report(out / "runs", runs, baseline="ROSCO"))


if __name__ == "__main__":
    main()
