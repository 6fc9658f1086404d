"""Well-posedness of H∞ problems: SLICOT's assumptions checked before SLICOT runs.

SLICOT's H∞ routines assume (A1) (A, B2) stabilisable and (C2, A) detectable,
(A2) D12 full column rank and D21 full row rank, (A3)/(A4) no invariant zeros of
(A, B2, C1, D12) and (A, B1, C2, D21) on the imaginary axis. When one of them fails
``sb10ad`` (python-control's ``hinfsyn``) can iterate on γ without end, so
:func:`check_well_posed` checks every assumption first and raises a :class:`ValueError`
naming the condition and a remedy. Two regularisation helpers make a problem well posed
on request: :func:`regularized_plant` (ε·u appended to z, ε·noise added to y) and
:func:`shift_axis_poles` (poles on the imaginary axis moved to Re = −ε); a change is
announced with :class:`WellPosednessWarning` by the synthesis functions.

Frequencies in rad/s. Every system is a python-control object.
"""
from __future__ import annotations

import control as ct
import numpy as np
import scipy.linalg as sla

from ._statespace import as_ss, check_dims, format_roots, partition, slycot_routine

__all__ = ["AXIS_TOL", "RANK_TOL", "WellPosednessWarning", "check_well_posed", "regularized_plant", "shift_axis_poles"]

#: Relative rank tolerance of D12 and D21 (σ_min against the norm of their block row or column):
#: an exactly singular D comes out of the SVD at round-off, ~n·eps ≈ 1e-15 relative, and a
#: deliberate regularisation at ``epsilon`` = 1e-3 (:func:`regularized_plant`); 1e-9 sits six
#: orders above the one and six below the other.
RANK_TOL = 1e-9
#: Relative distance from the imaginary axis below which a zero or mode counts as on it
#: (|Re s| ≤ AXIS_TOL·max(1, |s|)): an integrator or undamped resonance placed on the axis comes
#: out of the eigenvalue and zero computations at round-off (~1e-15 relative), while the
#: ``shift`` that moves such a weight pole off the axis (1e-4 rad/s) is five orders above it.
AXIS_TOL = 1e-9


class WellPosednessWarning(UserWarning):
    """A weight or the problem was modified (pole shifted, regularised) to make it well posed."""



def _invariant_zeros(A, B, C, D):
    """Finite invariant zeros of (A, B, C, D), any shape (SLICOT ab08nd + QZ)."""
    n = A.shape[0]
    if n == 0:
        return np.array([], dtype=complex)
    ab08nd = slycot_routine("ab08nd")
    # SLICOT may overwrite its arguments: hand it copies.
    out = ab08nd(n, B.shape[1], C.shape[0], A.copy(), B.copy(), C.copy(), D.copy())
    nu = out[0]
    if nu == 0:
        return np.array([], dtype=complex)
    Af, Bf = out[8][:nu, :nu], out[9][:nu, :nu]
    z = sla.eigvals(Af, Bf)
    return z[np.isfinite(z)].astype(complex)


def _balanced(A, B1, B2, C1, C2):
    """(A, B1, B2, C1, C2) after SLICOT tb01id's diagonal state scaling of the whole plant (job 'A')."""
    n = A.shape[0]
    if n == 0:
        return A, B1, B2, C1, C2
    m1, p1 = B1.shape[1], C1.shape[0]
    B, C = np.hstack([B1, B2]), np.vstack([C1, C2])
    _, Ab, Bb, Cb, _ = slycot_routine("tb01id")(n, B.shape[1], C.shape[0], 0.0, np.array(A, order="F"),
                                                 np.array(B, order="F"), np.array(C, order="F"), job="A")
    return Ab, Bb[:, :m1], Bb[:, m1:], Cb[:p1], Cb[p1:]


def _on_axis(values, axis_tol):
    values = np.asarray(values, dtype=complex)
    return values[np.abs(values.real) <= axis_tol * np.maximum(1.0, np.abs(values))]



def shift_axis_poles(sys: ct.StateSpace, epsilon: float, axis_tol: float) -> tuple:
    """Move eigenvalues with |Re| ≤ tol to Re = −ε, leaving the others untouched.

    An ordered real Schur form puts those eigenvalues in the leading block; subtracting
    ε·I there shifts exactly them (the form is block upper-triangular).

    Parameters
    ----------
    sys : control.StateSpace
        The system (typically a weight).
    epsilon : float
        Distance the poles are moved left, rad/s.
    axis_tol : float
        An eigenvalue s counts as on the axis when |Re s| ≤ axis_tol·max(1, |s|).

    Returns
    -------
    shifted : control.StateSpace
        The system with those poles at Re = −ε (``sys`` itself if none).
    moved : numpy.ndarray
        The poles that were moved (complex, 1/s).
    """
    A = np.asarray(sys.A, dtype=float)
    if A.shape[0] == 0:
        return sys, np.array([], dtype=complex)
    poles = np.linalg.eigvals(A)
    moved = _on_axis(poles, axis_tol)
    if moved.size == 0:
        return sys, moved
    T, Z, k = sla.schur(
        A, output="real",
        sort=lambda re, im: abs(re) <= axis_tol * max(1.0, np.hypot(re, im)),
    )
    T = T.copy()
    T[:k, :k] -= epsilon * np.eye(k)
    shifted = ct.ss(T, Z.T @ np.asarray(sys.B), np.asarray(sys.C) @ Z, sys.D)
    return shifted, moved



