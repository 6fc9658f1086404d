"""The design loop below rated and through the transition (issue 16, part 1): the numbers of docs/below_rated.md.

Run: python benchmarks/below_rated_design.py [--part analysis|designs|held|transition|torque|torque_design|torque_gap|bins|all]
Prints
(0) ``analysis``: ``spec.baseline_analysis`` from cut-in to cut-out (the torque law closed in the
    plant; ROSCO's pitch loop linearised at the trim: open below rated): tower DEL and ΔD% (~5 s);
(1) ``designs``: the specification-driven QFT design (``qft.design_qft(model, v, target)``) at
    11-14 m/s for the targets 25, 20, 15 % (the first that is certified), and 13 m/s at 20 % with
    |S| <= 2.2, with the error message where none is certified (~2-4 min);
(1b) ``held``: why a design held below rated may not stay at fine pitch: the pitch response to a
    sustained speed deficit and the first seconds of a 3 m/s run (~1 min);
(2) ``transition``: ROSCO vs the lifetime demo's schedule (15-25 m/s, held down to rated) vs the
    schedule from 13 m/s (LIFETIME_DESIGNS) vs that with the 11 m/s design too, ROSCO's torque law
    in every run (``torque_control="rosco"``), 9-15 m/s x 4 paired seeds x 600 s: tower-base DEL
    change per speed with its jackknife SE, rotor-speed SD, mean power and pitch-rate SD (~3 min);
(3) ``torque``: below rated, what a generator-torque controller G on the generator speed
    (added to ROSCO's torque law, tau = -G*Omega_g) can do for the tower: the general QFT form
    T_MyT,w = (A + B*G)/(C + D*G) with the torque law closed in the plant, its limit G -> inf
    (rotor speed held), the pointwise bound for |S| <= r, a proportional family G = -k with
    its costs (rotor-speed, torque and power SD, mean aerodynamic power change, linear), and
    the nonlinear check with ROSCO's own TSR-tracking torque PI made stiffer (~30 s);
(3b) ``torque_design``: the design loop's step below rated, ``qft.design_torque(model, v, target,
    max_power_loss_pct=1.0)`` at 5-10 m/s for 10-30 % (gain, promise, costs, or the refusal), and
    the designs for 10 % at 7, 20 % at 8-9 m/s and 25 % at 8 m/s run nonlinear (``TorqueDesign.torque_law``: ROSCO's
    mode-3 PI), ROSCO's pitch PI, 20 paired seeds x 600 s (issue 28: the promise checked over >= 20 seeds; ~2 min);
(3c) ``torque_gap``: where the 8 m/s 20 % design's promise and rainflow part, one change per row (the linearised
    turbine in the time domain, the nonlinear one with the law the linearisation assumes, the torque limits, the
    compiled laws, the pitch PI, the filter/integral/reference, the minimum speed), 20 paired seeds x 600 s each,
    and the laws' linearisation against the nonlinear loop's small-amplitude response (~2 min);
(4) ``bins``: every 2 m/s wind bin 3-25 m/s x 6 paired seeds x 600 s, ROSCO vs the demo's
    schedule (the same campaign as ``python -m specdesign demo --lifetime``) vs the schedule from
    13 m/s, and both again with the stiffer torque loop: tower DEL change per bin with its SE,
    mean power, and the lifetime change over the seed paper's Weibull climate (~3 min).
"""
from __future__ import annotations

import argparse
import dataclasses
import time
import warnings

import control as ct
import numpy as np

from specdesign import qft, validate
from specdesign.closedloop.maps import state_space_response
from specdesign.fatigue import del_rainflow
from specdesign.qft.torque_design import torque_law_response
from specdesign.rosco import rosco_baseline, rosco_scheduled
from specdesign.simulate import scheduled, simulate
from specdesign.spec import baseline_analysis
from specdesign.spectral import del_spectral
from specdesign.turbine import iea15mw
from specdesign.wind import rotor_effective_spectrum

#: The lifetime demo's schedule (specdesign.demo.LIFETIME_DESIGN_SPEEDS at 25 %): wind speed (m/s) →
#: (DEL target %, design_qft options).
DEMO_DESIGNS = {v: (25.0, {}) for v in (15.0, 17.0, 19.0, 21.0, 23.0, 25.0)}
#: The schedule down to 13 m/s, the lowest speed with a safe certified design (part 1): 13 m/s at 20 % with
#: |S| <= 2.2 (under the default high-frequency bound 25 % is certified there, but with |S| <= 1.9 its design
#: misses the margin by 0.81 dB).
LIFETIME_DESIGNS = {13.0: (20.0, {"max_sensitivity": 2.2})} | DEMO_DESIGNS
#: The schedule with the 11 m/s design too, for part 2 (its controller was unstable without the
#: high-frequency gain bound; under the default bound 11 m/s has no certified specification, part 1,
#: and part 2 says so instead of running it).
WITH_11 = {11.0: (20.0, {})} | LIFETIME_DESIGNS
#: design_qft results by (v, target, options): the schedules of parts 2 and 4 share their designs.
_MADE: dict = {}

