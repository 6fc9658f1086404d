"""The README's OpenFAST chain as one script: OpenFAST linearisations → specification → QFT design →
DISCON library → an OpenFAST campaign with TurbSim winds → Table 3 (rainflow beside the promise and
the linear prediction).

The design is the paper's structure by default (``--structure atd``: PI + notch + low-pass and a
tower damper on the tower-top velocity, tuned to the DEL target against the notch specification,
``spec_notch``), the one that keeps the tower mode's damping and its promise in OpenFAST;
``--structure certificate`` designs the certified pitch-only controller, which lowers that damping
and leaves OpenFAST's tower DEL unchanged at 19 m/s (docs/openfast.md).

    python examples/openfast_chain.py                  # the README's: 18-20 m/s linearised, 19 m/s, 4 seeds × 600 s
    python examples/openfast_chain.py --quick          # 19 m/s linearised (2 azimuths), 1 seed, 20 s recorded

Every step is cached or resumable: the linearisations in ``~/.cache/specdesign/linearizations``
(keyed by the case's files and the OpenFAST version: a second call reads them back), the TurbSim
fields in ``~/.cache/specdesign/turbsim``, the OpenFAST runs in ``--out``/runs. The full run costs
about 20 minutes of CPU per 660 s OpenFAST run (2 controllers × 4 seeds) plus the linearisations
(docs/openfast.md, docs/openfast_linearization.md); ``--quick`` proves the chain end to end, its
numbers (one short seed) are not a result. OpenFAST runs niced (``--nice``).
"""
from __future__ import annotations

import argparse
import dataclasses
import time
from pathlib import Path

import numpy as np

from specdesign import feasibility, turbine, validate
from specdesign.export import export_discon
from specdesign.openfast import iea15mw_monopile, linearize_deck
from specdesign.qft import design_qft, spec_from_certified, spec_notch
from specdesign.simulate import ScheduledController
from specdesign.spec import baseline_controller


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true",
                    help="19 m/s linearised with 2 azimuths, 1 seed, 10 s discarded + 20 s recorded")
    ap.add_argument("--wind-speed", type=float, default=19.0, help="design and campaign speed, m/s")
    ap.add_argument("--target", type=float, default=25.0, help="tower-base DEL reduction target, %%")
    ap.add_argument("--structure", choices=("atd", "certificate"), default="atd",
                    help="the paper's PI + notch + tower damper (default) or the certified pitch-only design")
    ap.add_argument("--nice", type=int, default=10, help="niceness added to OpenFAST and TurbSim")
    ap.add_argument("--out", default="build/openfast_chain")
    args = ap.parse_args()
    v = args.wind_speed
    lin_speeds, azimuths, seeds, duration, transient = (
        ([v], 2, 1, 20.0, 10.0) if args.quick else ([v - 1.0, v, v + 1.0], 4, 4, 600.0, 60.0))
    out = Path(args.out).resolve()
    t0 = time.monotonic()

    deck = iea15mw_monopile()                        # the IEA 15 MW monopile deck, OpenFAST v5.0 format
    lt = linearize_deck(deck, lin_speeds, n_azimuths=azimuths, nice=args.nice, progress=True)
    print(f"1. linearisations at {lin_speeds} m/s ({azimuths} azimuths): {time.monotonic() - t0:.0f} s")

    t = time.monotonic()
    if args.structure == "atd":
        design = design_qft(lt, v, spec=spec_notch(args.target))
        promise = float(design.row()["promised_del_pct"])  # the (relaxed) notch specification the design meets
        print(f"2-3. notch specification and design at {v:g} m/s: {design.summary()} ({time.monotonic() - t:.0f} s)")
    else:
        spec = feasibility.specification_for_target(lt, v, args.target)
        promise = float(spec.promise.exact_del)
        print(f"2. specification at {v:g} m/s: promises {promise:.2f} % ({time.monotonic() - t:.0f} s)")
        t = time.monotonic()
        design = design_qft(lt, v, spec=spec_from_certified(spec))
        print(f"3. QFT design: {design.summary()} ({time.monotonic() - t:.0f} s)")

    # the generator torque, pitch limits and rated speed of the turbine the deck models (its reduced
    # model carries them); the pitch rate limited as ROSCO's PC_MaxRat (OpenFAST has no actuator
    # model); OpenFAST's tower-top acceleration carries a bias, so an ATD loop's velocity is high-passed
    reduced = turbine.iea15mw()
    lib = export_discon(design, out / f"qft{v:g}", dt=0.01, model=reduced, torque="rosco",
                        pitch_rate_limit=reduced.pitch_rate_limit, atd_highpass=0.05, name=f"QFT {v:g} m/s")
    print(f"4. DISCON library {lib.library}, parameters {lib.parameters}")

    t = time.monotonic()
    camp = validate.run_campaign({"ROSCO": deck.fst.with_name(deck.name + "_DISCON.IN"), "QFT": lib}, [v], seeds,
                                 plant=deck, duration=duration, transient=transient, store=out / "runs",
                                 progress=True, openfast={"processes": 1, "nice": args.nice})
    print(f"5. OpenFAST campaign, {seeds} seed(s) × {transient + duration:g} s: {time.monotonic() - t:.0f} s")

    # the linear predictions on the design plant (the compiled controllers have no linear form there);
    # the baseline is the design's: ROSCO's PI placed on OpenFAST's rotor model (LinearTurbine)
    # (both loops of the design closed)
    pred = [validate.linear_prediction(lt, baseline_controller(lt, v), v).del_,
            validate.linear_prediction(lt, ScheduledController.fixed(design.pitch_controller, design.atd_controller), v).del_]
    predicted = np.full((len(camp.controllers), 1), np.nan)
    predicted[camp.index("ROSCO"), 0], predicted[camp.index("QFT"), 0] = pred
    camp = dataclasses.replace(camp, predicted_del=predicted)
    print("\n" + validate.table3(camp, "QFT", "ROSCO", promised={v: promise}).to_markdown())
    print(f"\nthe chain: {time.monotonic() - t0:.0f} s wall")


if __name__ == "__main__":
    main()