def check_well_posed(generalized_plant: ct.StateSpace | ct.TransferFunction, n_meas: int, n_ctrl: int, *,
                     rank_tol: float = RANK_TOL, axis_tol: float = AXIS_TOL) -> None:
    """Check SLICOT's assumptions (A1)–(A4) on a generalized plant; raise if one fails.

    Parameters
    ----------
    generalized_plant : control.StateSpace
        Continuous-time plant with inputs ``[w; u]`` and outputs ``[z; y]``.
    n_meas, n_ctrl : int
        Number of measurements y (last outputs) and controls u (last inputs).
    rank_tol : float
        Relative rank tolerance: D12 counts as rank deficient when
        σ_min(D12) ≤ rank_tol·‖[C1 D12]‖ (and likewise for D21 with ‖[B1; D21]‖).
    axis_tol : float
        A zero or mode s counts as on the imaginary axis when |Re s| ≤ axis_tol·max(1, |s|).

    Raises
    ------
    ValueError
        Naming the failed condition and a remedy.
    """
    P = as_ss(generalized_plant, "generalized_plant")
    check_dims(P, n_meas, n_ctrl)
    p = partition(P, n_meas, n_ctrl)
    A, B1, B2, C1, C2, D12, D21 = (p[k] for k in ("A", "B1", "B2", "C1", "C2", "D12", "D21"))
    n = A.shape[0]
    for key in ("A", "B1", "B2", "C1", "C2", "D11", "D12", "D21", "D22"):  # else LAPACK: "SVD did not converge"
        if not np.all(np.isfinite(p[key])):
            raise ValueError(f"ill-posed H∞ problem: the generalized plant's {key} has NaN or inf entries; check the "
                             "plant and the weights it was built from")

    # (A2): rank conditions. A rank-deficient D12 is the classic "spins forever" case.
    s12 = sla.svdvals(D12) if D12.size else np.zeros(0)
    scale12 = max(np.linalg.norm(np.hstack([C1, D12]), 2), np.finfo(float).tiny)
    if D12.shape[0] < D12.shape[1] or s12.size == 0 or s12.min() <= rank_tol * scale12:
        raise ValueError(
            f"ill-posed H∞ problem: D12 ({D12.shape[0]}×{D12.shape[1]}) is not of full column "
            f"rank (singular values {np.array2string(s12, precision=3)}): some control input "
            "has no direct penalty at high frequency. Remedy: add a control-effort weight "
            "with a non-zero feed-through (w_ks in mixed_sensitivity), give a weight on T a "
            "biproper part, or pass regularize=True to add epsilon·u to the outputs."
        )
    s21 = sla.svdvals(D21) if D21.size else np.zeros(0)
    scale21 = max(np.linalg.norm(np.vstack([B1, D21]), 2), np.finfo(float).tiny)
    if D21.shape[1] < D21.shape[0] or s21.size == 0 or s21.min() <= rank_tol * scale21:
        raise ValueError(
            f"ill-posed H∞ problem: D21 ({D21.shape[0]}×{D21.shape[1]}) is not of full row "
            f"rank (singular values {np.array2string(s21, precision=3)}): some measurement is "
            "noise-free. Remedy: add a sensor-noise input to every measurement, or pass "
            "regularize=True to add epsilon·(noise) to the measurements."
        )

    # (A1), (A3), (A4) hold or fail alike in every state coordinate; their numerical tests do
    # not: a model whose states mix scales (a stiff structure's displacements beside a slow
    # integrator, N·m beside rad) has ‖[A B2]‖ set by its stiffest rows, and a well-controllable
    # slow mode then looks rank deficient against that norm. The tests run after the diagonal
    # state similarity of SLICOT's tb01id (the one the synthesis solves with), which leaves
    # every transfer function and mode unchanged.
    A, B1, B2, C1, C2 = _balanced(A, B1, B2, C1, C2)

    # (A1): stabilisable / detectable by the PBH test at every closed-RHP eigenvalue.
    if n:
        norm_ab = max(np.linalg.norm(np.hstack([A, B2]), 2), 1.0)
        norm_ac = max(np.linalg.norm(np.vstack([A, C2]), 2), 1.0)
        for lam in np.linalg.eigvals(A):
            if lam.real < -axis_tol * max(1.0, abs(lam)):
                continue
            M = A - lam * np.eye(n)
            if sla.svdvals(np.hstack([M, B2])).min() <= rank_tol * norm_ab:
                raise ValueError(
                    f"ill-posed H∞ problem: (A, B2) is not stabilisable, the mode at "
                    f"s = {format_roots([lam])} cannot be moved by the controls. Remedy: remove "
                    "the mode from the weights/plant, or shift it into the left half-plane "
                    "(weights: integrators are shifted by epsilon automatically in "
                    "mixed_sensitivity)."
                )
            if sla.svdvals(np.vstack([M, C2])).min() <= rank_tol * norm_ac:
                raise ValueError(
                    f"ill-posed H∞ problem: (C2, A) is not detectable, the mode at "
                    f"s = {format_roots([lam])} is not seen by the measurements. Remedy: remove the "
                    "mode (it is usually an unobservable weight state) or shift it into the "
                    "left half-plane."
                )

    # (A3)/(A4): invariant zeros on the imaginary axis (a pole of a weight or plant that
    # sits on the axis and cannot be cancelled shows up here).
    z12 = _on_axis(_invariant_zeros(A, B2, C1, D12), axis_tol)
    if z12.size:
        raise ValueError(
            "ill-posed H∞ problem: (A, B2, C1, D12) has invariant zeros on the imaginary axis "
            f"at s = {format_roots(z12)}. Typical cause: a pole on the axis (integrator) in a weight or "
            "in the plant, or a zero of the plant on the axis. Remedy: shift the pole by a "
            "small epsilon into the left half-plane (mixed_sensitivity does this for weights)."
        )
    z21 = _on_axis(_invariant_zeros(A, B1, C2, D21), axis_tol)
    if z21.size:
        raise ValueError(
            "ill-posed H∞ problem: (A, B1, C2, D21) has invariant zeros on the imaginary axis "
            f"at s = {format_roots(z21)}. Typical cause: a plant pole on the axis (integrator) that the "
            "disturbances do not excite. Remedy: shift the pole by a small epsilon into the "
            "left half-plane, or add a disturbance input that excites it."
        )