def analysis(model):
    print("## The baseline loop from cut-in to cut-out (spec.baseline_analysis: torque law closed, ROSCO's pitch loop "
          "linearised at the trim)")
    print("| v (m/s) | region | ROSCO's pitch loop | tower-base DEL (MN·m, Dirlik) | ΔD% peak at (rad/s) | tower band 0.8-1.4 rad/s share of ΣΔD% |")
    print("|---|---|---|---|---|---|")
    for v in (3.0, 5.0, 7.0, 8.0, 9.0, 10.0, 10.5, 10.8, 11.0, 12.0, 13.0, 15.0, 19.0):
        base = baseline_analysis(model, v)
        c = rosco_baseline(model, v)
        band = (base.omega >= 0.8) & (base.omega <= 1.4)
        loop = "open (C = 0, fine pitch)" if c.name.endswith("_fine_pitch") else "closed"
        print(f"| {v:g} | {model.trim(v).region} | {loop} | {base.del_1hz / 1e6:.2f} | {base.omega[np.argmax(base.sensitivity)]:.3f} "
              f"| {100 * base.sensitivity[band].sum() / base.sensitivity.sum():.1f} % |")


def designs_near_rated(model):
    print("## Specification-driven QFT designs near rated (qft.design_qft(model, v, target))")
    print("| v (m/s) | target (%) | result | predicted DEL red. (%) | gen-speed SD (%) | pitch-rate SD (%) | GM (dB) | PM (deg) | states |")
    print("|---|---|---|---|---|---|---|---|---|")
    cases = [(v, t, {}) for v in (11.0, 12.0, 13.0, 14.0) for t in (25.0, 20.0, 15.0)] + [(13.0, 20.0, {"max_sensitivity": 2.2})]
    done = set()
    for v, target, kw in cases:
        if (v, bool(kw)) in done:
            continue
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                d = qft.design_qft(model, v, target, **kw)
            except ValueError as e:
                print(f"| {v:g} | {target:g} | refused: {e} | | | | | | |")
                continue
        done.add((v, bool(kw)))
        r = d.row()
        print(f"| {v:g} | {target:g}{' ' + str(kw) if kw else ''} | {'met' if d.success else 'NOT met: ' + d.message} "
              f"| {r['predicted_del_pct']:.1f} | {r['gen_speed_sd_change_pct']:+.1f} | {r['pitch_rate_sd_change_pct']:+.1f} "
              f"| {r['gain_margin_db']:.1f} | {r['phase_margin_deg']:.1f} | {r['n_states']} |")


def schedule(model, designs, name):
    """Scheduled pitch controller of design_qft(model, v, target, **options) for {v: (target, options)}."""
    out = {}
    for v, (t, kw) in designs.items():
        key = (v, t, tuple(sorted(kw.items())))
        if key not in _MADE:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                _MADE[key] = qft.design_qft(model, v, t, **kw)
            print(f"design at {v:g} m/s: {_MADE[key].message}")
        out[v] = _MADE[key]
    return scheduled(model, {v: ct.tf(d.pitch_controller) for v, d in out.items()}, name=name)

def _table(camp, names, base="ROSCO"):
    b = camp.controllers.index(base)
    tower = camp.values["tower_del"]
    print("| v (m/s) | controller | tower DEL (MN·m) | change vs ROSCO (%) | SE (pp) | Ω SD (rad/s) | mean power (MW) | pitch-rate SD (deg/s) |")
    print("|---|---|---|---|---|---|---|---|")
    for w, v in enumerate(camp.wind_speeds):
        for name in names:
            i = camp.controllers.index(name)
            if camp.unstable[i, w]:
                print(f"| {v:g} | {name} | unstable: the linearised closed loop there has a pole with Re ≥ 0 (not run) | | | | | |")
                continue
            ch, se = _paired_change(tower[i, w], tower[b, w])
            row = [camp.values[k][i, w].mean() for k in ("gen_speed_sd", "mean_power", "pitch_rate_sd")]
            print(f"| {v:g} | {name} | {tower[i, w].mean() / 1e6:.2f} | {ch:+.1f} | {se:.1f} | {row[0]:.4f} "
                  f"| {row[1] / 1e6:.3f} | {np.degrees(row[2]):.3f} |")


