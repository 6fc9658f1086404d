"""The H∞ structures on given specifications at 19 m/s (docs/hinf.md, "Measured at 19 m/s").

``design_hinf`` on QFT's notch specifications (``spec_like_qft``: its ladder of speed relaxations)
and on ROSCO's (``spec_from_rosco``), pitch only and pitch + ATD (1×2), on the reduced IEA 15 MW
model, 8 states: every number is the design's own assessment on its refined grid, with what keeps
a design off a real turbine beside it (C_β against the default high-frequency gain bound,
the reduced controller's unstable poles, the sign of its generator-speed integral action against
ROSCO's). ``--noise-scan`` adds the pitch + ATD design on QFT's specifications with the
synthesis' generator-speed noise raised ×2 per step (``noise={"gen_speed": ...}``): what rolling
C_β off that way costs. The table is printed and spliced into docs/hinf.md between its markers.
``--openfast 19`` prints instead, on OpenFAST's linearisation of the IEA 15 MW monopile deck at that
speed (the cached one, ``openfast_table3.openfast_model``), the gain of the exported H∞ design
(``design_hinf``'s default) and of the QFT+ATD design over ROSCO's, 20·log10|C_β/C_ROSCO|, at
0.5-10 rad/s, with each design's linear pitch SD against ROSCO's (docs/comparison.md, "In OpenFAST").

Run: python benchmarks/hinf_structures.py [--noise-scan] [--no-docs] [--openfast 19]   (≈ 1 min, 3 with the scan)
"""
from __future__ import annotations

import argparse
import warnings
from pathlib import Path

import numpy as np
from comparison import splice
from openfast_table3 import designs, openfast_model

from specdesign import hinf, spec, turbine
from specdesign.closedloop import siso_response
from specdesign.feasibility import MAX_HF_GAIN_RATIO
from specdesign.openfast import iea15mw_monopile

V = 19.0
DOC = Path(__file__).resolve().parents[1] / "docs" / "hinf.md"
START, END = "<!-- hinf_structures: start -->", "<!-- hinf_structures: end -->"
PITCH, ATD = ("gen_speed",), ("gen_speed", "tower_top_vel")
HEAD = ("| design | specs (r) | full order | γ | reduced | ‖K − K_r‖∞ (bound) | speed spec | over ROSCO's T_{Ω,w} | "
        "tower at mode (±10 %) | vs notch spec at mode | ζ_min (at rad/s) | max Re p | M_s | DEL red. | pitch σ | "
        "C_β vs bound | K's unstable poles | speed sign |")


