"""The paper's Table 3 from OpenFAST: QFT designs at 15-25 m/s (by default the paper's structure,
PI + notch + low-pass and a tower damper, tuned to the DEL target; with ``--structure certificate``
the workbench's certified pitch-only chain, as ``specdesign demo``, which lowers the tower mode's
damping and does not keep its promise in OpenFAST: docs/openfast.md), exported as DISCON libraries, and
ROSCO's compiled DISCON, run in OpenFAST on the shipped IEA 15 MW monopile deck with TurbSim
winds (IEC Kaimal NTM class B, 4 seeds × 600 s per speed after 60 s discarded, as the paper);
rainflow DELs, the specification's promise and the linear prediction side by side.

A long run (~1.3 s of CPU per simulated second per run: 2 controllers × 6 speeds × 4 seeds ×
660 s ≈ 7 h of CPU), resumable and background-friendly: every finished run is kept in
``--out`` (a folder per run; default :data:`STORE`, in the repository), a second call runs only
what is missing; OpenFAST runs niced.

    nohup nice -n 10 python benchmarks/openfast_table3.py --processes 2 > table3.log 2>&1 &
    python benchmarks/openfast_table3.py --speeds 19 --seeds 1 --duration 30 --transient 10 --out /tmp/smoke  # a smoke run (its own store: other settings)

Designs are made on the reduced model (``--plant reduced``, default) or on OpenFAST's
linearisations of the deck (``--plant openfast``: always those at :data:`LINEARISED`, so the
designs do not depend on which speeds a call runs). ``--rosco-only`` runs ROSCO only (its
indicators are printed; Table 3 needs a design). ``benchmarks/openfast_report.py`` tabulates
the runs finished so far.
"""
from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from pathlib import Path

import numpy as np

from specdesign import feasibility, qft, rosco, spec, turbine, validate
from specdesign.export import export_discon
from specdesign.openfast import find_openfast, iea15mw_monopile, linearize_deck
from specdesign.simulate import ScheduledController


#: OpenFAST's linearisations the design model is made of, whatever speeds a call runs: the plant
#: cases (v ± 0.5, ± 1 m/s) are interpolated between them, so a design depends on this set, and a
#: campaign resumed or extended speed by speed must design on the same model to find its runs.
LINEARISED = (15.0, 17.0, 19.0, 21.0, 23.0, 25.0)

#: The campaign's store, kept in the repository: of each finished run only what
#: ``benchmarks/openfast_report.py`` reads (``run.json``, ``result.npz``, OpenFAST's log; the
#: folder's ``.gitignore`` leaves out the case files OpenFAST ran). A clone tabulates the documented
#: runs in seconds, a campaign resumed from it runs only what is missing (a run is recognised by its
#: settings and its controller files' digests, an exported design also by its responses within
#: ``export.parameters.SAME_DESIGN_RTOL``), and a machine lost does not lose its CPU hours.
STORE = Path(__file__).resolve().parent / "results" / "openfast_table3"


def openfast_model(deck, speeds=(), **kwargs):
    """The design model on OpenFAST's linearisations: :data:`LINEARISED` and any other ``speeds``
    (cached by ``linearize_deck``; ``kwargs`` go to it)."""
    return linearize_deck(deck, sorted(set(LINEARISED) | {float(v) for v in speeds}), **kwargs)


#: The second baseline's name in the campaign: ROSCO with its tower damper (``--rosco-td``).
ROSCO_TD = "ROSCO+TD"
#: ROSCO+TD with ROSCO's notch at 3P on its measurements (:func:`rosco_td_discon` with a notch).
ROSCO_TD_3P = "ROSCO+TD+3P"


