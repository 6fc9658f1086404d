"""The forwarding DISCON library (specdesign.export.forwarded): the cost of calling Python at
each control step (issue 31, item 3).

Run: python benchmarks/bench_forward.py
Drives, through the ctypes harness (specdesign.rosco.Discon), the same 5 000-call swap sequence
(19 m/s, DLL_DT = 0.02 s) into
  * the exported library of the 19 m/s ROSCO-form PI (all in C: the reference),
  * the forwarding library with a Python controller that does nothing (holds its first pitch):
    the round trip itself (socket, thread, swap decoding, the measurements dict),
  * the forwarding library with QuadraticMPC (ts = 0.1 s, the initial pitch's operating
    point): its QP every 5th call.
It prints the wall time per call of each (best of 3), the overhead of the round trip
(forwarded no-op minus exported), and the server's own time per call (request read → reply sent).
"""
from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
from timing import best_of

from specdesign.export import ForwardServer, export_discon, forwarded
from specdesign.mpc import QuadraticMPC
from specdesign.rosco import Discon
from specdesign.turbine import iea15mw, rosco_baseline

N, DT = 5000, 0.02


class Hold:
    """A controller that holds the pitch it starts at: the round trip alone."""

    def start(self, dt, wind, pitch, torque):
        self.cmd = pitch.copy()

    def __call__(self, t, y):
        return self.cmd


def sequence(model):
    t = np.arange(N) * DT
    op = model.trim(19.0)
    w = model.rated_rotor_speed * (1 + 0.02 * np.sin(0.7 * t))
    ys = [{"gen_speed": np.array([w[k]]), "pitch": np.array([op.pitch]), "power": np.array([model.rated_power]),
           "tower_top_acc": np.array([0.2 * np.sin(1.1 * t[k])])} for k in range(N)]
    return t, ys, op


def drive(discon, t, ys, op):
    discon.start(DT, np.array([19.0]), np.array([op.pitch]), np.array([op.gen_torque]))
    for tk, y in zip(t, ys):
        discon(tk, y)
    discon.close()


def main():
    model = iea15mw()
    t, ys, op = sequence(model)
    tmp = Path(tempfile.mkdtemp())
    rec = export_discon(rosco_baseline(model, 19.0), tmp / "export", model=model, dt=DT)
    exported = Discon(rec.parameters, library=rec.library)
    t_exp = best_of(lambda: drive(exported, t, ys, op)) / N
    rows = []
    for label, ctrl in (("no-op Python controller", Hold()),
                        ("QuadraticMPC (ts = 0.1 s)", QuadraticMPC(model, ts=0.1, operating_point="initial pitch"))):
        fwd = forwarded(ctrl, dt=DT, model=model)
        server_times = []

        def one():
            with ForwardServer(fwd) as srv:
                drive(Discon(srv.write(tmp / "fwd.IN"), library=fwd.library), t, ys, op)
            srv.raise_error()
            server_times.append(np.mean(srv.call_times))

        rows.append((label, best_of(one) / N, min(server_times)))
    print(f"calls per run: {N} (DLL_DT = {DT} s: {N * DT:g} s simulated)")
    print(f"exported library (C only), per call:          {t_exp * 1e6:8.1f} µs")
    for label, per_call, server in rows:
        print(f"forwarded, {label:27s} per call: {per_call * 1e6:8.1f} µs  (server {server * 1e6:7.1f} µs)")
    print(f"round-trip overhead per call (no-op - exported): {(rows[0][1] - t_exp) * 1e6:6.1f} µs")


if __name__ == "__main__":
    main()
