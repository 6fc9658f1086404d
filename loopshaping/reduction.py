"""Make an H∞ controller implementable: order reduction and discretisation.

:func:`reduce` truncates the stable part of a controller by balanced truncation (the unstable
part is kept exactly) and reports the H∞ norm of the error with the a-priori bound;
:func:`discretize` samples it (Tustin with prewarping, ZOH or FOH).

Frequencies in rad/s, times in s. Every system is a python-control object.
"""
from __future__ import annotations

from dataclasses import dataclass

import control as ct
import numpy as np
import scipy.linalg as sla

from ._statespace import as_ss, hinf_norm, slycot_routine
from .wellposed import AXIS_TOL

__all__ = ["ReductionResult", "discretize", "reduce"]


@dataclass(frozen=True)
class ReductionResult:
    """Result of :func:`reduce`. Unpacks as ``K_r, error = result``.

    Parameters
    ----------
    controller : control.StateSpace
        Reduced controller (same D, same unstable part as the original).
    error_hinf : float
        ‖K − K_r‖∞, computed (``ab13dd``) on the stable parts, where the whole error lives.
    bound : float
        A-priori balanced-truncation bound 2·Σ σ_i over the discarded Hankel singular
        values of the stable part; ``error_hinf ≤ bound``.
    hankel_singular_values : numpy.ndarray
        Hankel singular values of the stable part, decreasing.
    n_unstable : int
        Number of poles with Re ≥ 0 that were kept unreduced.
    """

    controller: ct.StateSpace
    error_hinf: float
    bound: float
    hankel_singular_values: np.ndarray
    n_unstable: int

    def __iter__(self):
        yield self.controller
        yield self.error_hinf



def _stable_unstable_split(sys, axis_tol):
    """Additive split G = G_s + G_u (+D) with G_s strictly stable, G_u the rest.

    Ordered Schur form puts stable eigenvalues first; a Sylvester equation removes the
    coupling block, giving two decoupled realisations.
    """
    A, B, C = (np.asarray(M, dtype=float) for M in (sys.A, sys.B, sys.C))
    T, Z, ns = sla.schur(
        A, output="real", sort=lambda re, im: re < -axis_tol * max(1.0, np.hypot(re, im))
    )
    Bt, Ct = Z.T @ B, C @ Z
    A11, A12, A22 = T[:ns, :ns], T[:ns, ns:], T[ns:, ns:]
    # [I X; 0 I] block-diagonalises when A11·X − X·A22 = −A12.
    X = sla.solve_sylvester(A11, -A22, -A12) if ns and A22.size else np.zeros((ns, A22.shape[0]))
    Bs = Bt[:ns] - X @ Bt[ns:]
    Bu = Bt[ns:]
    Cs = Ct[:, :ns]
    Cu = Ct[:, ns:] + Ct[:, :ns] @ X
    return (A11, Bs, Cs), (A22, Bu, Cu)


