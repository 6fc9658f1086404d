"""The design loop on the shipped floating IEA 15 MW OpenFAST linearisation (issue 15 part 2).

    python benchmarks/floating_lin.py

Prints what docs/turbines.md ("Designs on OpenFAST linearisations") quotes: the set read
from ``sample_floating_19mps.1.lin`` (one speed, so the plant cases are 19 m/s only), the
platform-pitch mode of the closed loop against the rotor-speed bandwidth of ROSCO's pole
placement, the baseline's ΔD%(ω) and where it lies, the notch specifications that
``spec.shape_to_target`` finds, and the feasibility conditions of
:mod:`specdesign.feasibility` for them (pointwise disks by ``sensitivity_disks``; the
right-half-plane zeros of P_{Ω,β} for the Poisson condition), each with the speed
specification relaxed by 0, 3 and 6 dB and M_s = 2.
"""
from __future__ import annotations

import warnings
from importlib import resources

import control
import numpy as np

from specdesign import spec
from specdesign.closedloop import closed_loop_matrices
from specdesign.feasibility import sensitivity_disks
from specdesign.openfast import LinearTurbine, RotorModelSchedule
from specdesign.rosco import rosco_baseline
from specdesign.validate import linear_prediction

V = 19.0
BANDS = ((0.0, 0.1), (0.1, 0.3), (0.3, 0.6), (0.6, 1.5), (1.5, 10.0))


def platform_mode(A, labels):
    """(ω, ζ) of the eigenvalue whose mode moves the platform pitch most, relative to the
    ElastoDyn degrees of freedom (HydroDyn's radiation states have other scales). ``labels``
    name the first states of ``A`` (the plant's; a closed loop's controller states follow)."""
    lam, vec = np.linalg.eig(A)
    ed = [i for i, x in enumerate(labels) if x.startswith("ED ")]
    k = next(i for i, x in enumerate(labels) if x.startswith("ED Platform pitch tilt rotation DOF"))
    norm = np.linalg.norm(vec[ed], axis=0)
    ok = (norm > 1e-9 * np.abs(vec).max(axis=0)) & (lam.imag > 0.05)  # oscillatory, upper half-plane, moving ED
    part = np.where(ok, np.abs(vec[k]) / np.where(ok, norm, 1.0), 0.0)
    z = lam[np.argmax(part)]
    return abs(z), -z.real / abs(z)


def pointwise(plant, w, tower, speed, ms=2.0):
    d = sensitivity_disks(plant, w, tower, speed, ms)
    r = np.minimum(d["r_speed"], d["r_margin"])
    gap = np.abs(d["c"]) - d["rho"] - r  # > 0: the disks miss each other
    bad = gap > 0
    return bad, d


def main():
    path = resources.files("specdesign") / "data/iea15mw/sample_floating_19mps.1.lin"
    lt = LinearTurbine.from_lin_files(path)
    plant = lt.linearize(V)
    op = lt.trim(V)
    print(f"set: {lt.name}, wind speeds {lt.wind_speeds.tolist()} m/s (plant cases: {V:g} m/s only), "
          f"{plant.nstates} states, rotor radius {lt.rotor_radius:.2f} m (from RtArea)")
    print(f"operating point: rotor {op.rotor_speed:.4f} rad/s, pitch {np.degrees(op.pitch):.2f} deg, "
          f"generator torque {op.gen_torque / 1e6:.2f} MN·m")
    gain_p, gain_i = lt.schedule.gains(V)
    print(f"ROSCO pole placement (omega_pc 0.2, zeta 1): Kp {float(gain_p):.4f} s, Ki {float(gain_i):.4f}")
    kp = lt.kernel_plant()
    labels = list(plant.state_labels)
    w_ptfm, z_ptfm = platform_mode(np.asarray(plant.A), labels)
    print(f"open loop (pitch fixed): platform-pitch mode {w_ptfm:.3f} rad/s, zeta {z_ptfm:.3f}")
    print("\nclosed loop, ROSCO's PI by pole placement, platform-pitch mode vs omega_pc:")
    print("omega_pc rad/s | mode rad/s | zeta")
    for wpc in (0.1, 0.15, 0.2, 0.25, 0.3, 0.4):
        c = rosco_baseline(lt, V, schedule=RotorModelSchedule(lt, omega_pc=wpc))
        acl, _ = closed_loop_matrices(kp, c, V)
        wm, zm = platform_mode(acl, labels)
        print(f"{wpc:14.2f} | {wm:10.3f} | {zm:+.4f}")

    base = spec.baseline_analysis(lt, V)
    w, s = base.omega, base.sensitivity
    print(f"\nbaseline (omega_pc 0.2): tower-base DEL {base.del_1hz / 1e6:.1f} MN·m (Dirlik, m = 4, 1 Hz, class B); "
          f"sum of DeltaD% {s.sum():.3f}")
    print(f"DeltaD% peak {s.max():.3f} % at {w[np.argmax(s)]:.3f} rad/s")
    shares = []
    for lo, hi in BANDS:
        sel = (w >= lo) & (w < hi)
        shares.append(f"{lo:g}-{hi:g} rad/s {100 * s[sel].sum() / s.sum():.1f} %")
    print("share of sum DeltaD% by band: " + ", ".join(shares))
    pred = linear_prediction(lt, lt.baseline_controller(V), V)
    print(f"linear prediction (validate.linear_prediction, 600 s grid): DEL {pred.del_ / 1e6:.1f} MN·m, "
          f"SD {pred.sd / 1e6:.2f} MN·m")

    z = control.zeros(plant["gen_speed", "pitch_cmd"])
    rhp = z[(z.real > 0) & np.isfinite(z)]
    print(f"\nright-half-plane zeros of P_Omega,beta: {np.round(rhp, 4).tolist() if rhp.size else 'none'} "
          "(so the Poisson condition is void; the pointwise one decides)")
    t_speed = np.abs(spec.speed_specification(lt, V).response(w))
    print("\nfeasibility, pointwise disks (M_s = 2), speed spec = baseline T_Omega,w relaxed by g dB:")
    print("specification | promised DEL % | g = 0 dB | g = 3 dB | g = 6 dB")
    cases = [("baseline T_MyT,w itself", None, 0.6)]
    for target, keep in ((15.0, 0.6), (15.0, 0.1), (50.0, 0.1), (75.0, 0.1)):
        cases.append((f"{target:g} % damage, notches above {keep:g} rad/s", target, keep))
    for label, target, keep in cases:
        if target is None:
            tower, promised = np.abs(base.t_response), 0.0
        else:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)
                res = spec.shape_to_target(base, target, keep_below=keep)
            tower = np.abs(res.specification.response(w))
            promised = res.promise.exact_del
            label += " [" + ", ".join(f"{n.omega_n:.3f} rad/s {n.depth_db:.1f} dB" for n in res.notches) + "]"
        cells = []
        for g in (0.0, 3.0, 6.0):
            bad, _ = pointwise(plant, w, tower, t_speed * 10 ** (g / 20))
            cells.append("feasible" if not bad.any() else f"fails {w[bad].min():.3f}-{w[bad].max():.3f} rad/s")
        print(f"{label} | {promised:.2f} | " + " | ".join(cells))


if __name__ == "__main__":
    main()