def _paired_change(x, base):
    """Change of the seed-mean (%) and its jackknife SE over the paired seeds (pp)."""
    n = x.size
    full = 100 * (x.mean() / base.mean() - 1)
    loo = np.array([100 * (np.delete(x, j).mean() / np.delete(base, j).mean() - 1) for j in range(n)])
    return full, float(np.sqrt((n - 1) / n * np.sum((loo - loo.mean()) ** 2)))


def transition(model):
    print("\n## Through the transition: 9-15 m/s x 4 paired seeds x 600 s, ROSCO's torque law in every run")
    t0 = time.perf_counter()
    ctrls = {"ROSCO": rosco_scheduled(model), "QFT 15-25": schedule(model, DEMO_DESIGNS, "QFT 15-25"),
             "QFT 13-25": schedule(model, LIFETIME_DESIGNS, "QFT 13-25")}
    try:
        ctrls["QFT 11-25"] = schedule(model, WITH_11, "QFT 11-25")
    except ValueError as e:  # no certified specification at 11 m/s (part 1): the schedule cannot be made
        print(f"QFT 11-25 not run: {e}")
    camp = validate.run_campaign(ctrls, [9.0, 10.0, 11.0, 12.0, 13.0, 14.0, 15.0], range(1, 5), model=model,
                                 duration=600.0, torque_control="rosco", progress=False)
    _table(camp, list(ctrls))
    print(f"({time.perf_counter() - t0:.0f} s with the designs)")
    return ctrls


def _variance_terms(model, v, k, w, s_w):
    """Linear maps with τ_add = k·δΩ_g added to the law: DEL, SDs, and the mean aerodynamic power change.

    The mean-power change is second order, ½·tr(H_P·Σ) with H_P the Hessian of P = Q·Ω in
    (Ω, wind − ẋ_top) from ``aero_expansion`` and Σ their covariance from the linear maps.
    """
    P = model.linearize(v)
    names = ("tower_base_my", "gen_speed", "tower_top_vel", "power")
    ii = [P.input_labels.index(n) for n in ("wind", "gen_torque")]
    oi = [P.output_labels.index(n) for n in names]
    R = state_space_response(np.asarray(P.A), np.asarray(P.B)[:, ii], np.asarray(P.C)[oi],
                             np.asarray(P.D)[np.ix_(oi, ii)], w)
    g = -k  # general form: τ = −G·Ω_g
    dk = 1 + g * R[:, 1, 1]
    T = {y: R[:, j, 0] - R[:, j, 1] * g * R[:, 1, 0] / dk for j, y in enumerate(names)}
    T["torque"] = 2 * model.torque_control.k_opt * model.trim(v).rotor_speed * T["gen_speed"] + k * T["gen_speed"]
    rel = 1 - T["tower_top_vel"]  # the rotor sees wind − ẋ_top
    z = [T["gen_speed"], rel]
    cov = np.array([[np.trapezoid(np.real(a * np.conj(b)) * s_w, w) for b in z] for a in z])
    e = model.aero_expansion(v)
    om, q = e.point[0], e.loads[0]
    gq, hq = e.gradient[0], e.hessian[0]
    hp = np.array([[om * hq[0, 0] + 2 * gq[0], om * hq[0, 1] + gq[1]], [om * hq[0, 1] + gq[1], om * hq[1, 1]]])
    sd = {y: float(np.sqrt(np.trapezoid(np.abs(T[y]) ** 2 * s_w, w))) for y in ("gen_speed", "power", "torque")}
    return (del_spectral(w, np.abs(T["tower_base_my"]) ** 2 * s_w, 4.0), sd, 0.5 * float(np.sum(hp * cov)), q * om,
            R)