def rosco_td_discon(discon_in, folder, notch=None) -> Path:
    """The deck's DISCON.IN with ROSCO's fore-aft tower damper on (``TD_Mode = 1``), ``FA_KI``
    from :func:`specdesign.rosco.tune_tower_damper` on the reduced model (the smallest gain giving
    the first tower mode ζ = 0.2 at every above-rated speed with ROSCO's PI: the rule of
    ``benchmarks/tower_damper.py`` and docs/comparison.md), written into ``folder``. With a
    ``notch`` (a :func:`specdesign.qft.three_p_notch`), ROSCO's own notch filter set to it
    (:func:`rosco_notch_values`): ROSCO+TD+3P, ROSCO's answer to what QFT+ATD+3P does. ROSCO
    (2.10.6, Filters.f90 ``PreFilterMeasuredSignals``) applies it to the generator speed; its
    tower-top notch filters only the floating feedback's signals (``FA_AccF``), while the tower
    damper (``ForeAftDamping``) integrates the high-passed raw acceleration: the damper's path
    stays unnotched."""
    damper = rosco.tune_tower_damper(turbine.iea15mw())
    Path(folder).mkdir(parents=True, exist_ok=True)
    if notch is None:
        return rosco.write_discon(discon_in, Path(folder) / "ROSCO_TD_DISCON.IN", **damper.discon_values())
    return rosco.write_discon(discon_in, Path(folder) / "ROSCO_TD_3P_DISCON.IN", **damper.discon_values(),
                              **rosco_notch_values(notch))


def rosco_notch_values(notch) -> dict:
    """The DISCON.IN entries of ROSCO's notch filter (Filters.f90: (s² + 2ωβ_num s + ω²)/(s² +
    2ωβ_den s + ω²), F_NotchFreqs in rad/s) equal to ``notch``, put on the generator speed and the
    tower-top acceleration (which ROSCO's tower damper does not read: :func:`rosco_td_discon`);
    ValueError when ``notch`` is not of that form."""
    num, den = (np.atleast_1d(np.squeeze(c)) for c in (notch.num[0][0], notch.den[0][0]))
    if num.size != 3 or den.size != 3 or not np.isclose(num[0], den[0]) or not np.isclose(num[2], den[2]) \
            or den[2] <= 0:
        raise ValueError(f"notch {notch} is not (s² + 2ωβ_num s + ω²)/(s² + 2ωβ_den s + ω²): ROSCO cannot carry it")
    num, den = num / num[0], den / den[0]
    w = float(np.sqrt(den[2]))
    return {"F_NumNotchFilts": 1, "F_NotchFreqs": f"{w:.8f}", "F_NotchBetaNum": f"{num[1] / (2 * w):.8f}",
            "F_NotchBetaDen": f"{den[1] / (2 * w):.8f}", "F_GenSpdNotch_N": 1, "F_GenSpdNotch_Ind": 1,
            "F_TwrTopNotch_N": 1, "F_TwrTopNotch_Ind": 1}


#: The designs a campaign can run: controller name, export folder prefix.
STRUCTURES = {"certificate": ("QFT", "export_"), "atd": ("QFT+ATD", "export_atd_"),
              "atd_3p": ("QFT+ATD+3P", "export_atd3p_"), "atd_3p_lp": ("QFT+ATD+3P+LP", "export_atd3plp_")}
#: Corner (rad/s) of the measurements' low-pass of the ``atd_3p_lp`` designs (``qft.rolloff``):
#: above the tower mode (1.1 rad/s) and 3P (2.4), −16 dB at 10 rad/s, where the 3P notch alone
#: left 41 % of the pitch-rate variance in OpenFAST (19 m/s, seed 0).
ROLLOFF = 4.0


def measurement_filter(model, structure):
    """The fixed filter on the measurements the designs of ``structure`` are tuned with, or None."""
    if structure == "atd_3p":
        return qft.three_p_notch(model)
    if structure == "atd_3p_lp":
        return qft.three_p_notch(model) * qft.rolloff(ROLLOFF)
    return None


