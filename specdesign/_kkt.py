"""Newton's method on the KKT conditions of a polished constrained optimum: where a local
method's end stops moving with round-off.

SLSQP ends where its line search or its tolerance stops it; along a shallow valley of the
objective that end moves with round-off (1e-7 to 1e-5 relative in the parameters), and a design
built on it then moves by far more than its data did. From that end, with the constraints active
there as equalities and the parameters on their box limits fixed, Newton's method on
∇f = Jᵀλ, g_A = 0 converges to the KKT point itself, a continuous function of the data. The QFT
tuner (:func:`specdesign.qft.tuner.kkt_refine`) and the notch shaper
(:func:`specdesign.spec.shape_to_target`) refine their ends with it.

Units are the caller's: the parameters ``x``, the objective and the constraints (≥ 0 when met).
"""
from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = ["central_jacobian", "kkt_point"]


def central_jacobian(f: Callable[[np.ndarray], np.ndarray], y: np.ndarray, step: float = 1e-4) -> np.ndarray:
    """d f/d y by central differences (step relative to max(1, |y|)), shape (len(f(y)), len(y))."""
    cols = []
    for i in range(y.size):
        h = step * max(1.0, abs(y[i]))
        e = np.zeros_like(y)
        e[i] = h
        cols.append((np.atleast_1d(f(y + e)) - np.atleast_1d(f(y - e))) / (2 * h))
    return np.stack(cols, axis=-1)


def kkt_point(objective: Callable[[np.ndarray], float], constraints: Callable[[np.ndarray], np.ndarray],
              x: np.ndarray, lower: np.ndarray, upper: np.ndarray, *, active_tol: float, feasible_tol: float,
              step_tol: float, iterations: int = 15, limit_tol: float = 1e-5,
              tie_break: tuple[float, np.ndarray] | None = None) -> tuple[np.ndarray, dict]:
    """The KKT point near a feasible polished ``x``, or ``x`` unchanged when Newton's method does not get there.

    The constraints with ``constraints(x) < active_tol`` are the active set, held as equalities;
    the parameters within ``limit_tol`` of ``lower``/``upper`` stay where they are. Gradients are
    central differences with a 1e-4 relative step; the Lagrangian's Hessian central differences of
    its gradient with a 1e-3 step. The refined point is kept only if the steps converge (at least
    three, the last below ``step_tol`` in every parameter), every multiplier is ≥ 0 (else the active
    set is not the optimum's) and every constraint stays met (≥ −``feasible_tol``) inside the box.

    Parameters
    ----------
    objective : callable
        x → f(x), the objective minimised.
    constraints : callable
        x → the constraint vector, ≥ 0 where met.
    x : numpy.ndarray
        A feasible polished point, inside ``lower``-``upper``.
    lower, upper : numpy.ndarray
        The box.
    active_tol, feasible_tol, step_tol : float
        In the constraints' units (the first two) and the parameters' (the last).
    iterations : int
        Newton steps at most.
    limit_tol : float
        How close to a box limit a parameter counts as on it (parameters' units).
    tie_break : (float, numpy.ndarray), optional
        (w, anchor): minimise ``objective`` + w·|x − anchor|² (a quadratic that makes a shallow
        valley's optimum unique), its gradient 2w·(x − anchor) exact: a central difference of it
        only adds round-off.

    Returns
    -------
    x : numpy.ndarray
        The KKT point (or ``x``).
    info : dict
        ``converged`` (bool), ``steps``, ``active`` (number of active constraints), ``free``
        (parameters not on a limit), ``kkt_residual`` (|∇f − Jᵀλ|, at the end) and ``reason``.
    """
    lo, hi = np.asarray(lower, float), np.asarray(upper, float)
    x = np.asarray(x, float).copy()
    free = (x > lo + limit_tol) & (x < hi - limit_tol)

    def full(y):
        z = x.copy()
        z[free] = y
        return z

    def cons(y):
        return np.atleast_1d(constraints(full(y)))

    active = cons(x[free]) < active_tol
    info = {"converged": False, "steps": 0, "active": int(active.sum()), "free": int(free.sum()),
            "kkt_residual": float("nan"), "reason": ""}
    if not free.any():
        info.update(converged=True, reason="every parameter on a limit")
        return x, info

    def grad_f(y):
        g = central_jacobian(lambda u: np.array([objective(full(u))]), y)[0]
        if tie_break is None:
            return g
        weight, anchor = tie_break
        return g + 2 * weight * (y - np.asarray(anchor, float)[free])

    def jac_a(y):
        return central_jacobian(lambda u: cons(u)[active], y).reshape(int(active.sum()), y.size)

    y = x[free].copy()
    with np.errstate(all="ignore"):
        for it in range(iterations):
            gf, J, gA = grad_f(y), jac_a(y), cons(y)[active]
            lam = np.linalg.lstsq(J.T, gf, rcond=None)[0] if J.size else np.zeros(0)
            info["kkt_residual"] = float(np.linalg.norm(gf - J.T @ lam))

            def grad_l(u, lam=lam):
                return grad_f(u) - jac_a(u).T @ lam

            H = central_jacobian(grad_l, y, step=1e-3)
            H = 0.5 * (H + H.T)
            n, m = y.size, J.shape[0]
            K = np.block([[H, -J.T], [J, np.zeros((m, m))]])
            rhs = -np.r_[gf - J.T @ lam, gA]
            step = np.linalg.lstsq(K, rhs, rcond=None)[0][:n]
            if not np.all(np.isfinite(step)):
                info["reason"] = "non-finite Newton step"
                return x, info
            y = y + step
            info["steps"] = it + 1
            if np.max(np.abs(step)) < step_tol and it >= 2:
                break
        else:
            info["reason"] = f"no convergence in {iterations} Newton steps"
            return x, info
    out = full(y)
    gf, J = grad_f(y), jac_a(y)
    lam = np.linalg.lstsq(J.T, gf, rcond=None)[0] if J.size else np.zeros(0)
    info["kkt_residual"] = float(np.linalg.norm(gf - J.T @ lam))
    g = np.atleast_1d(constraints(out))
    if lam.size and lam.min() < -1e-8 * max(1.0, np.abs(lam).max()):
        info["reason"] = "a negative multiplier (the active set is not the optimum's)"
        return x, info
    if not (np.all(np.isfinite(g)) and g.min() >= -feasible_tol and np.all(out >= lo) and np.all(out <= hi)):
        info["reason"] = "the refined point breaks a constraint"
        return x, info
    info.update(converged=True, reason="KKT point")
    return out, info