def torque_loop(model, speeds=(5.0, 7.0, 8.0, 9.0, 10.0)):
    print("\n## Below rated: a generator-torque controller for the tower (linear, IEC class B, m = 4)")
    w = np.logspace(-3, 1, 800)
    print("General form T_MyT,w = (A + B·G)/(C + D·G), G on Ω_g acting on the torque (added to ROSCO's law). "
          "DEL with ROSCO's law alone, with Ω held (G → ∞: the K∞ of the form), and the pointwise lower bound of "
          "|T_MyT,w| for |S| = |1/(1 + G·D)| ≤ r (the speed map allowed to grow by 20·log10(r) dB):")
    print("| v (m/s) | region | DEL law (MN·m) | DEL Ω held (MN·m) | bound r = 1.41 (3 dB) | r = 2 (6 dB) | r = 4 (12 dB) |")
    print("|---|---|---|---|---|---|---|")
    for v in speeds:
        s_w = rotor_effective_spectrum(w, v, model.rotor_radius, turbulence_class="B")
        d0, _, _, _, R = _variance_terms(model, v, 0.0, w, s_w)
        yw, yt, nw, nt = R[:, 0, 0], R[:, 0, 1], R[:, 1, 0], R[:, 1, 1]
        kinf = yw - yt * nw / nt
        row = [d0, del_spectral(w, np.abs(kinf) ** 2 * s_w, 4.0)]
        for r in (np.sqrt(2.0), 2.0, 4.0):
            tmin = np.maximum(0.0, np.abs(kinf) - r * np.abs(yw - kinf))
            row.append(100 * (del_spectral(w, tmin**2 * s_w, 4.0) / d0 - 1) if np.any(tmin > 0) else -100.0)
        print(f"| {v:g} | {model.trim(v).region} | {row[0] / 1e6:.2f} | {row[1] / 1e6:.2f} ({100 * (row[1] / row[0] - 1):+.0f} %) "
              f"| ≥ {row[2]:+.0f} % | ≥ {row[3]:+.0f} % | ≥ {row[4]:+.0f} % |")
    print("\nA proportional torque controller τ_add = k·δΩ_g (k in units of the law's own stiffness 2KΩ at 8 m/s):")
    print("| v (m/s) | k / 2KΩ | tower DEL (%) | Ω SD (rad/s) | torque SD (MN·m) | power SD (MW) | mean aero power (%) |")
    print("|---|---|---|---|---|---|---|")
    k_ref = 2 * model.torque_control.k_opt * model.trim(8.0).rotor_speed
    for v in (7.0, 8.0, 9.0):
        s_w = rotor_effective_spectrum(w, v, model.rotor_radius, turbulence_class="B")
        d0, _, p0, pm, _ = _variance_terms(model, v, 0.0, w, s_w)
        for f in (0.0, 1.0, 3.0, 10.0, 30.0):
            d, sd, dp, _, _ = _variance_terms(model, v, f * k_ref, w, s_w)
            print(f"| {v:g} | {f:g} | {100 * (d / d0 - 1):+.1f} | {sd['gen_speed']:.4f} | {sd['torque'] / 1e6:.3f} "
                  f"| {sd['power'] / 1e6:.3f} | {100 * (dp - p0) / pm:+.2f} |")


def stiff_torque_law(model, gain=3.0, reference_corner=0.02):
    """ROSCO's TSR-tracking torque PI (VS_ControlMode 3) with ``gain`` × its gains and a slower speed
    reference (F_VSRefSpdCornerFreq ``reference_corner`` rad/s; ROSCO's 0.209): a stiffer torque loop."""
    law = model.torque_control
    return dataclasses.replace(law, mode=3, kp=gain * law.kp, ki=gain * law.ki, reference_corner=reference_corner)


def torque_law_nonlinear(model, speeds=(5.0, 7.0, 8.0, 9.0)):
    print("\nNonlinear, ROSCO's pitch PI, 4 paired seeds x 600 s: ROSCO's law (mode 1) vs a stiffer torque loop "
          "(mode 3, gains x g, speed reference low-passed at f rad/s)")
    print("| v (m/s) | torque law | tower DEL (MN·m) | change (%) | SE (pp) | Ω SD (rad/s) | torque SD (MN·m) | mean power (MW) | change (%) |")
    print("|---|---|---|---|---|---|---|---|---|")
    ros = rosco_scheduled(model)
    laws = {"ROSCO (mode 1)": model.torque_control, "mode 3, g = 1, f = 0.209": dataclasses.replace(model.torque_control, mode=3),
            "mode 3, g = 3, f = 0.02": stiff_torque_law(model), "mode 3, g = 10, f = 0.02": stiff_torque_law(model, 10.0)}
    for v in speeds:
        ref = None
        for name, law in laws.items():
            r = simulate(model, ros, [v], seeds=range(1, 5), duration=600.0, torque_control=law)
            dels = np.array([del_rainflow(x, 4.0, 600.0) for x in r["tower_base_my"][0]])
            om, p = r["gen_speed"][0], r["power"][0]
            tq = p / (model.generator_efficiency * om)
            if ref is None:
                ref = (dels, p.mean(axis=1))
            ch, se = _paired_change(dels, ref[0])
            print(f"| {v:g} | {name} | {dels.mean() / 1e6:.2f} | {ch:+.1f} | {se:.1f} | {om.std(axis=1).mean():.4f} "
                  f"| {tq.std(axis=1).mean() / 1e6:.3f} | {p.mean() / 1e6:.3f} | {100 * (p.mean() / ref[1].mean() - 1):+.2f} |")


