"""Why the nonlinear simulation departs from the linear prediction of the DEL reduction (issue 7).

QFT (pitch + ATD, ``design_qft``) vs ROSCO (tower damping off), fixed controllers at one
operating point (default 19 m/s), ``--seeds`` paired seeds × 600 s. Every experiment runs
on the SAME wind series (paired), so the differences between rows are causal, not sampling:

A  baseline: linear prediction (Dirlik on |T|²S_W), rainflow on the linearised model,
   rainflow on the nonlinear model; per-controller DEL ratio nonlinear/linear.
B  mean state of the nonlinear runs vs the trim (pitch, rotor speed, thrust, tower).
C  turbulence scaling: wind fluctuation × a; deviation nonlinear − linear vs a.
D  which nonlinearity: hybrid kernels (a ``KernelPlant`` with its own numba rhs) that
   replace the aerodynamic torque and/or the thrust by their first-order Taylor expansion
   at the trim (in Ω, v_rel = w − ẋ_top, β), or that freeze v_rel → w in the aerodynamics.
E  saturations (pitch-rate / position limits off) and the integration/controller step.
F  frequency range and wind spectrum: synthesised variance vs ∫S_W, prediction grids.
G  a quasi-static operating-point mixture of linear predictions (does it explain the rest?).

Run: python benchmarks/nonlinearity.py [--seeds 40] [--speed 19] [--quick]
Controllers are designed on the fly (≈ 10 s per speed) and cached as JSON in build/cache
(inside the project, git-ignored), keyed by a hash of the code that designs them (every
module of specdesign/ and loopshaping/, the package data), the turbine model's parameters,
the wind speed and the library versions: any change is a new key, never a stale design.
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np
from numba import njit

from specdesign import spectral, validate
from specdesign import turbine as tb
from specdesign import wind as wmod
from specdesign.simulate import (
    KernelPlant,
    scheduled,
    simulate,
    turbine_plant,
    wind_series,
)

M = 4.0
DUR, TRANS, DT, RDT = 600.0, 60.0, 0.02, 0.1

# ----------------------------------------------------------------------------- hybrid kernel
# Extra parameter block appended to the turbine's parameter array; its offset sits in the
# unused header slot 19. Layout: [mode flags (4), Ω0, v0, β0, Q0, T0, dQ/dΩ, dQ/dv, dQ/dβ,
# dT/dΩ, dT/dv, dT/dβ].  Flags: linearise torque, linearise thrust, freeze v_rel (use w,
# with the −∂/∂v·ẋ_top term added linearly), unused.
_OFF = 19


@njit(cache=True)
def hybrid_rhs(x, wind, pitch_cmd, gen_torque, p, dx):
    # the model's own aerodynamics and mechanics: the hybrids differ from it only where intended
    omega, qd, beta = x[0], x[2], x[3]
    o = int(p[_OFF])
    lin_q, lin_t, frz = p[o] > 0.5, p[o + 1] > 0.5, p[o + 2] > 0.5
    om0, v0, b0, q0, t0 = p[o + 4], p[o + 5], p[o + 6], p[o + 7], p[o + 8]
    if frz:
        torque, thrust = tb.aero_loads(p, omega, wind, beta)
        torque -= p[o + 10] * qd
        thrust -= p[o + 13] * qd
    else:
        torque, thrust = tb.aero_loads(p, omega, wind - qd, beta)
    dom, dv, db = omega - om0, wind - qd - v0, beta - b0
    if p[o + 3] > 0.5:
        # Second-order Taylor expansion of both torque and thrust; mask picks the quadratic
        # terms (ΩΩ, vv, ββ, Ωv, Ωβ, vβ), Hessians of Q then T follow the mask.
        z0 = dom * dom * 0.5
        z1 = dv * dv * 0.5
        z2 = db * db * 0.5
        z3 = dom * dv
        z4 = dom * db
        z5 = dv * db
        torque = q0 + p[o + 9] * dom + p[o + 10] * dv + p[o + 11] * db
        thrust = t0 + p[o + 12] * dom + p[o + 13] * dv + p[o + 14] * db
        zs = (z0, z1, z2, z3, z4, z5)
        for k in range(6):
            torque += p[o + 15 + k] * p[o + 21 + k] * zs[k]
            thrust += p[o + 15 + k] * p[o + 27 + k] * zs[k]
    if lin_q:
        torque = q0 + p[o + 9] * dom + p[o + 10] * dv + p[o + 11] * db
    if lin_t:
        thrust = t0 + p[o + 12] * dom + p[o + 13] * dv + p[o + 14] * db
    tb.mechanics(x, torque, thrust, pitch_cmd, gen_torque, p, dx)


@njit(cache=True)
def hybrid_outputs(x, wind, pitch_cmd, gen_torque, p, y):
    dx = np.empty(5)
    hybrid_rhs(x, wind, pitch_cmd, gen_torque, p, dx)
    tb.outputs_from(x, dx, gen_torque, p, y)


def aero_derivatives(model, v):
    """(Q0, T0, [dQ/dΩ, dQ/dv, dQ/dβ], [dT/dΩ, dT/dv, dT/dβ]) at the trim, central differences."""
    op = model.trim(v)
    p = model.kernel_params()
    x0 = np.array([op.rotor_speed, v, op.pitch])
    h = np.array([1e-5, 1e-4, 1e-6])
    q0, t0 = tb.aero_loads(p, *x0)
    dq, dt_ = np.empty(3), np.empty(3)
    for k in range(3):
        a, b = x0.copy(), x0.copy()
        a[k] += h[k]
        b[k] -= h[k]
        qa, ta = tb.aero_loads(p, *a)
        qb, tb_ = tb.aero_loads(p, *b)
        dq[k], dt_[k] = (qa - qb) / (2 * h[k]), (ta - tb_) / (2 * h[k])
    return q0, t0, dq, dt_


def aero_hessians(model, v):
    """Second derivatives of (Q, T) at the trim in (Ω, v, β): terms (ΩΩ, vv, ββ, Ωv, Ωβ, vβ)."""
    op = model.trim(v)
    p = model.kernel_params()
    x0 = np.array([op.rotor_speed, v, op.pitch])
    h = np.array([2e-3, 2e-2, 2e-4])
    pairs = [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)]
    hq, ht = np.empty(6), np.empty(6)
    for n, (i, j) in enumerate(pairs):
        acc = np.zeros(2)
        for si, sj, sg in ((1, 1, 1), (1, -1, -1), (-1, 1, -1), (-1, -1, 1)):
            x = x0.copy()
            x[i] += si * h[i]
            x[j] += sj * h[j]
            acc += sg * np.array(tb.aero_loads(p, *x))
        acc /= 4 * h[i] * h[j]
        hq[n], ht[n] = acc
    return hq, ht


QUAD_TERMS = ("ΩΩ", "vv", "ββ", "Ωv", "Ωβ", "vβ")


def hybrid_plant(model, v, *, lin_torque=False, lin_thrust=False, freeze_vrel=False, rate_limit=None,
                 pitch_limits=None, quad=None):
    """KernelPlant of the reduced model with selected terms linearised at the trim of ``v``.

    quad : None, or a 6-sequence of 0/1 selecting the quadratic terms (:data:`QUAD_TERMS`) of
    a second-order Taylor model of both torque and thrust (replaces the full aerodynamics).
    """
    base = turbine_plant(model)
    p = model.kernel_params()
    op = model.trim(v)
    q0, t0, dq, dt_ = aero_derivatives(model, v)
    hq, ht = aero_hessians(model, v)
    mask = np.zeros(6) if quad is None else np.asarray(quad, float)
    extra = np.array([float(lin_torque), float(lin_thrust), float(freeze_vrel), float(quad is not None),
                      op.rotor_speed, v, op.pitch, q0, t0, *dq, *dt_, *mask, *hq, *ht])
    p = np.concatenate([p, extra])
    p[_OFF] = p.size - extra.size
    if rate_limit is not None:
        p[tb.P_RATE_LIM] = rate_limit
    if pitch_limits is not None:
        p[tb.P_PITCH_MIN], p[tb.P_PITCH_MAX] = pitch_limits
    return KernelPlant(rhs=hybrid_rhs, outputs=hybrid_outputs, params=np.ascontiguousarray(p),
                       output_names=base.output_names, trim=base.trim, rated_speed=base.rated_speed,
                       linearize=base.linearize, name="hybrid")


def saturated_plant(model, rate_limit=None, pitch_limits=None):
    base = turbine_plant(model)
    p = model.kernel_params()
    if rate_limit is not None:
        p[tb.P_RATE_LIM] = rate_limit
    if pitch_limits is not None:
        p[tb.P_PITCH_MIN], p[tb.P_PITCH_MAX] = pitch_limits
    return KernelPlant(rhs=base.rhs, outputs=base.outputs, params=np.ascontiguousarray(p), output_names=base.output_names,
                       trim=base.trim, rated_speed=base.rated_speed, linearize=base.linearize, name="sat")


# ----------------------------------------------------------------------------- ROSCO-style scheduling
def rosco_integral_scheduled(model, v, dt=DT, wind_speeds=None, filter_omega=0.1):
    """ROSCO's own gain scheduling as a callable ``f(t, y)``: β = Kp(β_f)·e_f + ∫Ki(β_f)·e_f dt,
    e_f = Ω_rated − F_lpf·Ω, gains of :func:`specdesign.turbine.rosco_baseline` interpolated in
    the filtered pitch command β_f (first-order, ``filter_omega`` rad/s), as
    :func:`specdesign.simulate.rosco_scheduled` uses, but scheduled *inside* the integral
    instead of by output blending. The integrator starts at the trim pitch of ``v``."""
    from specdesign.simulate import tustin_matrices

    if wind_speeds is None:
        wind_speeds = np.arange(11.0, 25.5, 1.0)
    sched = tb.rosco_gain_schedule(model)
    pa, pb = np.polyfit(sched.v, sched.A, 1), np.polyfit(sched.v, sched.B_beta, 1)
    a, b = np.polyval(pa, wind_speeds), np.polyval(pb, wind_speeds)
    kp = (2 * sched.zeta_pc * sched.omega_pc + a) / b
    ki = sched.omega_pc**2 / b
    bs = np.array([model.trim(s).pitch for s in wind_speeds])
    Af, Bf, Cf, Df = tustin_matrices(tb.speed_filter(), dt)
    beta0, om_ref = model.trim(v).pitch, model.rated_rotor_speed
    a_f = 1.0 - np.exp(-filter_omega * dt)
    st = {}

    def f(t, y):
        om = y["gen_speed"]
        if not st:
            n = om.size
            st.update(x=np.zeros((n, Af.shape[0])), i=np.full(n, beta0), bf=np.full(n, beta0), e=np.zeros(n))
        x = st["x"]
        d = om - om_ref
        of = x @ Cf + Df[0] * d
        st["x"] = x @ Af.T + np.outer(d, Bf)
        e = -of
        bf = st["bf"]
        kpi, kii = np.interp(bf, bs, kp), np.interp(bf, bs, ki)
        st["i"] = st["i"] + kii * 0.5 * dt * (e + st["e"])
        st["e"] = e
        cmd = st["i"] + kpi * e
        st["bf"] = bf + a_f * (cmd - bf)
        return cmd

    return f


# ----------------------------------------------------------------------------- helpers
CACHE = Path(__file__).resolve().parents[1] / "build" / "cache"  # the project's build folder (git-ignored)
# the code a design depends on: every module of both packages and the shipped data (a design
# reaches through many of them; hashing them all can only invalidate too often, never too rarely)
_DESIGN_SOURCES = ("specdesign", "loopshaping")


def _design_key(model, v) -> str:
    """sha256 of the design code, the package data, the model's parameters, v and the library
    versions: what ``design_qft(model, v)`` depends on."""
    import dataclasses
    import hashlib
    import importlib.metadata as md

    root = Path(__file__).resolve().parents[1]
    h = hashlib.sha256()
    for pkg in _DESIGN_SOURCES:
        for f in sorted((root / pkg).rglob("*")):
            if f.is_file() and (f.suffix == ".py" or "data" in f.relative_to(root / pkg).parts):
                h.update(str(f.relative_to(root)).encode() + b"\0" + f.read_bytes() + b"\0")
    for fld in dataclasses.fields(model):
        val = getattr(model, fld.name)
        h.update(fld.name.encode() + b"=" + (np.ascontiguousarray(val).tobytes() if isinstance(val, np.ndarray)
                                             else repr(val).encode()) + b"\0")
    versions = []
    for lib in ("numpy", "scipy", "control", "cvxpy", "numba"):
        try:
            versions.append(f"{lib} {md.version(lib)}")
        except md.PackageNotFoundError:
            versions.append(f"{lib} -")
    # the key names the notch design as it was called when the cache was made (spec='notch', now
    # spec=spec_notch(): the same design), so that the cached designs stay valid
    h.update(f"design_qft(model, {float(v)!r}, spec='notch') {'; '.join(versions)}".encode())
    return h.hexdigest()


def _design_file(model, v):
    return CACHE / f"qft_{float(v):g}mps_{_design_key(model, v)[:20]}.json"


def designs_for(model, v):
    """(C_β, C_atd) of design_qft(model, v, spec=spec_notch()), cached as JSON transfer functions under
    build/cache, keyed by the design code, the model, v and the library versions
    (:func:`_design_key`); an unreadable cache file is designed again and replaced."""
    import os

    import control

    from specdesign.qft import design_qft, spec_notch

    f = _design_file(model, v)
    if f.exists():
        try:
            data = json.loads(f.read_text())
            return tuple(control.tf(data[k]["num"], data[k]["den"]) for k in ("pitch", "atd"))
        except (ValueError, KeyError, TypeError) as e:
            print(f"cache file {f} is unreadable ({e}); designing again")
    d = design_qft(model, v, spec=spec_notch())
    out = (d.pitch_controller, d.atd_controller)
    f.parent.mkdir(parents=True, exist_ok=True)
    tmp = f.with_name(f"{f.name}.{os.getpid()}.tmp")  # written whole, then renamed: no half-written cache file
    tmp.write_text(json.dumps({k: {"num": list(map(float, c.num[0][0])), "den": list(map(float, c.den[0][0]))}
                               for k, c in zip(("pitch", "atd"), out)}))
    os.replace(tmp, f)
    return out


def the_wind(model, v, seeds, scale=1.0, dt_wind=RDT, duration=DUR):
    w = wind_series(model.rotor_radius, [v], seeds, TRANS + duration + dt_wind, dt_wind)
    return v + scale * (w - v)


def run(plant, ctrls, v, wind, *, linear=False, dt=DT, wind_dt=RDT, duration=DUR):
    """Per controller: (DEL per seed, SimulationResult)."""
    out = {}
    for name, c in ctrls.items():
        r = simulate(plant, c, [v], wind=wind, wind_dt=wind_dt, duration=duration, dt=dt, record_dt=RDT,
                     transient=TRANS, linear=linear)
        out[name] = (validate.indicators(r.outputs, r.dt, M).tower_del[0], r)
    return out


def reduction(res):
    ch = validate.paired_change(res["QFT"][0][None], res["ROSCO"][0][None], "tower_del", m=M)
    return float(-ch.change[0]), float(ch.se[0])


def pooled(d):
    return float(np.mean(d**M) ** (1 / M))


def dev_vs(res, ref):
    """Deviation (pp) of res's reduction from ref's, with the jackknife SE of that difference."""
    def red(a, b):
        return 100 * (1 - pooled(a) / pooled(b))

    qa, ra, qb, rb = res["QFT"][0], res["ROSCO"][0], ref["QFT"][0], ref["ROSCO"][0]
    est = red(qa, ra) - red(qb, rb)
    S = qa.size
    reps = np.array([red(np.delete(qa, i), np.delete(ra, i)) - red(np.delete(qb, i), np.delete(rb, i)) for i in range(S)])
    return est, float(np.sqrt((S - 1) / S * np.sum((reps - reps.mean()) ** 2)))


def record_spectrum(model, w, v):
    """S_W at v weighted by the variance a DUR-long record has about its own mean, as
    ``validate.linear_prediction`` weights it (``wind.record_window``)."""
    return wmod.rotor_effective_spectrum(w, v, model.rotor_radius) * wmod.record_window(w, DUR)


def prediction(model, ctrls, v, omega=None, plant_speed=None, spectrum_speed=None, method="dirlik"):
    """Linear-prediction DELs {name: DEL} (``method``, default Dirlik) on the record-windowed S_W,
    as ``validate.linear_prediction`` computes it; plant linearised at plant_speed (default v)
    while the controllers stay those of ``v``; S_W at spectrum_speed (default v)."""
    w = validate.prediction_grid(DUR) if omega is None else omega
    pv = v if plant_speed is None else plant_speed
    sw = record_spectrum(model, w, v if spectrum_speed is None else spectrum_speed)
    out = {}
    for name, c in ctrls.items():
        t = validate.closed_loop_response(model, c, pv, w)
        out[name] = float(spectral.del_spectral(w, np.abs(t) ** 2 * sw, M, method=method))
    return out


def pred_red(p):
    return 100 * (1 - p["QFT"] / p["ROSCO"])


def table(title, header, rows):
    print(f"\n### {title}\n")
    print("| " + " | ".join(header) + " |")
    print("|" + "|".join("---" for _ in header) + "|")
    for r in rows:
        print("| " + " | ".join(r) + " |")


# ----------------------------------------------------------------------------- experiments
def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seeds", type=int, default=40)
    ap.add_argument("--speed", type=float, default=19.0)
    ap.add_argument("--quick", action="store_true", help="skip the slower experiments (E dt, G)")
    args = ap.parse_args(argv)
    t0 = time.time()
    model = tb.iea15mw()
    v = args.speed
    seeds = np.arange(args.seeds)
    cb, ca = designs_for(model, v)
    ctrls = {"ROSCO": tb.rosco_baseline(model, v), "QFT": scheduled(model, {v: cb}, atd={v: ca}, name="QFT")}
    wind = the_wind(model, v, seeds)
    pred = prediction(model, ctrls, v)
    lin = run(model, ctrls, v, wind, linear=True)
    nl = run(model, ctrls, v, wind)
    pr = pred_red(pred)

    # A ---------------------------------------------------------------------------------
    rl, sl = reduction(lin)
    rn, sn = reduction(nl)
    d_nl, s_nl = dev_vs(nl, lin)
    rows = [["linear prediction (Dirlik, |T|²S_W)", f"{pred['ROSCO'] / 1e6:.1f}", f"{pred['QFT'] / 1e6:.1f}", f"{pr:.2f}", "", ""],
            ["rainflow, linearised model", f"{pooled(lin['ROSCO'][0]) / 1e6:.1f}", f"{pooled(lin['QFT'][0]) / 1e6:.1f}",
             f"{rl:.2f} ± {sl:.2f}", f"{rl - pr:+.2f}", ""],
            ["rainflow, nonlinear model", f"{pooled(nl['ROSCO'][0]) / 1e6:.1f}", f"{pooled(nl['QFT'][0]) / 1e6:.1f}",
             f"{rn:.2f} ± {sn:.2f}", f"{rn - pr:+.2f}", f"{d_nl:+.2f} ± {s_nl:.2f}"]]
    table(f"A. {v:g} m/s, {args.seeds} paired seeds × {DUR:g} s: DEL (MN·m) and reduction",
          ["evaluation", "DEL ROSCO", "DEL QFT", "reduction %", "− prediction (pp)", "− linear sim (pp)"], rows)
    print(f"\nDEL ratio nonlinear/linear: ROSCO {pooled(nl['ROSCO'][0]) / pooled(lin['ROSCO'][0]):.4f}, "
          f"QFT {pooled(nl['QFT'][0]) / pooled(lin['QFT'][0]):.4f}")
    # Std and higher moments of the tower-base moment, nonlinear vs linear
    rows = []
    for name in ctrls:
        for lab, res in (("linear", lin), ("nonlinear", nl)):
            y = res[name][1]["tower_base_my"][0]
            yc = y - y.mean(axis=-1, keepdims=True)
            sd = np.sqrt(np.mean(yc**2))
            sk = np.mean(np.mean(yc**3, axis=-1) / np.mean(yc**2, axis=-1) ** 1.5)
            ku = np.mean(np.mean(yc**4, axis=-1) / np.mean(yc**2, axis=-1) ** 2)
            rows.append([name, lab, f"{sd / 1e6:.2f}", f"{sk:+.3f}", f"{ku:.3f}"])
    table("A2. tower-base moment: SD (MN·m), skewness, kurtosis (mean over seeds)",
          ["controller", "model", "SD", "skewness", "kurtosis"], rows)
    bands = ((0.0, 0.3), (0.3, 0.8), (0.8, 1.4), (1.4, 100.0))
    rows = []
    for name in ctrls:
        om, pl = validate.welch_psd(lin[name][1]["tower_base_my"][0], RDT, 1024)
        _, pn = validate.welch_psd(nl[name][1]["tower_base_my"][0], RDT, 1024)
        pl, pn = pl.mean(0), pn.mean(0)
        tot = np.trapezoid(pl, om)
        cells = []
        for lo, hi in bands:
            k = (om >= lo) & (om < hi)
            cells.append(f"{100 * np.trapezoid(pl[k], om[k]) / tot:.1f} / {100 * (np.trapezoid(pn[k], om[k]) - np.trapezoid(pl[k], om[k])) / tot:+.2f}")
        rows.append([name] + cells)
    table("A3. tower-base moment variance by band (Welch, 102.4 s segments): linear share % / nonlinear − linear, % of linear total",
          ["controller"] + [f"{lo:g}-{hi:g} rad/s" for lo, hi in bands], rows)

    # B ---------------------------------------------------------------------------------
    op = model.trim(v)
    rows = []
    for name in ctrls:
        r = nl[name][1]
        om = r["gen_speed"][0].mean()
        be = r["pitch"][0].mean()
        thr = r["tower_base_my"][0].mean() / model.tower_base_moment_per_m * model.tower_modal_stiffness
        rl_ = lin[name][1]
        rows.append([name, f"{np.rad2deg(be):.3f} ({np.rad2deg(be - op.pitch):+.3f})",
                     f"{om:.5f} ({om - op.rotor_speed:+.1e})", f"{thr / 1e3:.0f} ({(thr - op.thrust) / op.thrust * 100:+.2f} %)",
                     f"{np.rad2deg(rl_['pitch'][0].mean() - op.pitch):+.4f}"])
    # The wind speed whose trim pitch is the nonlinear mean pitch.
    from scipy.optimize import brentq

    be_m = np.mean([nl[n][1]["pitch"][0].mean() for n in ctrls])
    v_eff = brentq(lambda s: model.trim(s).pitch - be_m, max(v - 3, 11.5), min(v + 3, model.wind_range[1]))
    table(f"B. mean state of the nonlinear runs vs trim (pitch {np.rad2deg(op.pitch):.3f}°, Ω {op.rotor_speed:.5f} rad/s, "
          f"thrust {op.thrust / 1e3:.0f} kN)",
          ["controller", "mean pitch ° (− trim)", "mean Ω rad/s (− trim)", "mean thrust kN (vs trim)", "linear model: mean pitch − trim °"],
          rows)
    p_eff = prediction(model, ctrls, v, plant_speed=v_eff)
    print(f"\nmean pitch ≙ trim at {v_eff:.2f} m/s; prediction with the plant linearised there (S_W at {v:g} m/s): "
          f"{pred_red(p_eff):.2f} % (vs {pr:.2f} %)")

    # C ---------------------------------------------------------------------------------
    rows = []
    for a in (0.25, 0.5, 1.0, 1.5):
        wa = the_wind(model, v, seeds, a)
        la = lin if a == 1.0 else run(model, ctrls, v, wa, linear=True)
        na = nl if a == 1.0 else run(model, ctrls, v, wa)
        d, s = dev_vs(na, la)
        rows.append([f"{a:g}", f"{a * 0.14 * (0.75 * v + 5.6) / v * 100:.1f}", f"{reduction(la)[0]:.2f}", f"{reduction(na)[0]:.2f}",
                     f"{d:+.2f} ± {s:.2f}", f"{d / a**2:+.2f}"])
    table("C. turbulence scaling (wind fluctuation × a, same seeds)",
          ["a", "TI % (point)", "reduction linear sim %", "reduction nonlinear %", "nonlinear − linear (pp)", "÷ a²"], rows)

    # D ---------------------------------------------------------------------------------
    cases = [
        ("full nonlinear (hybrid kernel, check)", {}),
        ("torque linearised", {"lin_torque": True}),
        ("thrust linearised", {"lin_thrust": True}),
        ("torque + thrust linearised (saturations kept)", {"lin_torque": True, "lin_thrust": True}),
        ("v_rel → w in aerodynamics, −∂/∂v·ẋ linear", {"freeze_vrel": True}),
        ("torque + thrust linearised, saturations off", {"lin_torque": True, "lin_thrust": True, "rate_limit": 10.0,
                                                         "pitch_limits": (-1.0, 2.0)}),
    ]
    rows = []
    for lab, kw in cases:
        res = run(hybrid_plant(model, v, **kw), ctrls, v, wind)
        d, s = dev_vs(res, lin)
        rows.append([lab, f"{reduction(res)[0]:.2f}", f"{d:+.2f} ± {s:.2f}",
                     f"{pooled(res['ROSCO'][0]) / pooled(lin['ROSCO'][0]):.4f}", f"{pooled(res['QFT'][0]) / pooled(lin['QFT'][0]):.4f}"])
    for n, term in enumerate(QUAD_TERMS + ("all six",)):
        mask = np.ones(6) if n == 6 else np.eye(6)[n]
        res = run(hybrid_plant(model, v, quad=mask), ctrls, v, wind)
        d, s = dev_vs(res, lin)
        rows.append([f"2nd-order Taylor of Q and T, quadratic term {term}" if n < 6 else "2nd-order Taylor of Q and T, all six terms",
                     f"{reduction(res)[0]:.2f}", f"{d:+.2f} ± {s:.2f}",
                     f"{pooled(res['ROSCO'][0]) / pooled(lin['ROSCO'][0]):.4f}", f"{pooled(res['QFT'][0]) / pooled(lin['QFT'][0]):.4f}"])
    hq, ht = aero_hessians(model, v)
    _, _, dq, dt_ = aero_derivatives(model, v)
    print("\nTrim derivatives (Ω rad/s, v m/s, β rad): dQ/d(Ω, v, β) = " + ", ".join(f"{x:.3e}" for x in dq)
          + "; dT/d(Ω, v, β) = " + ", ".join(f"{x:.3e}" for x in dt_))
    print("Hessian terms (" + ", ".join(QUAD_TERMS) + "): Q " + ", ".join(f"{x:.3e}" for x in hq)
          + "; T " + ", ".join(f"{x:.3e}" for x in ht))
    table("D. which nonlinearity (hybrid kernels, same seeds)",
          ["plant", "reduction %", "− linear sim (pp)", "DEL/linear ROSCO", "DEL/linear QFT"], rows)

    # E ---------------------------------------------------------------------------------
    rows = []
    rate = model.pitch_rate_limit
    for name in ctrls:
        r = nl[name][1]
        prate = np.diff(r["pitch"][0], axis=-1) / r.dt
        rows.append([name, f"{np.rad2deg(np.abs(prate).max()):.2f}", f"{100 * np.mean(np.abs(prate) > 0.98 * rate):.3f}",
                     f"{np.rad2deg(r['pitch'][0].min()):.2f}"])
    table(f"E1. pitch saturations in the nonlinear runs (rate limit {np.rad2deg(rate):.1f}°/s, "
          f"min pitch {np.rad2deg(model.pitch_min):.1f}°)",
          ["controller", "max |pitch rate| °/s", "% of samples ≥ 98 % of the limit", "min pitch °"], rows)
    res = run(saturated_plant(model, rate_limit=10.0, pitch_limits=(-1.0, 2.0)), ctrls, v, wind)
    d, s = dev_vs(res, lin)
    print(f"\nnonlinear plant with saturations removed: reduction {reduction(res)[0]:.2f} %, − linear sim {d:+.2f} ± {s:.2f} pp")
    if not args.quick:
        rows = []
        for dt in (0.01, 0.02, 0.05):
            l2 = lin if dt == DT else run(model, ctrls, v, wind, linear=True, dt=dt)
            n2 = nl if dt == DT else run(model, ctrls, v, wind, dt=dt)
            d, s = dev_vs(n2, l2)
            rows.append([f"{dt:g}", f"{reduction(l2)[0]:.2f}", f"{reduction(l2)[0] - pr:+.2f}", f"{reduction(n2)[0]:.2f}",
                         f"{d:+.2f} ± {s:.2f}"])
        table("E2. integration / controller step (Tustin, command held over the step)",
              ["dt (s)", "reduction linear sim %", "linear sim − prediction (pp)", "reduction nonlinear %", "nonlinear − linear (pp)"],
              rows)

    # F ---------------------------------------------------------------------------------
    wf = wind[0] - v
    rec = wf[:, int(TRANS / RDT):int((TRANS + DUR) / RDT)]
    g = validate.prediction_grid(DUR)
    g0 = np.geomspace(1e-4, 30, 6000)
    sw_full = np.trapezoid(wmod.rotor_effective_spectrum(g0, v, model.rotor_radius), g0)
    sw_rec = np.trapezoid(record_spectrum(model, g, v), g)
    print(f"\n### F. wind spectrum and frequency range\n\nrotor-effective wind variance: ∫S_W over (1e-4, 30) rad/s "
          f"{sw_full:.3f}, ∫S_W·record window over the prediction grid ({g[0]:.2e}, {g[-1]:g}) {sw_rec:.3f}, "
          f"synthesised series (660 s period, mean over seeds) {np.mean(wf.var(axis=-1)):.3f}, within each 600 s record "
          f"{np.mean(rec.var(axis=-1)):.3f} (m/s)²")
    rows = []
    for lab, om in ((f"{g[0]:.2e} … 30 rad/s (default, record-windowed S_W)", g),
                    ("1e-4 … 30", np.geomspace(1e-4, 30, 4000)),
                    ("2π/660 … 30", np.geomspace(2 * np.pi / 660, 30, 3000)),
                    ("2π/600 … 30", np.geomspace(2 * np.pi / 600, 30, 3000)),
                    (f"{g[0]:.2e} … 15", np.geomspace(g[0], 15, 3000))):
        rows.append([lab, f"{pred_red(prediction(model, ctrls, v, omega=om)):.2f}"])
    for meth in ("tovo_benasciutti", "narrowband"):
        rows.append([f"default grid, {meth} instead of Dirlik", f"{pred_red(prediction(model, ctrls, v, method=meth)):.2f}"])
    table("F2. prediction vs frequency grid and spectral method (linear sim gives "
          f"{rl:.2f} %)", ["grid", "predicted reduction %"], rows)

    # G ---------------------------------------------------------------------------------
    if not args.quick:
        # Quasi-static mixture: slow wind (below the closed-loop bandwidth) moves the operating
        # point; the plant is linearised at v + u (controllers fixed), S_W kept at v, damage
        # averaged over u ~ N(0, σ_slow²), σ_slow from S_W below 0.2 rad/s.
        ws = np.geomspace(1e-4, 0.2, 400)
        sig = float(np.sqrt(np.trapezoid(wmod.rotor_effective_spectrum(ws, v, model.rotor_radius), ws)))
        us = np.linspace(-2.5, 2.5, 11) * sig
        wts = np.exp(-0.5 * (us / sig) ** 2)
        wts /= wts.sum()
        dam = {n: 0.0 for n in ctrls}
        for u, wgt in zip(us, wts):
            p = prediction(model, ctrls, v, plant_speed=float(np.clip(v + u, 11.5, 25.0)))
            for n in ctrls:
                dam[n] += wgt * p[n] ** M
        mix = {n: dam[n] ** (1 / M) for n in ctrls}
        print(f"\n### G. quasi-static operating-point mixture\n\nσ of the wind below 0.2 rad/s {sig:.2f} m/s; damage-averaged "
              f"prediction over plants linearised at v + u, u ~ N(0, σ²): reduction {pred_red(mix):.2f} % "
              f"(ROSCO DEL {mix['ROSCO'] / 1e6:.1f}, QFT {mix['QFT'] / 1e6:.1f} MN·m) vs {pr:.2f} % at the trim")
    # H ---------------------------------------------------------------------------------
    sched_speeds = (15.0, 17.0, 19.0, 21.0, 23.0, 25.0)
    if not args.quick and all(_design_file(model, s).exists() for s in sched_speeds):
        from specdesign.simulate import rosco_scheduled

        ds = {s: designs_for(model, s) for s in sched_speeds}
        sch = {"ROSCO": rosco_scheduled(model, form="output"),
               "QFT": scheduled(model, {s: d[0] for s, d in ds.items()}, atd={s: d[1] for s, d in ds.items()}, name="QFT")}
        hp = pred_red(prediction(model, sch, v))
        hl = run(model, sch, v, wind, linear=True)
        hn = run(model, sch, v, wind)
        d, s = dev_vs(hn, hl)
        rows = [["fixed (A)", f"{pr:.2f}", f"{rl:.2f}", f"{rn:.2f}", f"{rl - pr:+.2f}", f"{dev_vs(nl, lin)[0]:+.2f}"],
                ["scheduled on filtered pitch", f"{hp:.2f}", f"{reduction(hl)[0]:.2f}", f"{reduction(hn)[0]:.2f}",
                 f"{reduction(hl)[0] - hp:+.2f}", f"{d:+.2f} ± {s:.2f}"]]
        for name in sch:
            bf = hn[name][1]["pitch_cmd"][0]
            print(f"scheduled {name}: pitch command SD {np.rad2deg(bf.std(axis=-1).mean()):.2f}°, range over the records "
                  f"{np.rad2deg(bf.min()):.1f}-{np.rad2deg(bf.max()):.1f}°")
        table(f"H. gain scheduling (rosco_scheduled vs QFT scheduled at {', '.join(f'{s:g}' for s in sched_speeds)} m/s) at {v:g} m/s",
              ["controllers", "prediction %", "linear sim %", "nonlinear %", "linear sim − prediction (pp)", "nonlinear − linear sim (pp)"],
              rows)
        # I: ROSCO scheduled as ROSCO does it (gains inside the integral) instead of output blending.
        rows = []
        variants = ((f"ROSCO fixed ({v:g} m/s gains)", ctrls["ROSCO"]), ("ROSCO output-blended (rosco_scheduled)", sch["ROSCO"]),
                    ("ROSCO gains inside the integral (callable)", None))
        for lab, c in variants:
            if c is None:
                dl = run(model, {"R": rosco_integral_scheduled(model, v)}, v, wind, linear=True)["R"][0]
                dn = run(model, {"R": rosco_integral_scheduled(model, v)}, v, wind)["R"][0]
            else:
                dl = run(model, {"R": c}, v, wind, linear=True)["R"][0]
                dn = run(model, {"R": c}, v, wind)["R"][0]
            cells = [lab, f"{pooled(dl) / 1e6:.2f}", f"{pooled(dn) / 1e6:.2f}"]
            for qlab, q in (("fixed", nl), ("scheduled", hn)):
                ql = (lin if qlab == "fixed" else hl)["QFT"][0]
                red_l = 100 * (1 - pooled(ql) / pooled(dl))
                red_n = 100 * (1 - pooled(q["QFT"][0]) / pooled(dn))
                cells += [f"{red_l - pr:+.2f}", f"{red_n - pr:+.2f}"]
            rows.append(cells)
        table(f"I. the baseline's scheduling at {v:g} m/s: DEL (MN·m) and deviation from the prediction ({pr:.2f} %) in pp",
              ["ROSCO variant", "DEL linear sim", "DEL nonlinear", "vs fixed QFT: linear sim", "vs fixed QFT: nonlinear",
               "vs scheduled QFT: linear sim", "vs scheduled QFT: nonlinear"], rows)
    print(f"\n(total {time.time() - t0:.0f} s wall clock)")


if __name__ == "__main__":
    main()