def regularized_plant(P: ct.StateSpace, n_meas: int, n_ctrl: int, epsilon: float, rank_tol: float) -> tuple:
    """Append ε·u to z where D12 lacks rank and ε·noise to y where D21 lacks rank.

    Parameters
    ----------
    P : control.StateSpace
        Generalized plant, inputs ``[w; u]``, outputs ``[z; y]``.
    n_meas : int
        Number of measurements y (last outputs).
    n_ctrl : int
        Number of controls u (last inputs).
    epsilon : float
        Size of the added terms (units of z per unit of u, of y per unit of noise).
    rank_tol : float
        Relative rank tolerance, as in :func:`check_well_posed`.

    Returns
    -------
    plant : control.StateSpace
        The regularised plant (``P`` itself when nothing was needed).
    notes : list of str
        What was added.
    """
    p = partition(P, n_meas, n_ctrl)
    notes = []
    A, B1, B2, C1, C2 = p["A"], p["B1"], p["B2"], p["C1"], p["C2"]
    D11, D12, D21, D22 = p["D11"], p["D12"], p["D21"], p["D22"]
    n = A.shape[0]
    s12 = sla.svdvals(D12) if D12.size else np.zeros(0)
    scale12 = max(np.linalg.norm(np.hstack([C1, D12]), 2), np.finfo(float).tiny)
    if D12.shape[0] < D12.shape[1] or s12.size == 0 or s12.min() <= rank_tol * scale12:
        C1 = np.vstack([C1, np.zeros((n_ctrl, n))])
        D11 = np.vstack([D11, np.zeros((n_ctrl, D11.shape[1]))])
        D12 = np.vstack([D12, epsilon * np.eye(n_ctrl)])
        notes.append(f"regularised: appended {epsilon:g}·u to the performance outputs (D12)")
    s21 = sla.svdvals(D21) if D21.size else np.zeros(0)
    scale21 = max(np.linalg.norm(np.vstack([B1, D21]), 2), np.finfo(float).tiny)
    if D21.shape[1] < D21.shape[0] or s21.size == 0 or s21.min() <= rank_tol * scale21:
        B1 = np.hstack([B1, np.zeros((n, n_meas))])
        D11 = np.hstack([D11, np.zeros((D11.shape[0], n_meas))])
        D21 = np.hstack([D21, epsilon * np.eye(n_meas)])
        notes.append(f"regularised: added {epsilon:g}·noise to the measurements (D21)")
    if not notes:
        return P, notes
    B = np.hstack([B1, B2])
    C = np.vstack([C1, C2])
    D = np.block([[D11, D12], [D21, D22]])
    return ct.ss(A, B, C, D), notes

