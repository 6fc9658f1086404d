"""The forwarding DISCON library (specdesign.export.forwarded): the cost of calling Python at
each control step (issue 31, item 3).

Run: python benchmarks/bench_forward.py
Calls each library's DISCON directly through ctypes, 5 000 times on one swap sequence (19 m/s,
DLL_DT = 0.02 s, the same Python loop filling the swap array for all), as ServoDyn would:
  * the exported library of the 19 m/s ROSCO-form PI (all in C: the reference),
  * the forwarding library with a Python controller that does nothing (holds its first pitch):
    the round trip itself (socket both ways, the server thread, swap decoding, the measurements),
  * the forwarding library with QuadraticMPC (ts = 0.1 s, the initial pitch's operating
    point): its QP every 5th call.
The server runs in a thread of this process (as in a campaign); OpenFAST would be another
process, so the GIL hand-over here is a cost OpenFAST does not pay on its side. Prints the wall
time per call of each (best of 3), the round trip's overhead (forwarded no-op minus exported),
and the server's own mean time per call (request read → reply sent).
"""
from __future__ import annotations

import ctypes
import tempfile
from pathlib import Path

import numpy as np
from timing import best_of

from specdesign.export import ForwardServer, export_discon, forwarded
from specdesign.mpc import QuadraticMPC
from specdesign.rosco.discon import SWAP_SIZE
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


def drive(library, infile, t, ys, op):
    """All calls of one run (status 0, 1, ..., −1) of ``library`` reading ``infile``."""
    fn = ctypes.CDLL(str(library)).DISCON
    fn.restype = None
    fn.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_char_p, ctypes.c_char_p, ctypes.c_void_p]
    name = str(infile).encode() + b"\0"
    sw = np.zeros(SWAP_SIZE, np.float32)
    fail = np.zeros(1, np.int32)
    msg = np.zeros(1025, np.uint8)
    sw[2], sw[3], sw[22], sw[26], sw[48], sw[49] = DT, op.pitch, op.gen_torque, 19.0, 1024, len(name)
    args = (sw.ctypes.data, fail.ctypes.data, name, b"out\0", msg.ctypes.data)
    for k, (tk, y) in enumerate(zip(t, ys)):
        sw[0], sw[1], sw[19], sw[52] = (0 if k == 0 else 1), tk, y["gen_speed"][0], y["tower_top_acc"][0]
        fn(*args)
        if fail[0] < 0:
            raise RuntimeError(bytes(msg).split(b"\0")[0].decode())
    sw[0] = -1
    fn(*args)


def main():
    model = iea15mw()
    t, ys, op = sequence(model)
    tmp = Path(tempfile.mkdtemp())
    rec = export_discon(rosco_baseline(model, 19.0), tmp / "export", model=model, dt=DT)
    t_exp = best_of(lambda: drive(rec.library, rec.parameters, t, ys, op)) / N
    rows = []
    for label, ctrl in (("no-op Python controller", Hold()),
                        ("QuadraticMPC (ts = 0.1 s)", QuadraticMPC(model, ts=0.1, operating_point="initial pitch"))):
        fwd = forwarded(ctrl, dt=DT, model=model)
        server_times = []

        def one():
            with ForwardServer(fwd) as srv:
                drive(fwd.library, srv.write(tmp / "fwd.IN"), t, ys, op)
            srv.raise_error()
            server_times.append(np.mean(srv.call_times))

        rows.append((label, best_of(one) / N, min(server_times)))
    print(f"calls per run: {N} (DLL_DT = {DT} s: {N * DT:g} s simulated)")
    print(f"exported library (C only), per call:            {t_exp * 1e6:8.1f} µs")
    for label, per_call, server in rows:
        print(f"forwarded, {label:27s} per call: {per_call * 1e6:8.1f} µs  (server {server * 1e6:7.1f} µs)")
    print(f"round-trip overhead per call (no-op - exported): {(rows[0][1] - t_exp) * 1e6:6.1f} µs")


if __name__ == "__main__":
    main()
