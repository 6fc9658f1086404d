"""QFT engine timings, printed side by side: run ``python benchmarks/bench_qft.py``.

1. Exact bounds for a 1000-case template × 361 phases × 20 frequencies × 3 specs
   (target < 1 s), against brute-force evaluations of the same specs on a 0.25 dB
   magnitude grid (−80…80 dB): evaluating the closed-loop functions directly, and evaluating
   the expanded quadratic (the cheapest per-point arithmetic). The brute forces are timed on
   one of the frequencies and scaled linearly (their cost is exactly proportional to the
   number of frequencies); the grid's bound edges are compared with the exact ones.
2. Interactive designer update (recompute the loop on 600 frequencies, check the bounds,
   push data, blit-redraw with Agg): target < 100 ms.
"""
from __future__ import annotations

import time

import matplotlib

matplotlib.use("Agg")

import control as ct  # noqa: E402
import numpy as np  # noqa: E402
from timing import timed  # noqa: E402

from loopshaping import qft  # noqa: E402
from loopshaping.controller import Controller  # noqa: E402
from loopshaping.interactive import Designer  # noqa: E402


def brute_force(bounds, mags_db):
    """Allowed mask (n_omega, n_phase, n_mag) by direct evaluation of every part and case."""
    ph = np.deg2rad(bounds.phases_deg)
    L0 = 10 ** (mags_db[None, :] / 20) * np.exp(1j * ph[:, None])  # (n_phase, n_mag)
    out = np.ones((len(bounds.omega), len(ph), len(mags_db)), bool)
    for part in bounds.parts:
        for f, w in enumerate(part.omega):
            i = int(np.searchsorted(bounds.omega, w))
            G = L0 / part.p0[f]
            ok = np.ones(G.shape, bool)
            for c in range(part.A.shape[1]):  # one case at a time: (n_phase, n_mag) arrays
                lhs = np.abs(part.A[f, c] + part.B[f, c] * G)
                rhs = part.W[f, c] * np.abs(part.C[f, c] + part.D[f, c] * G)
                ok &= lhs <= rhs
            out[i] &= ok
    return out


def brute_force_quadratic(bounds, mags_db):
    """Same mask, evaluating the expanded quadratic a·y² + b(φ)·y + c ≤ 0 on the grid: the
    cheapest per-point arithmetic a grid method can use (the fairest grid competitor)."""
    ph = np.deg2rad(bounds.phases_deg)
    y = 10 ** (mags_db / 20)
    out = np.ones((len(bounds.omega), len(ph), len(mags_db)), bool)
    for part in bounds.parts:
        for f, w in enumerate(part.omega):
            i = int(np.searchsorted(bounds.omega, w))
            Bp, Dp, A, C, W2 = part.B[f] / part.p0[f], part.D[f] / part.p0[f], part.A[f], part.C[f], part.W[f] ** 2
            a = np.abs(Bp) ** 2 - W2 * np.abs(Dp) ** 2
            c = np.abs(A) ** 2 - W2 * np.abs(C) ** 2
            K = 2 * (np.conj(A) * Bp - W2 * np.conj(C) * Dp)
            b = np.cos(ph)[:, None] * K.real - np.sin(ph)[:, None] * K.imag  # (n_phase, n_cases)
            ok = np.ones((len(ph), len(y)), bool)
            for k in range(len(a)):
                ok &= (a[k] * y + c[k] / y)[None, :] + b[:, k, None] <= 0  # divided by y > 0
            out[i] &= ok
    return out