def designs(model, speeds, target, structure="certificate") -> dict:
    """QFT design per speed. Deterministic: a resumed run designs again and exports the same
    parameter files, so the runs already in the campaign folder are recognised (by digest).

    ``structure="certificate"``: the default chain (the certified specification for the target,
    the design reduced from its certificate; pitch only). ``"atd"``: the paper's structure, the
    fixed PI + notch + low-pass pitch controller and a first-order tower damper (ATD) on the
    tower-top velocity tuned against the notch specification with the DEL target
    (``qft.spec_notch(target)``); its promise is the notch specification's. ``"atd_3p"``: the
    same with a notch at 3P on both measurements (``qft.three_p_notch(model)``), tuned with it;
    ``"atd_3p_lp"``: with that notch and a low-pass at :data:`ROLLOFF` (``qft.rolloff``)."""
    res = {}
    for v in speeds:
        t = time.monotonic()
        if structure != "certificate":
            f = measurement_filter(model, structure)
            d = qft.design_qft(model, v, spec=qft.spec_notch(target), **({} if f is None else {"measurement_filter": f}))
            promise = float(d.row()["promised_del_pct"])  # the relaxed specification the design meets
        else:
            pair = feasibility.specification_for_target(model, v, target)
            d = qft.design_qft(model, v, spec=qft.spec_from_certified(pair))
            promise = float(pair.promise.exact_del)
        res[v] = {"design": d, "promise": promise}
        print(f"design at {v:g} m/s: {time.monotonic() - t:.0f} s; {d.summary()}", file=sys.stderr, flush=True)
    return res


def export_design(design, folder, name, reduced):
    """``design`` exported as a DISCON library in ``folder`` (the ``DisconExport``), as the
    campaign runs it: the generator torque as the deck's DISCON runs it (ROSCO's law below rated,
    constant torque above: VS_ConstPower = 0), the pitch rate limited as ROSCO's PC_MaxRat (the
    reduced model's), the tower-top velocity of an ATD loop high-passed (OpenFAST's acceleration
    has a bias), at DT = 0.01 s."""
    return export_discon(design, folder, dt=0.01, model=reduced, torque="rosco", pitch_rate_limit=reduced.pitch_rate_limit,
                         atd_highpass=0.05, name=name)


def predicted_del(model, v, design=None) -> float:
    """The linear prediction of the tower-base DEL (1 Hz, N·m) on the design model at ``v`` m/s
    (:func:`specdesign.validate.linear_prediction`): ``design``'s pitch loop and tower damper
    closed together, or ROSCO's PI on the design plant (the design's own baseline) for None."""
    c = (spec.baseline_controller(model, v) if design is None
         else ScheduledController.fixed(design.pitch_controller, design.atd_controller))
    return validate.linear_prediction(model, c, v).del_


def campaign_arguments(description: str, speeds: str) -> argparse.ArgumentParser:
    """The command line an OpenFAST campaign script shares: speeds (default ``speeds``), seeds, record
    and transient lengths, the designs' DEL target, OpenFAST processes and niceness."""
    ap = argparse.ArgumentParser(description=description)
    ap.add_argument("--speeds", default=speeds, help="wind speeds, m/s (default: %(default)s)")
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--duration", type=float, default=600.0, help="recorded s per run")
    ap.add_argument("--transient", type=float, default=60.0, help="discarded s per run")
    ap.add_argument("--target", type=float, default=25.0, help="DEL reduction target of the designs' specification, %%")
    ap.add_argument("--processes", type=int, default=None, help="OpenFAST processes at a time (default: CPUs)")
    ap.add_argument("--nice", type=int, default=0, help="niceness added to OpenFAST (on top of this process's)")
    return ap