def reduce(controller: ct.StateSpace | ct.TransferFunction, order: int, method: str = "balanced", *,
           axis_tol: float = AXIS_TOL) -> ReductionResult:
    """Reduce a controller's order by balanced truncation of its stable part.

    The unstable (and marginal, e.g. integrator) part is kept exactly, so the error
    lives in the stable part only and the classic bounds hold:
    σ_{k+1} ≤ ‖K − K_r‖∞ ≤ 2·Σ_{i>k} σ_i over the stable part's Hankel singular values σ.

    Parameters
    ----------
    controller : control LTI
        Continuous-time controller.
    order : int
        Desired number of states, ≥ the number of unstable/marginal poles.
    method : {"balanced", "singular_perturbation"}
        Square-root balanced truncation (``ab09ad``) or balanced singular perturbation
        approximation (``ab09nd``, matches the DC gain of the stable part; same bound).
    axis_tol : float
        A pole p counts as unstable or marginal (kept exactly) unless
        Re p < −axis_tol·max(1, |p|).

    Returns
    -------
    ReductionResult
        Unpacks as ``K_r, error_hinf``.
    """
    K = as_ss(controller, "controller")
    if method not in ("balanced", "singular_perturbation"):
        raise ValueError(f"method={method!r} must be 'balanced' or 'singular_perturbation'")
    if not isinstance(order, (int, np.integer)) or order < 0:
        raise ValueError(f"order={order!r} must be a non-negative integer")
    n = K.nstates
    if order >= n:
        raise ValueError(f"order={order} must be smaller than the controller's {n} states")
    (As, Bs, Cs), (Au, Bu, Cu) = _stable_unstable_split(K, axis_tol)
    ns, nu_ = As.shape[0], Au.shape[0]
    if order < nu_:
        raise ValueError(
            f"order={order} is below the {nu_} unstable or marginal poles of the controller, "
            "which balanced truncation must keep; ask for at least that order"
        )
    m, p = Bs.shape[1], Cs.shape[0]
    k = order - nu_
    # SLICOT overwrites its array arguments in place: keep the stable part intact.
    Gs = ct.ss(As, Bs, Cs, np.zeros((p, m))) if ns else ct.ss([], [], [], np.zeros((p, m)))
    As, Bs, Cs = As.copy(order="F"), Bs.copy(order="F"), Cs.copy(order="F")
    if ns == 0:
        hsv = np.zeros(0)
        Ar, Br, Cr, Dr_s = As, Bs, Cs, np.zeros((p, m))
    elif method == "balanced":
        nr, Ar, Br, Cr, hsv = slycot_routine("ab09ad")("C", "B", "N", ns, m, p, As, Bs, Cs, nr=k)
        Ar, Br, Cr = Ar[:nr, :nr], Br[:nr], Cr[:, :nr]
        Dr_s = np.zeros((p, m))
    else:
        Zero = np.zeros((p, m))
        nr, Ar, Br, Cr, Dr_s, _, hsv = slycot_routine("ab09nd")(
            "C", "B", "N", ns, m, p, As, Bs, Cs, Zero, nr=k
        )
        Ar, Br, Cr = Ar[:nr, :nr], Br[:nr], Cr[:, :nr]
    hsv = np.asarray(hsv, dtype=float)[:ns]
    Gsr = ct.ss(Ar, Br, Cr, Dr_s) if Ar.shape[0] else ct.ss([], [], [], Dr_s)
    err = ct.parallel(Gs, ct.negate(Gsr)) if ns else ct.ss([], [], [], np.zeros((p, m)))
    error = hinf_norm(err) if ns else 0.0
    bound = 2.0 * float(np.sum(hsv[Ar.shape[0]:])) if ns else 0.0
    D = np.asarray(K.D, dtype=float)
    nr_tot = nu_ + Ar.shape[0]
    Ared = sla.block_diag(Au, Ar) if nr_tot else np.zeros((0, 0))
    Bred = np.vstack([Bu, Br])
    Cred = np.hstack([Cu, Cr])
    Kr = ct.ss(Ared, Bred, Cred, D + Dr_s, inputs=K.input_labels, outputs=K.output_labels)
    return ReductionResult(
        controller=Kr, error_hinf=error, bound=bound, hankel_singular_values=hsv,
        n_unstable=nu_,
    )


_DISCRETIZE = ("tustin", "zoh", "foh")


def discretize(controller: ct.StateSpace | ct.TransferFunction, dt: float, method: str = "tustin",
               prewarp_frequency: float | None = None) -> ct.StateSpace:
    """Discrete-time controller for implementation at sample time ``dt`` (s).

    Parameters
    ----------
    controller : control LTI
        Continuous-time controller.
    dt : float
        Sample time in s.
    method : {"tustin", "zoh", "foh"}
        Discretisation rule.
    prewarp_frequency : float, optional
        Frequency (rad/s, below the Nyquist frequency π/dt) at which the Tustin map is
        exact, e.g. the tower mode. Only with ``method="tustin"``.

    Returns
    -------
    control.StateSpace
        Discrete-time controller with ``dt`` set.
    """
    K = as_ss(controller, "controller")
    if not (isinstance(dt, (int, float, np.integer, np.floating)) and np.isfinite(dt) and dt > 0):
        raise ValueError(f"dt={dt!r} must be a positive sample time in seconds")
    if method not in _DISCRETIZE:
        raise ValueError(f"method={method!r} must be one of {_DISCRETIZE}")
    if prewarp_frequency is not None:
        if method != "tustin":
            raise ValueError("prewarp_frequency only applies to method='tustin'")
        w0 = float(prewarp_frequency)
        if not (0 < w0 < np.pi / dt):
            raise ValueError(
                f"prewarp_frequency={prewarp_frequency!r} rad/s must lie in (0, π/dt = "
                f"{np.pi / dt:.4g} rad/s)"
            )
    return ct.sample_system(K, dt, method=method, prewarp_frequency=prewarp_frequency)