def main():
    rng = np.random.default_rng(0)
    n_cases, omegas = 1000, np.logspace(-1, 2, 20)
    k, a, b = rng.uniform(1, 10, n_cases), rng.uniform(1, 5, n_cases), rng.uniform(20, 30, n_cases)
    s = 1j * omegas[:, None]
    tmpl = qft.Template.from_responses(omegas, k / ((s + a) * (s + b)), nominal=0)
    w_sens = 0.02 * (ct.tf("s") ** 3 + 64 * ct.tf("s") ** 2 + 748 * ct.tf("s") + 2400) / (
        ct.tf("s") ** 2 + 14.4 * ct.tf("s") + 169)

    def exact():
        return qft.intersect(qft.bounds(tmpl, "stability", 1.2), qft.bounds(tmpl, "sensitivity", w_sens),
                             qft.bounds(tmpl, "input_disturbance", 0.01))

    t_exact, B = timed(exact)
    sub_w = omegas[[13]]
    sub = qft.intersect(*(qft.bounds(tmpl.at(sub_w), kind, wt) for kind, wt in
                          (("stability", 1.2), ("sensitivity", w_sens), ("input_disturbance", 0.01))))
    mags = np.arange(-80, 80.0001, 0.25)
    t = time.perf_counter()
    grid = brute_force(sub, mags)
    t_brute = (time.perf_counter() - t) * len(omegas) / len(sub_w)
    t = time.perf_counter()
    grid_q = brute_force_quadratic(sub, mags)
    t_brute_q = (time.perf_counter() - t) * len(omegas) / len(sub_w)
    agree = np.mean(grid == grid_q)
    # Accuracy of the grid: its transitions vs the exact edges (should be within one step).
    err = 0.0
    for i in range(len(sub_w)):
        for j in range(0, len(sub.phases_deg), 10):
            g = grid[i, j]
            trans = mags[np.flatnonzero(g[1:] != g[:-1])] + 0.125
            f = sub.forbidden_db[i, j]
            ends = f[~np.isnan(f[:, 0])].ravel()
            ends = np.sort(ends[np.isfinite(ends) & (np.abs(ends) < 79)])
            if len(ends) == len(trans) and len(ends):
                err = max(err, np.max(np.abs(ends - trans)))
    print(f"QFT bounds, {n_cases} cases x {len(B.phases_deg)} phases x {len(omegas)} frequencies x 3 specs")
    print(f"  exact closed form                            {t_exact * 1e3:9.1f} ms   (target < 1000 ms)")
    print(f"  brute force, 0.25 dB, closed-loop functions  {t_brute * 1e3:9.1f} ms   ratio {t_brute / t_exact:7.1f}x")
    print(f"  brute force, 0.25 dB, expanded quadratic     {t_brute_q * 1e3:9.1f} ms   ratio {t_brute_q / t_exact:7.1f}x")
    print(f"  (brute forces timed on {len(sub_w)} of {len(omegas)} frequencies and scaled; "
          f"their masks agree on {100 * agree:.4f} % of the grid points)")
    print(f"  largest grid-vs-exact edge difference where both see the same edges: {err:.3f} dB")

    # Interactive update on the QFT Toolbox example.
    P = [ct.tf([kk], [1, aa + bb, aa * bb]) for kk, aa, bb in
         [(10, x, 20) for x in np.linspace(1, 5, 10)] + [(1, x, 30) for x in np.linspace(1, 5, 10)]
         + [(x, 5, 30) for x in np.linspace(1, 10, 10)] + [(x, 1, 20) for x in np.linspace(1, 10, 10)]]
    w_design = np.array([0.1, 5, 10, 100])
    t40 = qft.Template.from_systems(P, w_design, nominal=10)
    b40 = qft.intersect(qft.bounds(t40, "stability", 1.2), qft.bounds(t40, "sensitivity", w_sens, band=(0, 10)),
                        qft.bounds(t40, "input_disturbance", 0.01, band=(0, 10)))
    s_ = ct.tf("s")
    d = Designer(b40, t40, Controller.from_tf(379 * (s_ / 42 + 1) / (s_**2 / 247**2 + s_ / 247 + 1)))
    fig = d.draw(live=True)
    fig.canvas.draw()
    compute, full = [], []
    for gain in np.linspace(300, 450, 40):
        t = time.perf_counter()
        d.controller = d.controller.set(0, k=gain)
        d.update(redraw=False)
        compute.append(time.perf_counter() - t)
        t = time.perf_counter()
        d.set_param(0, k=gain * 1.001)
        full.append(time.perf_counter() - t)
    print(f"Interactive update (40 plant cases, {len(d.omega)} frequencies)")
    print(f"  recompute + bound check + set data      {np.median(compute) * 1e3:7.1f} ms (median)")
    print(f"  ... + blitted Agg redraw                 {np.median(full) * 1e3:7.1f} ms (median, target < 100 ms)")
    still = Designer(b40, t40, d.controller)
    still.draw(live=False)
    full_redraw = []
    for gain in np.linspace(300, 450, 10):
        t = time.perf_counter()
        still.set_param(0, k=gain)  # a full Agg render of the bounds, the grid and the lines
        full_redraw.append(time.perf_counter() - t)
    print(f"  ... + full Agg redraw instead            {np.median(full_redraw) * 1e3:7.1f} ms (median: what blitting saves)")


if __name__ == "__main__":
    main()
