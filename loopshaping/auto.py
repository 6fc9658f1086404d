"""Automatic loop shaping with convex optimisation (cvxpy, imported lazily).

The controller poles are fixed; the numerator coefficients are the variables, so G(jω) and
every A + B·G, C + D·G are affine in them at each design frequency. Each spec row (design
frequency × case) |A + B·G| ≤ W·|C + D·G| is a second-order cone on the left and a
non-convex "stay outside a disc" on the right. The right side is replaced by its tangent
lower bound W·Re(conj(z_t)·(C + D·G))/|z_t| at the current iterate z_t (convex-concave
procedure): each convex subproblem is an inner approximation, so once feasible every later
iterate is feasible and the objective (the largest controller gain over the high-frequency
grid) never increases. Slack variables with a growing penalty let the iteration start from
an infeasible loop; slack left at the end means infeasible, and the binding design
frequency and spec are reported.

The bounds only hold at the design frequencies and do not imply closed-loop stability: run
:func:`loopshaping.check.check` on the result. :func:`refine` does both in a loop: shape,
check on a dense grid over every case, add the frequencies where the check fails to the
design set (bounds recomputed there from the plant cases and the specs) and shape again.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from .bounds import Bounds, BoundsWarning, as_specs, bounds, intersect
from .check import check
from .controller import Controller
from .freqresp import check_grid, evaluate
from .templates import Template

if TYPE_CHECKING:  # annotations only
    from collections.abc import Sequence

    from .specs import Spec

__all__ = ["InfeasibleError", "RefineResult", "refine", "shape"]


class InfeasibleError(ValueError):
    """No controller with the given structure meets the bounds.

    Parameters
    ----------
    message : str
        The error message.
    omega : float
        The most violated design frequency, rad/s.
    spec : str
        The most violated spec's name.
    violation_db : float
        By how much the best loop found misses it, dB.
    """

    def __init__(self, message: str, omega: float, spec: str, violation_db: float):
        super().__init__(message)
        self.omega, self.spec, self.violation_db = omega, spec, violation_db


def _rows(bounds, basis):
    """Stack every (spec, frequency, case) row: a, b (row·x), c, d (row·x), W, ω, spec name."""
    a, b, c, d, W, om, name = [], [], [], [], [], [], []
    for part in bounds.parts:
        fi = np.searchsorted(bounds.omega, part.omega)
        for k, f in enumerate(fi):
            n = part.A.shape[1]
            a.append(part.A[k])
            b.append(part.B[k][:, None] * basis[f][None, :])
            c.append(part.C[k])
            d.append(part.D[k][:, None] * basis[f][None, :])
            W.append(part.W[k])
            om.append(np.full(n, part.omega[k]))
            name += [part.spec.name] * n
    return (np.concatenate(a), np.vstack(b), np.concatenate(c), np.vstack(d), np.concatenate(W),
            np.concatenate(om), np.array(name))


def _fixed_poles(poles, omega):
    if poles is None:
        return np.array([-10.0 * omega.max()] * 2, complex)
    if isinstance(poles, Controller):
        return np.roots(poles.polys()[1]).astype(complex)
    p = np.atleast_1d(np.asarray(poles, complex))
    if p.size and not np.all(np.isfinite(p)):
        raise ValueError("poles must be finite")
    return p


def shape(bounds: Bounds, poles: object = None, *, n_zeros: int | None = None, initial: object = None,
          hf_omega: ArrayLike | None = None, margin_db: float = 0.0, max_iter: int = 40, tol: float = 1e-5,
          solver: str | None = None) -> Controller:
    """Shape G = N(s)/D(s) with fixed poles so that L0 = P0·G meets ``bounds``.

    Parameters
    ----------
    bounds : Bounds
        The bounds (their specs' exact inequalities are used, not the phase grid).
    poles : array_like or Controller, optional
        Fixed controller poles, rad/s (complex, conjugate pairs; 0 for integrators), or a
        :class:`~loopshaping.controller.Controller` whose poles are kept. Default: a double
        real pole at 10 × the highest design frequency.
    n_zeros : int, optional
        Numerator degree, ≤ number of poles (proper); default = number of poles.
    initial : Controller or control LTI, optional
        The first linearisation point (least-squares fitted onto the structure); default: a
        constant gain that lifts the nominal loop 3 dB above the highest lower bound at the
        lowest design frequency.
    hf_omega : array_like, optional
        Grid (rad/s) where the largest controller gain is minimised; default 30 points from
        2 × to 1000 × the highest design frequency.
    margin_db : float
        Every weight is tightened by this many dB, a cushion for the response between
        design frequencies.
    max_iter : int
        Convex-concave iterations at most.
    tol : float
        Relative change of the objective that ends the iteration.
    solver : str, optional
        cvxpy solver name.

    Returns
    -------
    Controller
        The shaped controller (a gain and the factors of its zeros and poles).

    Raises
    ------
    InfeasibleError
        With the binding design frequency and spec, when slack remains after ``max_iter``
        iterations.
    TypeError
        If ``bounds`` is not a Bounds.
    ValueError
        For ``n_zeros`` out of range or poles not in conjugate pairs.
    RuntimeError
        If a convex subproblem fails before any iterate.
    """
    try:
        import cvxpy as cp
    except ImportError as e:  # pragma: no cover - cvxpy is a declared dependency
        raise ImportError("loopshaping.auto.shape needs cvxpy") from e
    if not isinstance(bounds, Bounds):
        raise TypeError(f"bounds must be a loopshaping.qft.Bounds; got {type(bounds).__name__}")
    w = bounds.omega
    p = _fixed_poles(poles, w)
    m = len(p) if n_zeros is None else int(n_zeros)
    if not 0 <= m <= len(p):
        raise ValueError(f"n_zeros={n_zeros} must be between 0 and the number of poles ({len(p)}) for a proper controller")
    den = np.real_if_close(np.poly(p)) if p.size else np.array([1.0])
    if np.iscomplexobj(den):
        raise ValueError("poles must come in complex-conjugate pairs")
    if hf_omega is None:
        # A grid, not one point: a lone frequency would be "minimised" by a notch on it.
        hf_omega = np.logspace(np.log10(2 * w.max()), np.log10(1000 * w.max()), 30)
    hf = np.atleast_1d(np.asarray(hf_omega, float))
    w_s = float(np.exp(np.mean(np.log(w))))  # numerator basis (s/w_s)^i keeps columns comparable

    def basis_at(om):
        s = 1j * np.asarray(om, float)
        return (s[:, None] / w_s) ** np.arange(m + 1)[None, :] / np.polyval(den, s)[:, None]

    basis = basis_at(w)
    col = np.max(np.abs(basis), axis=0)
    basis, hf_basis = basis / col, basis_at(hf) / col
    a, b, c, d, W, om, names = _rows(bounds, basis)
    W = W * 10 ** (-float(margin_db) / 20)

    # Starting point.
    if initial is None:
        part0 = bounds.lower_bound_db()[0]
        lb = np.max(part0[np.isfinite(part0)], initial=0.0)
        p0 = _nominal(bounds)[0]
        target = np.full(len(w), 10 ** ((lb + 3) / 20) / abs(p0))
    else:
        target = initial.response(w) if isinstance(initial, Controller) else evaluate(initial, w, "initial")
    A_ls = np.vstack([basis.real, basis.imag])
    x_t = np.linalg.lstsq(A_ls, np.r_[target.real, target.imag], rcond=None)[0]

    x = cp.Variable(m + 1)
    slack = cp.Variable(len(a), nonneg=True)
    t = cp.Variable()
    tau = 10.0
    prev = np.inf
    for _ in range(max_iter):
        z_t = c + d @ x_t
        mod = np.maximum(np.abs(z_t), 1e-300)
        norm = np.where(W * mod > 0, W * mod, 1.0)
        lhs_re = cp.multiply(1 / norm, a.real + b.real @ x)
        lhs_im = cp.multiply(1 / norm, a.imag + b.imag @ x)
        lin = np.conj(z_t)[:, None] * d
        rhs = (W / (mod * norm)) * np.real(np.conj(z_t) * c) + cp.multiply(W / (mod * norm), lin.real @ x)
        g_hf = np.abs(hf_basis @ x_t).max() or 1.0
        cons = [cp.norm(cp.vstack([lhs_re, lhs_im]), 2, axis=0) <= rhs + slack,
                cp.norm(cp.vstack([hf_basis.real @ x, hf_basis.imag @ x]), 2, axis=0) <= t]
        prob = cp.Problem(cp.Minimize(t / g_hf + tau * cp.sum(slack)), cons)
        try:
            prob.solve(solver=solver)
        except cp.SolverError:
            x.value = None
        if x.value is None:
            if np.isfinite(prev):
                break  # a large penalty made the subproblem ill-conditioned: judge the last iterate
            raise RuntimeError(f"the convex subproblem failed ({prob.status}); try another solver=")
        x_t = x.value
        obj = float(np.abs(hf_basis @ x_t).max())
        if slack.value.max() < 1e-8 and abs(prev - obj) <= tol * max(obj, 1e-300):
            break
        prev = obj
        tau = min(tau * 5, 1e5)

    with np.errstate(divide="ignore"):
        viol = 20 * np.log10(np.abs(a + b @ x_t)) - 20 * np.log10(W * np.abs(c + d @ x_t))
    viol = np.nan_to_num(viol, nan=0.0, neginf=-np.inf)
    worst = int(np.argmax(viol))
    if viol[worst] > 1e-6:
        raise InfeasibleError(
            f"no controller with poles {np.round(p, 6).tolist()} and {m} zeros meets the bounds: spec "
            f"{names[worst]!r} is missed by {viol[worst]:.3g} dB at ω = {om[worst]:.4g} rad/s",
            float(om[worst]), str(names[worst]), float(viol[worst]))
    coef = x_t / col / w_s ** np.arange(m + 1)  # ascending powers of s
    scale = np.max(np.abs(x_t))
    keep = np.flatnonzero(np.abs(x_t) > 1e-10 * scale)
    num = coef[: keep.max() + 1][::-1]
    return Controller.from_zpk(np.roots(num), p, num[0] / den[0])


def _nominal(bounds):
    """Nominal plant P0 at the design frequencies, from the parts of the bounds."""
    p0 = np.full(len(bounds.omega), np.nan + 0j)
    for part in bounds.parts:
        p0[np.searchsorted(bounds.omega, part.omega)] = part.p0
    return p0


@dataclass(frozen=True, eq=False)
class RefineResult:
    """Outcome of :func:`refine`.

    Parameters
    ----------
    controller : Controller
        The last shaped controller.
    bounds : Bounds
        The bounds it was shaped against (the final design set).
    template : Template
        The plant cases at the final design frequencies (rad/s).
    check : CheckResult
        :func:`loopshaping.check.check` of ``controller`` on the dense grid.
    added : numpy.ndarray
        (k,) frequencies added to the design set, rad/s, in the order they were added.
    rounds : int
        Shaping calls made.
    """

    controller: Controller
    bounds: Bounds
    template: Template
    check: object
    added: np.ndarray
    rounds: int

    @property
    def passed(self) -> bool:
        """Every spec met on the dense grid for every case and every closed loop stable."""
        return bool(self.check.passed)


def refine(template: Template, specs: "Bounds | Spec | Sequence[Spec]", omega: ArrayLike, poles: object = None, *,
           max_rounds: int = 6, margin_db: float = 0.01, phases_deg: ArrayLike | None = None,
           **shape_kwargs) -> RefineResult:
    """:func:`shape`, check on a dense grid, add the failing frequencies, shape again.

    Each round shapes against the exact bounds of ``specs`` at the current design frequencies
    (first the template's), runs :func:`loopshaping.check.check` on ``omega`` over every
    case and, if a spec fails, adds the worst frequency of every violated range of the grid
    to the design set (bounds recomputed there from the plant cases), starting the next shape
    from the last controller. Stops when the check passes, after ``max_rounds`` shapes, or
    when nothing new can be added (a failure left only at design frequencies, or closed-loop
    instability, which bounds at more frequencies do not cure): look at ``result.passed``.

    Parameters
    ----------
    template : Template
        Built from systems (the cases are re-evaluated at the added frequencies); a disk
        radius must be the same at every design frequency.
    specs : Bounds or Spec or list of Spec
        The specifications (of a Bounds, its specs); weights and general-form coefficients
        must be numbers, LTI or callables of ω.
    omega : array_like
        Strictly increasing grid of the check, rad/s.
    poles : array_like or Controller, optional
        As :func:`shape`.
    max_rounds : int
        Shaping calls at most, ≥ 1.
    margin_db : float
        :func:`shape`'s cushion, dB, default 0.01 dB, so that solver tolerance cannot leave
        a bound violated by a hair at a design frequency.
    phases_deg : array_like, optional
        Phase grid of the returned bounds, degrees (charts only; the shaper uses the exact
        inequalities).
    **shape_kwargs
        Passed to :func:`shape` (``n_zeros``, ``initial``, ``hf_omega``, ``max_iter``,
        ``tol``, ``solver``).

    Returns
    -------
    RefineResult
        The last controller, its bounds, template and check; ``.passed`` tells whether the
        check passed.

    Raises
    ------
    InfeasibleError
        When a shaping round is infeasible.
    TypeError
        If ``template`` is not a Template.
    ValueError
        If the template has no systems, a disk radius that varies, or ``max_rounds`` < 1.
    """
    if not isinstance(template, Template):
        raise TypeError(f"template must be a loopshaping.qft.Template; got {type(template).__name__}")
    if template.systems is None:
        raise ValueError("template has no systems (built from responses): refine re-evaluates the plant cases "
                         "at new frequencies; build it with Template.from_systems")
    disk = template.disk_radius
    if disk is not None:
        if not np.allclose(disk, disk[0], rtol=1e-12, atol=0):
            raise ValueError("template.disk_radius varies with frequency: refine cannot evaluate it at new "
                             "frequencies; expand the disk into cases or use a constant radius")
        disk = float(disk[0])
    specs = as_specs(specs)
    w_dense = check_grid(omega, "omega")
    if int(max_rounds) < 1:
        raise ValueError(f"max_rounds={max_rounds} must be ≥ 1")
    if poles is None:
        # shape's default depends on the design frequencies: fix it once for every round
        poles = _fixed_poles(None, template.omega)
    systems, nominal = template.systems, template.nominal
    w_design = template.omega
    added = []
    initial = shape_kwargs.pop("initial", None)
    for rounds in range(1, int(max_rounds) + 1):
        tmpl = Template.from_systems(systems, w_design, nominal, disk)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", BoundsWarning)
            # a spec may leave some design frequencies unconstrained (band, infinite weight)
            parts = [bounds(tmpl, sp, phases_deg=phases_deg) for sp in specs if np.any(sp.in_band(w_design))]
            b = intersect(*parts)
        G = shape(b, poles, initial=initial, margin_db=margin_db, **shape_kwargs)
        res = check(tmpl, G, specs, w_dense)
        if res.passed or rounds == int(max_rounds):
            break
        new = []
        for name, ok in zip(res.names, res.spec_passed):
            if ok:
                continue
            i = res.names.index(name)
            m = np.nan_to_num(res.margins_db[i], nan=np.inf)
            for lo, hi in res.violated_ranges(name):
                sel = (w_dense >= lo) & (w_dense <= hi)
                new.append(w_dense[sel][np.argmin(m[sel])])
        new = np.setdiff1d(np.unique(new), w_design)
        new = new[~np.isclose(new[:, None], w_design[None, :], rtol=1e-9, atol=0).any(axis=1)] if new.size else new
        if not new.size:
            break
        added.extend(new.tolist())
        w_design = np.unique(np.r_[w_design, new])
        initial = G
    return RefineResult(G, b, tmpl, res, np.array(added, float), rounds)