def _design(model, spec, meas, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # what they warn of is a column of the table
        return hinf.design_hinf(model, V, spec=spec, measurements=meas, order=8, **kw)


def row(label, d) -> str:
    poles = ", ".join(f"{p.real:+.3f}" + (f"{p.imag:+.3f}j" if p.imag else "") for p in d.controller_unstable_poles)
    return (f"| {label} | {d.specs} ({d.speed_relax_db:g} dB) | {d.full_controller.nstates} | {d.gamma:.3g} | "
            f"{d.controller.nstates} | {d.reduction.error_hinf:.3f} ({d.reduction.bound:.3f}) | "
            f"{d.speed_excess_db:+.2f} dB | {d.speed_excess_baseline_db:+.2f} dB | "
            f"{d.tower_excess_db:+.2f} ({d.tower_band_excess_db:+.2f}) dB | {d.tower_notch_excess_db:+.2f} dB | "
            f"{d.zeta_min:.3f} ({d.zeta_min_frequency:.3g}) | {d.max_pole_real:.3f} | {d.peak_sensitivity:.2f} | "
            f"{d.predicted_del_reduction:.1f} % | {d.pitch_std:.4f} rad | {d.hf_excess_db:+.1f} dB | "
            f"{poles or 'none'} | {'ROSCO' if d.speed_integral_sign > 0 else '**reversed**'} |")


def table(model, noise_scan=False) -> str:
    cases = [
        ("**`spec_like_qft`**: 1×2 (Ω_g, v_tt)", hinf.spec_like_qft(model, V), ATD, {}),
        ("pitch (Ω_g)", hinf.spec_like_qft(model, V), PITCH, {}),
        ("1×2, first rung only", hinf.spec_like_qft(model, V, speed_relax_db=3.0), ATD, {}),
        ("1×2", hinf.spec_from_rosco(model, V), ATD, {}),
        ("pitch", hinf.spec_from_rosco(model, V), PITCH, {}),
        ("pitch, `min_damping=0, decay_rate=0`", hinf.spec_from_rosco(model, V), PITCH,
         {"min_damping": 0.0, "decay_rate": 0.0}),
    ]
    out = [HEAD, "|" + "---|" * HEAD.count(" | ") + "---|"]
    d = None
    for label, given, meas, kw in cases:
        d = _design(model, given, meas, **kw)
        out.append(row(label, d))
    baseline = d.pitch_std_baseline
    if noise_scan:
        base = hinf.DEFAULT_NOISE["gen_speed"]
        for factor in (2, 4, 8, 16, 32, 64):
            noise = dict(hinf.DEFAULT_NOISE, gen_speed=factor * base)
            d = _design(model, hinf.spec_like_qft(model, V), ATD, noise=noise)
            out.append(row(f"1×2, generator-speed noise × {factor} ({factor * base:g} rad/s)", d))
    command = "python benchmarks/hinf_structures.py" + (" --noise-scan" if noise_scan else "")
    out += ["", f"ROSCO's pitch σ is {baseline:.4f} rad (`{command}`)."]
    return "\n".join(out)


def openfast_gains(v: float) -> str:
    """|C_β/C_ROSCO| (dB) of the exported H∞ and QFT+ATD designs on OpenFAST's linearisation at ``v`` m/s."""
    model = openfast_model(iea15mw_monopile(), [v])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        h = hinf.design_hinf(model, v)
        q = designs(model, [v], 25.0, "atd")[v]["design"]
    w = np.array([0.5, 1.0, 1.5, 2.0, 3.0 * model.rated_rotor_speed, 3.0, 4.0, 6.0, 8.0, 10.0])
    rosco = np.abs(siso_response(spec.baseline_controller(model, v), w))
    out = ["| design | " + " | ".join(f"{x:.3g}" for x in w) + " rad/s | pitch SD / ROSCO's (linear) |",
           "|" + "---|" * (w.size + 2)]
    for name, c, ratio in (("H∞ (design_hinf's default)", h.pitch_controller, h.pitch_std / h.pitch_std_baseline),
                           ("QFT+ATD", q.pitch_controller, 1 + q.pitch_sd_change / 100)):
        gain = 20 * np.log10(np.abs(siso_response(c, w)) / rosco)
        out.append(f"| {name} | " + " | ".join(f"{g:+.1f}" for g in gain) + f" | {ratio:.2f} |")
    out.append(f"\n20·log10|C_β/C_ROSCO| in dB at {v:g} m/s; the bound's κ = {MAX_HF_GAIN_RATIO:g} is "
               f"{20 * np.log10(MAX_HF_GAIN_RATIO):.1f} dB on {w[3]:g}-{w[-1]:g} rad/s.")
    return "\n".join(out)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--noise-scan", action="store_true", help="add the 1×2 design with more generator-speed noise")
    ap.add_argument("--no-docs", action="store_true", help="print only; do not splice docs/hinf.md")
    ap.add_argument("--openfast", type=float, default=None, metavar="SPEED",
                    help="print the H∞ and QFT+ATD designs' gains on OpenFAST's linearisation at SPEED m/s instead")
    args = ap.parse_args()
    if args.openfast is not None:
        print(openfast_gains(args.openfast))
        return
    text = table(turbine.iea15mw(), args.noise_scan)
    print(text)
    if not args.no_docs:
        splice(DOC, text, START, END)


if __name__ == "__main__":
    main()
