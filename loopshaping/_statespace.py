"""State-space helpers shared by :mod:`loopshaping.hinf`, :mod:`loopshaping.wellposed` and
:mod:`loopshaping.reduction` (private module; its names are internal to loopshaping)."""
from __future__ import annotations

import control as ct
import numpy as np
import scipy.linalg as sla

__all__ = ["as_ss", "check_dims", "format_roots", "hinf_norm", "partition", "sigma_max", "slycot_routine"]


def slycot_routine(name):
    # slycot is optional for the package as a whole but required here: fail loudly, late.
    try:
        import slycot
    except ImportError as e:  # pragma: no cover - slycot is installed in CI
        raise ImportError(f"loopshaping.hinf needs slycot (for {name}); pip install slycot") from e
    return getattr(slycot, name)


def as_ss(sys, name):
    if isinstance(sys, (int, float, np.integer, np.floating)):
        return ct.ss([], [], [], np.atleast_2d(float(sys)))
    if isinstance(sys, ct.TransferFunction):
        sys = ct.ss(sys)
    if not isinstance(sys, ct.StateSpace):
        raise TypeError(
            f"{name} must be a control.StateSpace, control.TransferFunction or a number, "
            f"got {type(sys).__name__}"
        )
    if not sys.isctime():
        raise ValueError(f"{name} must be continuous-time (dt=0); discretise after synthesis")
    return sys


def partition(P, n_meas, n_ctrl):
    A, B, C, D = (np.asarray(M, dtype=float) for M in (P.A, P.B, P.C, P.D))
    m1 = B.shape[1] - n_ctrl
    p1 = C.shape[0] - n_meas
    return dict(
        A=A, B1=B[:, :m1], B2=B[:, m1:], C1=C[:p1], C2=C[p1:],
        D11=D[:p1, :m1], D12=D[:p1, m1:], D21=D[p1:, :m1], D22=D[p1:, m1:],
    )



def format_roots(values):
    return ", ".join(f"{v.real:+.3g}{v.imag:+.3g}j" for v in values)


def sigma_max(sys, w):
    """Largest singular value of sys(jω) for each ω of w (rad/s)."""
    r = np.asarray(ct.frequency_response(sys, w).complex)
    r = r.reshape(sys.noutputs, sys.ninputs, len(w))
    return np.linalg.svd(np.moveaxis(r, -1, 0), compute_uv=False)[:, 0]


def hinf_norm(sys):
    """H∞ norm of a stable system: ab13dd, guarded by a pole-spanning grid search.

    ab13dd (Bruinsma–Steinbuch) occasionally returns a local peak (seen on controllers
    whose poles span eight decades); taking the larger of it and a refined grid maximum
    removes that failure without losing ab13dd's accuracy when it is right.
    """
    if sys.nstates == 0:
        return float(sla.svdvals(np.atleast_2d(sys.D))[0]) if np.size(sys.D) else 0.0
    gpeak = float(ct.linfnorm(sys)[0])
    mags = np.abs(np.linalg.eigvals(np.asarray(sys.A)))
    mags = mags[mags > 0]
    lo = np.log10(mags.min()) - 3 if mags.size else -3.0
    hi = np.log10(mags.max()) + 3 if mags.size else 3.0
    w = np.concatenate([[0.0], np.logspace(lo, hi, int(200 * (hi - lo)))])
    g = sigma_max(sys, w)
    i = int(np.argmax(g))
    best = g[i]
    for _ in range(3):
        # Zoom three times on the grid peak (±1 grid step, 201 points) to pin it down.
        lo_w, hi_w = w[max(i - 1, 0)], w[min(i + 1, len(w) - 1)]
        w = np.linspace(lo_w, hi_w, 201)
        g = sigma_max(sys, w)
        i = int(np.argmax(g))
        best = max(best, g[i])
    return max(gpeak, float(best))



def check_dims(P, n_meas, n_ctrl):
    for name, v in (("n_meas", n_meas), ("n_ctrl", n_ctrl)):
        if not isinstance(v, (int, np.integer)) or v < 1:
            raise ValueError(f"{name}={v!r} must be a positive integer")
    if n_meas >= P.noutputs:
        raise ValueError(
            f"n_meas={n_meas} must be smaller than the number of plant outputs "
            f"({P.noutputs}): there must be at least one performance output z"
        )
    if n_ctrl >= P.ninputs:
        raise ValueError(
            f"n_ctrl={n_ctrl} must be smaller than the number of plant inputs "
            f"({P.ninputs}): there must be at least one exogenous input w"
        )