#: Paired seeds of the nonlinear check of design_torque (issue 28 item 6: >= 20; 4 seeds gave -19.6 +- 2.9 % at
#: 8 m/s for a 20 % design, 20 seeds -16.0 +- 1.1 %).
TORQUE_SEEDS = range(1, 21)


def _tower_dels(model, ctrl, v, torque_control, linear=False):
    """Rainflow tower-base DEL (N·m, m = 4, 1 Hz) per seed of TORQUE_SEEDS x 600 s, and the run."""
    r = simulate(model, ctrl, [v], seeds=TORQUE_SEEDS, duration=600.0, torque_control=torque_control, linear=linear)
    return np.array([del_rainflow(x, 4.0, 600.0) for x in r["tower_base_my"][0]]), r


def torque_design(model):
    print("\n## The torque-loop design: qft.design_torque(model, v, target, max_power_loss_pct=1.0) (linear, class B, m = 4, "
          "both torque laws linearised as simulated)")
    print("| v (m/s) | target (%) | k (MN·m per rad/s) | k / law stiffness | promise (%) | G → ∞ (%) | Ω SD (rad/s) | "
          "torque SD (MN·m) | power SD (MW) | mean power (%) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for v in (5.0, 7.0, 8.0, 9.0, 10.0):
        for target in (10.0, 20.0, 30.0):
            try:
                d = qft.design_torque(model, v, target, max_power_loss_pct=1.0)
            except ValueError as e:
                print(f"| {v:g} | {target:g} | refused: {e} |||||||")
                continue
            print(f"| {v:g} | {target:g} | {d.gain / 1e6:.1f} | {d.gain / d.law_stiffness:.2f} | {d.promise:.1f} | "
                  f"{d.limit_promise:.1f} | {d.baseline_speed_sd:.4f} → {d.speed_sd:.4f} | {d.baseline_torque_sd / 1e6:.3f} → "
                  f"{d.torque_sd / 1e6:.3f} | {d.baseline_power_sd / 1e6:.3f} → {d.power_sd / 1e6:.3f} | {d.power_change_pct:+.2f} |")
    print("\nNonlinear: the designs as ROSCO's mode-3 PI (TorqueDesign.torque_law, reference corner 0.02 rad/s) vs ROSCO's "
          f"law (mode 1), ROSCO's pitch PI, {len(TORQUE_SEEDS)} paired seeds x 600 s; linear promise and power estimate "
          "beside")
    print("| v (m/s) | target (%) | kp (MN·m per rad/s) | tower DEL change (%) | SE (pp) | linear (%) | Ω SD (rad/s) | "
          "mean power (%) | linear (%) | ROSCO: time Ω > min + 0.005 / > 0.97 rated (%) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    ros = rosco_scheduled(model)
    tl0 = model.torque_control
    for v, target in ((7.0, 10.0), (8.0, 10.0), (8.0, 20.0), (9.0, 20.0), (10.0, 20.0)):
        try:
            d = qft.design_torque(model, v, target, max_power_loss_pct=1.0)
        except ValueError as e:
            print(f"| {v:g} | {target:g} | refused: {e} ||||||")
            continue
        law = d.torque_law(model.torque_control)
        runs = {}
        for name, tl in (("rosco", model.torque_control), ("design", law)):
            dels, r = _tower_dels(model, ros, v, tl)
            om = r["gen_speed"][0]
            runs[name] = (dels, r["power"][0].mean(axis=1), om.std(axis=1).mean(), 100 * np.mean(om > tl0.min_speed + 0.005),
                          100 * np.mean(om > 0.97 * tl0.reference_speed))
        ch, se = _paired_change(runs["design"][0], runs["rosco"][0])
        dp = 100 * (runs["design"][1].mean() / runs["rosco"][1].mean() - 1)
        print(f"| {v:g} | {target:g} | {law.kp / 1e6:.1f} | {ch:+.1f} | {se:.1f} | {-d.promise:+.1f} | "
              f"{runs['rosco'][2]:.4f} → {runs['design'][2]:.4f} | {dp:+.2f} | {d.power_change_pct:+.2f} | "
              f"{runs['rosco'][3]:.0f} / {runs['rosco'][4]:.1f} |")


class _HeldPitch:
    """A callable controller (the simulator's slow path): pitch held at the trim, generator torque ``law(Ω)`` (N·m)."""

    def __init__(self, pitch, law):
        self.pitch, self.law = pitch, law

    def __call__(self, t, y):
        om = y["gen_speed"]
        return np.full(om.shape, self.pitch), self.law(om)


def torque_gap(model, v=8.0, target=20.0):
    """The gap between design_torque's promise and rainflow, one change per row (issue 28 item 6)."""
    d = qft.design_torque(model, v, target, max_power_loss_pct=1.0)
    op, law0 = model.trim(v), model.torque_control
    law = d.torque_law(law0)
    K, om0, tq0, k = law0.k_opt, op.rotor_speed, op.gen_torque, d.gain
    print(f"\n## The gap at {v:g} m/s, {target:g} % design (k = {k / 1e6:.1f} MN·m per rad/s, kp = {law.kp / 1e6:.1f}), "
          f"{len(TORQUE_SEEDS)} paired seeds x 600 s: tower-base DEL change vs the row's baseline, one change per row")
    print("| row | baseline → design (what changes from the row above) | tower DEL change (%) | SE (pp) | linear (%) |")
    print("|---|---|---|---|---|")
    # linear rows: the promise as designed, and the general form with linearize's law (K·Ω² on the raw speed) + k·δΩ
    A, B, C, D = qft.torque_general_form(model, v, d.omega)
    index = 100 * (del_spectral(d.omega, np.abs((A - B * k) / (C - D * k)) ** 2 * d.wind_psd, 4.0)
                   / del_spectral(d.omega, np.abs(A) ** 2 * d.wind_psd, 4.0) - 1)
    print(f"| a | design_torque's promise: ROSCO's law → the mode-3 PI, both linearised as simulated "
          f"(torque_law_response) | | | {-d.promise:+.1f} |")
    print(f"| b | the same k on linearize's law: K·Ω² → K·Ω² + k·δΩ, raw speed, no filter, PI or reference | | | {index:+.1f} |")
    rows = []
    hold = model.trim(v).pitch
    clip = (law0.min_torque, min(law0.rated_torque, law0.max_torque))
    rows.append(("c", "b in the time domain: the linearised turbine (`linear=True`), pitch held, rainflow",
                 _HeldPitch(hold, lambda om: np.full(om.shape, tq0)), _HeldPitch(hold, lambda om: tq0 + k * (om - om0)),
                 None, None, True))
    rows.append(("d", "c on the nonlinear turbine (aerodynamics, K·Ω² curvature)",
                 _HeldPitch(hold, lambda om: K * om**2), _HeldPitch(hold, lambda om: K * om**2 + k * (om - om0)),
                 None, None, False))
    rows.append(("e", f"d with the torque held within [{clip[0]:g}, {clip[1] / 1e6:.2f} MN·m] (ROSCO's limits)",
                 _HeldPitch(hold, lambda om: np.clip(K * om**2, *clip)),
                 _HeldPitch(hold, lambda om: np.clip(K * om**2 + k * (om - om0), *clip)), None, None, False))
    zero = ct.tf([0.0], [1.0])
    zero.name = "pitch held"
    ros = rosco_scheduled(model)
    region2 = {"min_speed": 0.3}  # region 2 throughout (the trim is 0.576 rad/s): no minimum-speed PI
    bare = region2 | {"filter_corner": 30.0}
    b_bare = dataclasses.replace(law0, **bare)
    d_bare = dataclasses.replace(law, **bare, ki=0.0, reference_corner=1e-9, max_rate=1e12)
    rows.append(("f", ("e as the compiled laws (`simulate(..., torque_control=law)`): mode 1 vs mode 3 with ki = 0, fixed "
                 "reference, no speed filter (corner 30 rad/s) or rate limit, minimum speed 0.3 rad/s"), zero, zero,
                 b_bare, d_bare, False))
    rows.append(("g", "f with ROSCO's pitch PI", ros, ros, b_bare, d_bare, False))
    rows.append(("h", ("g with the laws as designed (ROSCO's speed filter, the PI's integral, the moving reference, the "
                 "rate limit)"), ros, ros, dataclasses.replace(law0, **region2), dataclasses.replace(law, **region2), False))
    rows.append(("i", "h with ROSCO's minimum speed 0.524 rad/s (region 1.5): the nonlinear check above", ros, ros, law0,
                 law, False))
    for row, what, c_base, c_design, t_base, t_design, linear in rows:
        base, _ = _tower_dels(model, c_base, v, t_base, linear)
        new, _ = _tower_dels(model, c_design, v, t_design, linear)
        ch, se = _paired_change(new, base)
        print(f"| {row} | {what} | {ch:+.1f} | {se:.1f} | |")
    print("\nThe laws linearised as simulated against the nonlinear loop at small amplitude: pitch held, wind "
          f"{v:g} + 0.02·sin(ω₀t) m/s, first harmonic of the tower-base moment over 600 s after 600 s (the design's law)")
    print("| ω₀ (rad/s) | |T| nonlinear (MN·m per m/s) | as simulated: amplitude, phase error | linearize's K·Ω² + k·δΩ: "
          "amplitude, phase error |")
    print("|---|---|---|---|")
    w0s = np.array([0.03, 0.1, 0.3, 1.0])
    A, B, C, D = qft.torque_general_form(model, v, w0s)
    G = 2 * K * om0 - torque_law_response(model, law, v, w0s)
    for i, w0 in enumerate(w0s):
        measured = _small_amplitude(model, zero, law, v, w0)
        lin, idx = (A[i] + B[i] * G[i]) / (C[i] + D[i] * G[i]), (A[i] - B[i] * k) / (C[i] - D[i] * k)
        cells = [f"{100 * (abs(x / measured) - 1):+.2f} %, {np.degrees(np.angle(x / measured)):+.2f}°" for x in (lin, idx)]
        print(f"| {w0:g} | {abs(measured) / 1e6:.2f} | {cells[0]} | {cells[1]} |")


def _small_amplitude(model, ctrl, law, v, w0, amp=0.02, settle=600.0):
    """T_MyT,w(jω₀) of the nonlinear loop: the first harmonic of the tower-base moment (N·m per m/s) under v + amp·sin(ω₀t)."""
    dur = np.ceil(600.0 / (2 * np.pi / w0)) * 2 * np.pi / w0
    t = np.arange(0.0, settle + dur + 1.0, 0.1)
    r = simulate(model, ctrl, [v], wind=(v + amp * np.sin(w0 * t))[None, None], duration=round(dur, 1), transient=settle,
                 torque_control=law, wind_dt=0.1)
    tt = r.time + settle
    c = np.linalg.lstsq(np.column_stack([np.sin(w0 * tt), np.cos(w0 * tt), np.ones_like(tt)]), r["tower_base_my"][0, 0],
                        rcond=None)[0]
    return (c[0] + 1j * c[1]) / amp


def _merge(a, b, names):
    """Campaign ``a`` with ``b``'s controllers added under ``names`` (same speeds and seeds)."""
    idx = [b.controllers.index(n) for n in names]
    values = {k: np.concatenate([a.values[k], b.values[k][idx]]) for k in a.values}
    return dataclasses.replace(a, controllers=tuple(a.controllers) + tuple(f"{n}, stiff torque" for n in names),
                               values=values, predicted_del=np.concatenate([a.predicted_del, b.predicted_del[idx]]),
                               unstable=np.concatenate([a.unstable, b.unstable[idx]]), welch=None, predicted_psd=None,
                               series=None, linear_values=None, volterra_values=None)


def every_bin(model, n_seeds=6, duration=600.0):
    print(f"\n## Every wind bin 3-25 m/s (2 m/s) x {n_seeds} paired seeds x {duration:g} s; seed paper's Weibull "
          "climate (k 2.2, A 11.29 m/s)")
    t0 = time.perf_counter()
    climate = validate.weibull_bins(validate.WEIBULL_K, scale=validate.WEIBULL_A)
    ctrls = {"ROSCO": rosco_scheduled(model),
             "QFT 15-25": schedule(model, DEMO_DESIGNS, "QFT 15-25"),
             "QFT 13-25": schedule(model, LIFETIME_DESIGNS, "QFT 13-25")}
    kw = {"model": model, "duration": duration, "progress": False}
    camp = validate.run_campaign(ctrls, climate.centres, n_seeds, torque_control="rosco", **kw)
    stiff = validate.run_campaign(ctrls, climate.centres, n_seeds, torque_control=stiff_torque_law(model), **kw)
    both = _merge(camp, stiff, ["ROSCO", "QFT 13-25"])
    print("ROSCO's law in every run; 'stiff torque': the same pitch controllers with the stiffer torque loop "
          "(mode 3, gains x 3, reference 0.02 rad/s) in every run.")
    names = list(both.controllers)
    print("| v (m/s) | p | " + " | ".join(f"{n}: tower DEL change (%) ± SE, power (%)" for n in names[1:]) + " |")
    print("|---|---|" + "---|" * (len(names) - 1))
    tower, power = both.values["tower_del"], both.values["mean_power"]
    for w, v in enumerate(climate.centres):
        cells = []
        for i in range(1, len(names)):
            ch, se = _paired_change(tower[i, w], tower[0, w])
            cells.append(f"{ch:+.1f} ± {se:.1f}, {100 * (power[i, w].mean() / power[0, w].mean() - 1):+.2f}")
        print(f"| {v:g} | {climate.probabilities[w]:.3f} | " + " | ".join(cells) + " |")
    life = validate.lifetime(both, climate, baseline="ROSCO")
    energy = climate.probabilities @ power.mean(axis=2).T
    print("| lifetime | | " + " | ".join(
        f"{life.change[i, 0]:+.2f} ± {life.change_se[i, 0]:.2f}, {100 * (energy[i] / energy[0] - 1):+.2f}"
        for i in range(1, len(names))) + " |")
    print("Lifetime tower-base DEL: " + ", ".join(f"{n} {life.del_life[i, 0] / 1e6:.2f} MN·m" for i, n in enumerate(names))
          + f"; ROSCO's damage share below rated (3-9 m/s bins): {_share(life, climate, 0):.1f} %")
    print(f"({time.perf_counter() - t0:.0f} s with the designs)")


def _share(life, climate, i):
    """Share (%) of the baseline's lifetime damage in the bins below rated (centres < 10 m/s)."""
    below = np.asarray(climate.centres) < 10.0
    return 100 * float(np.asarray(life.damage_share)[i, 0, below].sum())

def held_below_rated(model):
    print("\n## A design held below rated: its pitch for a sustained speed deficit (linear, unsaturated) and at 3 m/s")
    law = model.torque_control
    deficit = law.pitch_reference_speed - law.min_speed
    print(f"β = −C·δΩ_g for a step δΩ_g = −{deficit:.3f} rad/s (the pitch controller's reference "
          f"{law.pitch_reference_speed:.3f} rad/s minus the torque law's minimum speed {law.min_speed:.4f}; "
          "qft.fine_pitch_lift is its largest β); then the 3 m/s run from the trim (seed 1, ROSCO's torque law):")
    print("| controller | fine_pitch_lift (deg) | β max at (s) | β at 1 s / 5 s / 20 s (deg) | 3 m/s run: Ω at 0, 5, 10, 15 s (rad/s) | pitch max in 0-20 s (deg) |")
    print("|---|---|---|---|---|---|")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ctrls = {"QFT 13 m/s (20 %, |S| ≤ 2.2)": qft.design_qft(model, 13.0, 20.0, max_sensitivity=2.2).pitch_controller,
                 "QFT 15 m/s (25 %)": qft.design_qft(model, 15.0, 25.0).pitch_controller,
                 "ROSCO's PI at 13 m/s": rosco_baseline(model, 13.0)}
    t = np.linspace(0.0, 20.0, 2001)
    for name, c in ctrls.items():
        _, y = ct.step_response(ct.ss(c), t)
        beta = np.degrees(deficit * np.squeeze(y))
        v = 13.0 if "13" in name else 15.0
        r = simulate(model, scheduled(model, {v: ct.tf(c)}, name="held"), [3.0], seeds=[1], duration=20.0, transient=0.0,
                     torque_control="rosco")
        om, pitch = r["gen_speed"][0, 0], np.degrees(r["pitch"][0, 0])
        at = [round(s / 20.0 * (om.size - 1)) for s in (0.0, 5.0, 10.0, 15.0)]
        print(f"| {name} | {np.degrees(qft.fine_pitch_lift(c, deficit)):+.1f} | {t[beta.argmax()]:.1f} "
              f"| {beta[100]:+.1f} / {beta[500]:+.1f} / {beta[-1]:+.1f} "
              f"| {', '.join(f'{om[i]:.3f}' for i in at)} | {pitch.max():.2f} |")


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--part", default="all", choices=["analysis", "designs", "held", "transition", "torque", "torque_design", "torque_gap",
                                                     "bins", "all"])
    part = ap.parse_args().part
    m = iea15mw()
    if part in ("analysis", "all"):
        analysis(m)
    if part in ("designs", "all"):
        designs_near_rated(m)
    if part in ("held", "all"):
        held_below_rated(m)
    if part in ("transition", "all"):
        transition(m)
    if part in ("torque", "all"):
        torque_loop(m)
        torque_law_nonlinear(m)
    if part in ("torque_design", "all"):
        torque_design(m)
    if part in ("torque_gap", "all"):
        torque_gap(m)
    if part in ("bins", "all"):
        every_bin(m)