def main() -> None:
    ap = campaign_arguments(__doc__.split("\n")[0], "15,17,19,21,23,25")
    ap.add_argument("--plant", choices=("reduced", "openfast"), default="reduced")
    ap.add_argument("--structure", choices=tuple(STRUCTURES), default="atd",
                    help="the design: the paper's PI + notch + ATD (QFT+ATD, default) or the certified chain (QFT, pitch "
                         "only: it lowers the tower mode's damping, docs/openfast.md)")
    ap.add_argument("--rosco-only", action="store_true", help="run ROSCO only (no design, no Table 3)")
    ap.add_argument("--rosco-td", action="store_true",
                    help=f"also the second baseline {ROSCO_TD!r}: ROSCO's compiled DISCON with its fore-aft tower damper "
                         "(TD_Mode = 1, FA_KI by rosco.tune_tower_damper's rule on the reduced model)")
    ap.add_argument("--out", default=str(STORE), help="the campaign's store (default: the repository's, %(default)s)")
    args = ap.parse_args()
    speeds = [float(x) for x in args.speeds.split(",")]
    out = Path(args.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.monotonic()
    install = find_openfast()
    deck = iea15mw_monopile()
    model = reduced = turbine.iea15mw()
    discon_in = deck.fst.with_name(f"{deck.name}_DISCON.IN")
    export = None if args.rosco_only else export_design
    if export is not None and args.plant == "openfast":
        # cached in ~/.cache/specdesign/linearizations (keyed by the case's files and the OpenFAST
        # version): a resumed run, or examples/openfast_chain.py, reads them back
        model = openfast_model(deck, speeds, processes=args.processes or 2, nice=args.nice, progress=True)
    label, prefix = STRUCTURES[args.structure]
    made = designs(model, speeds, args.target, args.structure) if export is not None else {}
    camps = []
    for v in speeds:
        controllers = {"ROSCO": discon_in}
        if args.rosco_td:
            controllers[ROSCO_TD] = rosco_td_discon(discon_in, out)
        if export is not None:
            controllers[label] = export(made[v]["design"], out / f"{prefix}{v:g}", f"{label} {v:g} m/s", reduced)
        camps.append(validate.run_campaign(
            controllers, [v], args.seeds, plant=deck, duration=args.duration, transient=args.transient,
            store=out / "runs", progress=True, keep_series=1,  # seed 0's records: Fig. 9 (openfast_report.py)
            openfast={"processes": args.processes, "nice": args.nice, "install": install}))
    camp = validate.concat_campaigns(camps)
    wall = time.monotonic() - t0
    print(f"\nOpenFAST v{install.version}, {len(speeds)} speeds × {args.seeds} seeds × "
          f"{args.duration + args.transient:g} s, {len(camp.controllers)} controllers: {wall / 60:.1f} min wall")
    vals = camp.values
    for ci, name in enumerate(camp.controllers):
        for wi, v in enumerate(camp.wind_speeds):
            print(f"{name} {v:g} m/s: tower DEL {np.nanmean(vals['tower_del'][ci, wi]) / 1e6:.2f} MN·m, blade DEL "
                  f"{np.nanmean(vals['blade_del'][ci, wi]) / 1e6:.2f} MN·m, pitch SD "
                  f"{np.nanmean(vals['pitch_sd'][ci, wi]):.4f} rad, gen-speed SD "
                  f"{np.nanmean(vals['gen_speed_sd'][ci, wi]):.4f} rad/s")
    if export is None:
        return
    # the linear predictions of both controllers on the design model, per speed: the design's own
    # baseline is ROSCO's PI on the design plant (on OpenFAST's linearisations, LinearTurbine's pole
    # placement; turbine.rosco_baseline takes a TurbineModel only)
    # (ROSCO+TD, when run, has no linear form here: its row stays NaN, Table 3 compares the other two)
    pred = np.full((len(camp.controllers), len(speeds)), np.nan)
    for wi, v in enumerate(speeds):
        pred[camp.index("ROSCO"), wi] = predicted_del(model, v)
        pred[camp.index(label), wi] = predicted_del(model, v, made[v]["design"])
    camp = dataclasses.replace(camp, predicted_del=pred)
    t3 = validate.table3(camp, label, "ROSCO", promised={v: made[v]["promise"] for v in speeds})
    text = t3.to_markdown() if hasattr(t3, "to_markdown") else str(t3)
    (out / "table3.md").write_text(text + "\n")
    print("\n" + text)


if __name__ == "__main__":
    main()
