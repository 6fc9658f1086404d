"""H∞ synthesis that refuses ill-posed problems before SLICOT sees them.

Two entry points:

- :func:`mixed_sensitivity` for the classic stacked problem ``[W_S·S; W_KS·K·S; W_T·T]``
  with negative feedback ``u = K·(r − y)``, so the loop is ``L = G·K`` and
  ``S = (I + G·K)⁻¹``.
- :func:`synthesize` for any generalized plant ``P = [[P11, P12], [P21, P22]]`` with
  inputs ``[w; u]`` and outputs ``[z; y]`` (measurements ``y`` and controls ``u`` last),
  closed by ``u = K·y`` (the lower linear fractional transformation, SLICOT's sign).

SLICOT's H∞ routines assume (A1) (A, B2) stabilisable and (C2, A) detectable,
(A2) D12 full column rank and D21 full row rank, (A3)/(A4) no invariant zeros of
(A, B2, C1, D12) and (A, B1, C2, D21) on the imaginary axis. When one of them fails
``sb10ad`` (python-control's ``hinfsyn``) can iterate on γ without end, so every assumption
is checked first (:mod:`loopshaping.wellposed`) and a failure raises :class:`ValueError`
naming the condition and a remedy. The γ iteration itself is a bounded bisection on
``sb10fd`` (see ``_solve``).

Then :func:`~loopshaping.reduction.reduce` (balanced truncation of the stable part, the
unstable part kept exactly, with the H∞ norm of the error and the a-priori bound) and
:func:`~loopshaping.reduction.discretize` (Tustin with prewarping) make the controller
implementable; they live in :mod:`loopshaping.reduction` and are re-exported here, as are
:func:`check_well_posed` and :class:`WellPosednessWarning`.

Frequencies in rad/s. Every transfer function is a python-control object.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import control as ct
import numpy as np

from ._statespace import as_ss, check_dims, format_roots, hinf_norm, partition, slycot_routine
from .reduction import ReductionResult, discretize, reduce
from .wellposed import AXIS_TOL, RANK_TOL, WellPosednessWarning, check_well_posed, regularized_plant, shift_axis_poles

__all__ = [
    "GAMMA_GRID",
    "HinfResult",
    "ReductionResult",
    "WellPosednessWarning",
    "check_well_posed",
    "discretize",
    "mixed_sensitivity",
    "reduce",
    "synthesize",
]


#: Relative step of the grid a suboptimal γ is rounded up to before the controller is formed
#: (:func:`synthesize` with ``suboptimality`` > 0): γ = (1 + suboptimality)·γ_hi with γ_hi the
#: bisection's upper end, a step function of the data (a round-off change of the plant can flip
#: one of its feasibility tests near γ_opt and move γ_hi by up to ``gamma_tol``). Rounded up to
#: this grid, the controller is formed at the same γ unless (1 + suboptimality)·γ_hi crosses a
#: grid point: a flipped test changes it with probability ≈ gamma_tol/GAMMA_GRID (2 % at the
#: default 1e-4), instead of always; the price is a γ at most 0.5 % above the one asked.
GAMMA_GRID = 0.005


# --------------------------------------------------------------------------- results


@dataclass(frozen=True)
class HinfResult:
    """Result of an H∞ synthesis. Unpacks as ``K, gamma = result``.

    Parameters
    ----------
    controller : control.StateSpace
        The controller K (sign convention of the function that produced it).
    gamma : float
        Achieved closed-loop H∞ norm of the weighted map w → z (dimensionless when the
        weights make z and w dimensionless), computed from the closed loop by ``ab13dd``.
        γ ≤ 1 means every weighted specification is met.
    closed_loop : control.StateSpace
        The closed loop w → z.
    gamma_bound : float
        The γ for which SLICOT built the controller (≥ ``gamma``).
    generalized_plant : control.StateSpace
        The generalized plant actually synthesised (after pole shifts/regularisation).
    notes : tuple of str
        Everything that was changed to make the problem well posed.
    rcond : numpy.ndarray
        SLICOT's reciprocal condition estimates (control, measurement, X- and Y-Riccati).
    decay_rate : float
        α of an α-shifted synthesis (0 for none). With α > 0, ``gamma_bound`` is the γ of
        the shifted problem (not a bound on ``gamma``, which is measured on the jω axis).
    """

    controller: ct.StateSpace
    gamma: float
    closed_loop: ct.StateSpace
    gamma_bound: float
    generalized_plant: ct.StateSpace
    notes: tuple = ()
    rcond: np.ndarray = field(default_factory=lambda: np.full(4, np.nan))
    decay_rate: float = 0.0

    def __iter__(self):
        # The public contract is "returns controller, γ": keep tuple unpacking working.
        yield self.controller
        yield self.gamma


def _lower_lft(parts, K):
    """State space of F_l(P, K) with u = K·y (handles D22 ≠ 0 and a proper K)."""
    A, B1, B2, C1, C2 = parts["A"], parts["B1"], parts["B2"], parts["C1"], parts["C2"]
    D11, D12, D21, D22 = parts["D11"], parts["D12"], parts["D21"], parts["D22"]
    Ak, Bk, Ck, Dk = (np.asarray(M, dtype=float) for M in (K.A, K.B, K.C, K.D))
    nu = D22.shape[1]
    M = np.eye(nu) - Dk @ D22
    if np.linalg.cond(M) > 1e12:
        raise ValueError("the loop u = K·y is not well posed: I − D_K·D22 is singular")
    R = np.linalg.inv(M)
    # u = Fx·x + Fk·x_k + Fw·w; then y follows from u.
    Fx, Fk, Fw = R @ Dk @ C2, R @ Ck, R @ Dk @ D21
    Yx, Yk, Yw = C2 + D22 @ Fx, D22 @ Fk, D21 + D22 @ Fw
    Acl = np.block([[A + B2 @ Fx, B2 @ Fk], [Bk @ Yx, Ak + Bk @ Yk]])
    Bcl = np.vstack([B1 + B2 @ Fw, Bk @ Yw])
    Ccl = np.hstack([C1 + D12 @ Fx, D12 @ Fk])
    Dcl = D11 + D12 @ Fw
    return ct.ss(Acl, Bcl, Ccl, Dcl)



# --------------------------------------------------------------------------- synthesis


def synthesize(
    generalized_plant: ct.StateSpace | ct.TransferFunction,
    n_meas: int,
    n_ctrl: int,
    *,
    regularize: bool = False,
    epsilon: float = 1e-3,
    suboptimality: float = 0.0,
    gamma_tol: float = 1e-4,
    rank_tol: float = RANK_TOL,
    axis_tol: float = AXIS_TOL,
    decay_rate: float = 0.0,
    decay_states: np.ndarray | None = None,
) -> HinfResult:
    """γ-optimal H∞ controller for a general plant, closed by ``u = K·y``.

    Parameters
    ----------
    generalized_plant : control.StateSpace
        Continuous-time plant, inputs ``[w; u]`` and outputs ``[z; y]`` with the
        ``n_meas`` measurements and ``n_ctrl`` controls last.
    n_meas, n_ctrl : int
        Sizes of y and u.
    regularize : bool
        If D12/D21 lack rank, append ``epsilon·u`` to z / ``epsilon·v`` noise to y instead
        of raising (recorded in ``notes`` and warned).
    epsilon : float
        Size of the regularisation (in the units of z per unit of u, y per unit of noise).
    suboptimality : float
        ≥ 0. With 0 the central controller at the smallest γ the bisection found feasible
        (within ``gamma_tol`` of γ_opt); with e.g. 0.05 the one at 1.05 times that, rounded up to
        the relative grid :data:`GAMMA_GRID` (so round-off in the data does not move it), usually
        with much slower, better-conditioned poles.
    gamma_tol : float
        Relative width of the final γ bracket of the bisection.
    rank_tol, axis_tol : float
        Tolerances of :func:`check_well_posed`.
    decay_rate : float
        α ≥ 0 (1/s). With α > 0 the synthesis is α-shifted: it is done on the plant with
        A → A + α·I and the controller is shifted back (A_K → A_K − α·I), so every pole of
        the closed loop F_l(P, K) satisfies Re p < −α (ζ ≥ α/|p| for an oscillatory pair).
        The price: the γ-optimality then holds on the line Re s = −α, not on the jω axis;
        ``gamma`` is recomputed on the jω axis. Modes the controller cannot move (weight
        poles) slower than α make the shifted problem ill posed (ValueError): lower α or
        use ``decay_states``.
    decay_states : array of bool, optional
        Shift only these states of ``generalized_plant`` (default: all). Use it to leave
        input and output weights, which sit in series outside the feedback loop and which
        no controller can move, unshifted: the bound Re p < −α then holds for the poles of
        the loop formed by the shifted states and the controller, and the unshifted
        weights keep their own poles. The caller is responsible for the unshifted states
        being such series weights; the returned ``closed_loop`` lets you check.

    Returns
    -------
    HinfResult
        Unpacks as ``K, gamma``; K has ``n_meas`` inputs and ``n_ctrl`` outputs.

    Raises
    ------
    ValueError
        At once, before SLICOT is called, if the problem is ill posed.
    """
    P = as_ss(generalized_plant, "generalized_plant")
    check_dims(P, n_meas, n_ctrl)
    if not (np.isfinite(epsilon) and epsilon > 0):
        raise ValueError(f"epsilon={epsilon!r} must be a positive number")
    if not (np.isfinite(suboptimality) and suboptimality >= 0):
        raise ValueError(f"suboptimality={suboptimality!r} must be ≥ 0 (e.g. 0.05 for 5 %)")
    if not (0 < gamma_tol < 1):
        raise ValueError(f"gamma_tol={gamma_tol!r} must be in (0, 1)")
    if P.nstates == 0:
        raise ValueError(
            "generalized_plant has no states: a static problem needs no H∞ synthesis "
            "(use a static gain), and SLICOT does not accept it"
        )
    if not (np.isfinite(decay_rate) and decay_rate >= 0):
        raise ValueError(f"decay_rate={decay_rate!r} must be a number ≥ 0 (1/s)")
    if decay_states is None:
        mask = np.ones(P.nstates, dtype=bool)
    else:
        mask = np.asarray(decay_states, dtype=bool).reshape(-1)
        if mask.size != P.nstates:
            raise ValueError(
                f"decay_states has {mask.size} entries, the generalized plant {P.nstates} states"
            )
    notes = []
    if regularize:
        P, notes = regularized_plant(P, n_meas, n_ctrl, epsilon, rank_tol)
        for note in notes:
            warnings.warn(note, WellPosednessWarning, stacklevel=2)
    if decay_rate == 0:
        check_well_posed(P, n_meas, n_ctrl, rank_tol=rank_tol, axis_tol=axis_tol)
        return _solve(P, n_meas, n_ctrl, suboptimality, gamma_tol, tuple(notes))
    alpha = float(decay_rate)
    shift = alpha * np.diag(mask.astype(float))
    P_alpha = ct.ss(np.asarray(P.A, dtype=float) + shift, P.B, P.C, P.D)
    try:
        check_well_posed(P_alpha, n_meas, n_ctrl, rank_tol=rank_tol, axis_tol=axis_tol)
    except ValueError as e:
        raise ValueError(
            f"with decay_rate={alpha:g} (synthesis on A + α·I): {e} A mode slower than α that "
            "the controller cannot move (typically a weight pole) makes the shifted problem ill "
            "posed: lower decay_rate, speed up that weight pole, or leave the weights out of "
            "the shift with decay_states."
        ) from None
    notes = tuple(notes) + (
        f"α-shifted synthesis: decay_rate {alpha:g} 1/s ({int(mask.sum())} of {P.nstates} "
        "states shifted); γ recomputed on the jω axis",
    )
    res = _solve(P_alpha, n_meas, n_ctrl, suboptimality, gamma_tol, notes)
    Ka = res.controller
    K = ct.ss(np.asarray(Ka.A, dtype=float) - alpha * np.eye(Ka.nstates), Ka.B, Ka.C, Ka.D)
    cl = _lower_lft(partition(P, n_meas, n_ctrl), K)
    if cl.nstates and np.max(np.linalg.eigvals(cl.A).real) >= 0:  # pragma: no cover
        raise RuntimeError("α-shifted synthesis returned a destabilising controller")
    return HinfResult(
        controller=K, gamma=hinf_norm(cl), closed_loop=cl, gamma_bound=res.gamma_bound,
        generalized_plant=P, notes=notes, rcond=res.rcond, decay_rate=alpha,
    )


def _on_gamma_grid(gamma):
    """The smallest γ of the relative grid (1 + :data:`GAMMA_GRID`)^k, k whole, that is ≥ ``gamma``."""
    k = np.ceil(np.log(gamma) / np.log1p(GAMMA_GRID) * (1 - 1e-12))
    return max(float(np.exp(k * np.log1p(GAMMA_GRID))), gamma)


def _solve(P, n_meas, n_ctrl, suboptimality, gamma_tol, notes):
    """γ iteration by bisection on SLICOT's suboptimal solver ``sb10fd``.

    ``sb10ad`` (python-control's choice) iterates on γ internally and was seen to run for
    more than ten minutes on a badly scaled but well-posed turbine problem; a bisection
    here has a bounded number of steps, each a pair of Riccati equations.
    """
    parts = partition(P, n_meas, n_ctrl)
    # SLICOT's formulas assume D22 = 0; loop-shift it out and back in:
    # y0 = y − D22·u, synthesise K0 on y0, then K = K0·(I + D22·K0)⁻¹ on y.
    D22 = parts["D22"]
    A, B, C, D = (np.array(M, dtype=float, order="F") for M in (P.A, P.B, P.C, P.D))
    has_d22 = bool(np.any(D22))
    if has_d22:
        D[-n_meas:, -n_ctrl:] = 0.0
    n, m, np_ = A.shape[0], B.shape[1], C.shape[0]
    # A diagonal state similarity (SLICOT tb01id) changes no transfer function but brings
    # physical models (N·m next to rad) to a scale the Riccati solvers can handle.
    _, A, B, C, _ = slycot_routine("tb01id")(n, m, np_, 0.0, A.copy(), B.copy(), C.copy(), job="A")
    Pb = ct.ss(A, B, C, np.asarray(P.D, dtype=float))
    parts_b = partition(Pb, n_meas, n_ctrl)
    sb10fd = slycot_routine("sb10fd")

    def attempt(gamma):
        # SLICOT may overwrite its arguments: hand it copies.
        try:
            Ak, Bk, Ck, Dk, rcond = sb10fd(
                n, m, np_, n_ctrl, n_meas, gamma, A.copy(), B.copy(), C.copy(), D.copy()
            )
        except Exception:  # info 6-9: γ too small (or Riccati failure at this γ)
            return None
        K = ct.ss(Ak, Bk, Ck, Dk)
        if has_d22:
            # u = K0·(y − D22·u)  ⇒  u = (I + K0·D22)⁻¹·K0·y: K0 in feedback around D22.
            K = ct.feedback(K, ct.ss([], [], [], D22), sign=-1)
        try:
            cl = _lower_lft(parts_b, K)
        except ValueError:
            return None
        if cl.nstates and np.max(np.linalg.eigvals(cl.A).real) >= 0:
            return None
        return K, cl, np.asarray(rcond, dtype=float)

    hi, sol = 1.0, attempt(1.0)
    while sol is None:
        hi *= 10.0
        if hi > 1e12:
            raise RuntimeError(
                "no stabilising H∞ controller found up to γ = 1e12 although the problem passed "
                "the well-posedness checks: check the scaling of the generalized plant"
            )
        sol = attempt(hi)
    lo = hi / 10.0 if hi > 1.0 else None
    while lo is None:
        trial = hi / 10.0
        if trial < 1e-12:
            lo = 0.0
            break
        s_trial = attempt(trial)
        if s_trial is None:
            lo = trial
        else:
            hi, sol = trial, s_trial
    while hi - lo > gamma_tol * hi:
        mid = np.sqrt(lo * hi) if lo > 0 else hi / 2.0
        s_mid = attempt(mid)
        if s_mid is None:
            lo = mid
        else:
            hi, sol = mid, s_mid
    gamma_bound = float(hi)
    if suboptimality > 0:
        gamma_bound = _on_gamma_grid(float(hi) * (1.0 + suboptimality))
        s_sub = attempt(gamma_bound)
        if s_sub is None:  # pragma: no cover - feasibility is monotone in γ in theory
            raise RuntimeError(f"SLICOT sb10fd failed at γ = {gamma_bound:.6g} above γ_opt")
        sol = s_sub
    K, cl, rcond = sol
    gamma = hinf_norm(cl)
    return HinfResult(
        controller=K, gamma=gamma, closed_loop=cl, gamma_bound=gamma_bound,
        generalized_plant=P, notes=notes, rcond=rcond,
    )


def _augment(G, w_s, w_ks, w_t):
    """Generalized plant for mixed sensitivity, inputs [r; u], outputs [z_s; z_ks; z_t; e].

    e = r − y is the measurement, so ``u = K·e`` is negative feedback on y.
    """
    ny, nu = G.noutputs, G.ninputs
    Ag, Bg, Cg, Dg = (np.asarray(M, dtype=float) for M in (G.A, G.B, G.C, G.D))
    blocks = []  # (weight, matrices mapping [x_g; r; u] into the weight input)
    # Input of each weight as a linear map of (x_g, r, u):
    #   W_S sees e = r − y = −Cg x_g + r − Dg u, W_KS sees u, W_T sees y = Cg x_g + Dg u.
    ng = Ag.shape[0]
    maps = {
        "w_s": (-Cg, np.eye(ny), -Dg),
        "w_ks": (np.zeros((nu, ng)), np.zeros((nu, ny)), np.eye(nu)),
        "w_t": (Cg, np.zeros((ny, ny)), Dg),
    }
    for name, W in (("w_s", w_s), ("w_ks", w_ks), ("w_t", w_t)):
        if W is not None:
            blocks.append((W, *maps[name]))
    nw = sum(W.nstates for W, *_ in blocks)
    nz = sum(W.noutputs for W, *_ in blocks)
    n = ng + nw
    A = np.zeros((n, n))
    B = np.zeros((n, ny + nu))
    C = np.zeros((nz + ny, n))
    D = np.zeros((nz + ny, ny + nu))
    A[:ng, :ng] = Ag
    B[:ng, ny:] = Bg
    i, j = ng, 0
    for W, Mx, Mr, Mu in blocks:
        Aw, Bw, Cw, Dw = (np.asarray(M, dtype=float) for M in (W.A, W.B, W.C, W.D))
        k, q = Aw.shape[0], Cw.shape[0]
        A[i:i + k, i:i + k] = Aw
        A[i:i + k, :ng] = Bw @ Mx
        B[i:i + k, :ny] = Bw @ Mr
        B[i:i + k, ny:] = Bw @ Mu
        C[j:j + q, i:i + k] = Cw
        C[j:j + q, :ng] = Dw @ Mx
        D[j:j + q, :ny] = Dw @ Mr
        D[j:j + q, ny:] = Dw @ Mu
        i, j = i + k, j + q
    C[nz:, :ng] = -Cg
    D[nz:, :ny] = np.eye(ny)
    D[nz:, ny:] = -Dg
    return ct.ss(A, B, C, D)


def _weight(W, name, n_in):
    if W is None:
        return None
    W = as_ss(W, name)
    if W.ninputs == 1 and W.noutputs == 1 and n_in > 1:
        W = ct.append(*([W] * n_in))
    if W.ninputs != n_in:
        raise ValueError(
            f"{name} has {W.ninputs} inputs, expected {n_in} (a scalar weight is repeated "
            "on the diagonal)"
        )
    return W


def mixed_sensitivity(
    plant: ct.StateSpace | ct.TransferFunction,
    w_s: ct.LTI | float | None = None,
    w_ks: ct.LTI | float | None = None,
    w_t: ct.LTI | float | None = None,
    *,
    regularize: bool = False,
    epsilon: float = 1e-3,
    shift: float = 1e-4,
    suboptimality: float = 0.0,
    gamma_tol: float = 1e-4,
    rank_tol: float = RANK_TOL,
    axis_tol: float = AXIS_TOL,
    decay_rate: float = 0.0,
) -> HinfResult:
    """Mixed-sensitivity H∞ design: minimise ‖[W_S·S; W_KS·K·S; W_T·T]‖∞.

    Feedback is negative, ``u = K·(r − y)``: ``L = G·K``, ``S = (I + L)⁻¹``, ``T = L·S``
    (python-control's ``mixsyn`` convention).

    Parameters
    ----------
    plant : control LTI
        The plant G (ny outputs, nu inputs), continuous time.
    w_s, w_ks, w_t : control LTI, number or None
        Weights on S (ny inputs), K·S (nu inputs) and T (ny inputs). A SISO weight is
        repeated on the diagonal. At least one must be given. Weight poles on the
        imaginary axis (integrators, undamped resonances) are moved to Re = −``shift``
        with a :class:`WellPosednessWarning` and a note.
    regularize : bool
        Append ``epsilon·u`` to z when D12 lacks rank (e.g. no biproper w_ks) instead
        of raising.
    epsilon : float
        Size of that regularisation.
    shift : float
        Distance (rad/s) by which weight poles on the imaginary axis are moved left.
    suboptimality, gamma_tol, rank_tol, axis_tol
        As in :func:`synthesize`.
    decay_rate : float
        α ≥ 0 (1/s): α-shifted synthesis (see :func:`synthesize`) with only the plant's
        states shifted, so every pole of the feedback loop of G and K has Re < −α; the
        weights (in series, outside the loop) keep their own poles, so integrators in W_S
        are allowed.

    Returns
    -------
    HinfResult
        Unpacks as ``K, gamma = mixed_sensitivity(...)``; γ is the achieved H∞ norm of the
        stacked weighted closed loop.

    Raises
    ------
    ValueError
        At once if the problem is ill posed (e.g. a strictly proper plant with only w_s and
        w_t: D12 is rank deficient), naming the condition and the remedy.
    """
    G = as_ss(plant, "plant")
    if w_s is None and w_ks is None and w_t is None:
        raise ValueError("give at least one of w_s, w_ks, w_t")
    if not (np.isfinite(shift) and shift > 0):
        raise ValueError(f"shift={shift!r} must be a positive number of rad/s")
    ny, nu = G.noutputs, G.ninputs
    weights = {}
    notes = []
    for name, W, n_in in (("w_s", w_s, ny), ("w_ks", w_ks, nu), ("w_t", w_t, ny)):
        W = _weight(W, name, n_in)
        if W is not None:
            W, moved = shift_axis_poles(W, shift, axis_tol)
            if moved.size:
                note = (f"{name}: pole(s) on the imaginary axis at s = {format_roots(moved)} moved "
                        f"left by {shift:g} rad/s to make the problem well posed")
                notes.append(note)
                warnings.warn(note, WellPosednessWarning, stacklevel=2)
        weights[name] = W
    P = _augment(G, weights["w_s"], weights["w_ks"], weights["w_t"])
    decay_states = np.arange(P.nstates) < G.nstates  # _augment puts the plant's states first
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", WellPosednessWarning)
        result = synthesize(
            P, ny, nu, regularize=regularize, epsilon=epsilon, suboptimality=suboptimality,
            gamma_tol=gamma_tol, rank_tol=rank_tol, axis_tol=axis_tol,
            decay_rate=decay_rate, decay_states=decay_states,
        )
    for w in caught:  # re-issue at the caller of mixed_sensitivity, not inside this module
        warnings.warn(w.message, w.category, stacklevel=2)
    if notes:
        result = HinfResult(
            controller=result.controller, gamma=result.gamma, closed_loop=result.closed_loop,
            gamma_bound=result.gamma_bound, generalized_plant=result.generalized_plant,
            notes=tuple(notes) + result.notes, rcond=result.rcond,
            decay_rate=result.decay_rate,
        )
    return result
