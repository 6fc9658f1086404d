"""Exact QFT bounds: the closed-form solver, :class:`Bounds` and :func:`intersect`.

A *bound* at a design frequency is the set of nominal open-loop values L0 = P0·G (phase in
degrees, magnitude in dB) for which a specification holds for every case.

Every specification is written in the general form |(A + B·G)/(C + D·G)| ≤ W per case
(see :mod:`loopshaping.specs`). With G = L0/P0 and L0 = y·e^{jφ}, squaring gives, per case
and phase, a quadratic inequality in y = |L0|:

    a·y² + b(φ)·y + c ≤ 0,  a = |B'|² − W²|D'|², b = 2 Re(K e^{jφ}), c = |A|² − W²|C|²,

with B' = B/P0, D' = D/P0 and K = conj(A)·B' − W²·conj(C)·D'. Its solution is an interval
(a > 0), the complement of an interval (a < 0) or a half-line (a = 0), in closed form. The
bound is the intersection over cases: a band [max lower, min upper] minus the union of the
forbidden intervals. No magnitude grid is involved, so the bound is exact on the phase grid,
and :meth:`Bounds.is_allowed` evaluates the inequalities directly at any phase.

Frequencies in rad/s; magnitudes in dB only in the bound tables (``forbidden_db``).
"""
from __future__ import annotations

import warnings
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from .freqresp import DEFAULT_PHASES_DEG, check_phases, grid_indices
from .specs import Spec
from .templates import Template, tracking_pairs

__all__ = ["DEFAULT_PHASES_DEG", "Bounds", "BoundsWarning", "bounds", "intersect", "as_specs"]

# Phases × cases evaluated at once: small enough to stay in cache (measured optimum).
_BLOCK = 50_000


class BoundsWarning(UserWarning):
    """A bound is empty at some design frequency: no controller meets the spec there.

    Raised (as a warning) by :func:`bounds`; see ``Bounds.empty``.
    """


# ----------------------------------------------------------------------------- exact bounds
def _merge(lo, hi):
    """Union of intervals (lo, hi) along the last axis → sorted disjoint intervals.

    Empty intervals (hi ≤ lo) are dropped. Returns (lo, hi) of shape (..., k) padded with NaN.
    """
    lead = lo.shape[:-1]
    lo = lo.reshape(-1, lo.shape[-1])
    hi = hi.reshape(-1, hi.shape[-1])
    valid = hi > lo
    lo = np.where(valid, lo, np.inf)
    order = np.argsort(lo, axis=-1, kind="stable")
    lo = np.take_along_axis(lo, order, -1)
    hi = np.take_along_axis(np.where(valid, hi, -np.inf), order, -1)
    valid = np.take_along_axis(valid, order, -1)
    run = np.maximum.accumulate(hi, axis=-1)
    prev = np.concatenate([np.full((len(lo), 1), -np.inf), run[:, :-1]], axis=-1)
    start = valid & (lo > prev)
    start[:, 0] = valid[:, 0]
    nxt = np.concatenate([start[:, 1:] | ~valid[:, 1:], np.ones((len(lo), 1), bool)], axis=-1)
    last = valid & nxt
    gid = np.cumsum(start, axis=-1) - 1
    k = max(int(start.sum(-1).max(initial=0)), 1)
    out_lo = np.full((len(lo), k), np.nan)
    out_hi = np.full((len(lo), k), np.nan)
    r, c = np.nonzero(start)
    out_lo[r, gid[r, c]] = lo[r, c]
    r, c = np.nonzero(last)
    out_hi[r, gid[r, c]] = run[r, c]
    return out_lo.reshape(*lead, k), out_hi.reshape(*lead, k)


def _roots(b, a, c):
    """Real roots (lo, hi) of a·y² + b·y + c, stable form; NaN-free where disc ≥ 0."""
    disc = b * b - 4.0 * a * c
    with np.errstate(divide="ignore", invalid="ignore"):
        q = -0.5 * (b + np.copysign(np.sqrt(np.maximum(disc, 0.0)), b))
        r1, r2 = q / a, c / q
    return np.fmin(r1, r2), np.fmax(r1, r2), disc


def _bound_at(A, Bp, C, Dp, W, cos, sin):
    """Forbidden intervals of |L0| in dB at one frequency: (n_phase, k) lo and hi (NaN padded).

    Inputs are per case at this frequency (B' = B/P0, D' = D/P0). Cases are grouped by the
    sign of the quadratic coefficient a (it does not depend on the phase), so each group
    needs one closed form and no per-element branching.
    """
    W2 = W * W
    a = np.abs(Bp) ** 2 - W2 * np.abs(Dp) ** 2
    c = np.abs(A) ** 2 - W2 * np.abs(C) ** 2
    K2 = 2.0 * (np.conj(A) * Bp - W2 * np.conj(C) * Dp)
    lin = np.abs(a) <= 1e-12 * (np.abs(Bp) ** 2 + W2 * np.abs(Dp) ** 2)
    groups = {g: np.flatnonzero(m) for g, m in (("pos", (a > 0) & ~lin), ("neg", (a < 0) & ~lin), ("lin", lin))}
    n_phase, n_cases = len(cos), len(a)
    step = max(1, _BLOCK // n_cases)
    Lmax = np.zeros(n_phase)
    Hmin = np.full(n_phase, np.inf)
    f_lo, f_hi = [], []
    for p in range(0, n_phase, step):
        ph = slice(p, p + step)
        cs, sn = cos[ph, None], sin[ph, None]
        i = groups["pos"]
        if i.size:
            # a > 0: allowed y ∈ [r_lo, r_hi]; nothing allowed where the roots are complex.
            b = cs * K2.real[i] - sn * K2.imag[i]
            r_lo, r_hi, disc = _roots(b, a[i], c[i])
            Lmax[ph] = np.maximum(Lmax[ph], r_lo.max(axis=1))
            Hmin[ph] = np.minimum(Hmin[ph], np.where((disc < 0).any(axis=1), 0.0, r_hi.min(axis=1)))
        i = groups["lin"]
        if i.size:
            # a = 0: b·y + c ≤ 0 is a half-line (or everything / nothing when b = 0).
            b = cs * K2.real[i] - sn * K2.imag[i]
            cc = np.broadcast_to(c[i], b.shape)
            with np.errstate(divide="ignore", invalid="ignore"):
                root = -cc / b
            none = (b == 0) & (cc > 0)
            Lmax[ph] = np.maximum(Lmax[ph], np.where(b < 0, root, np.where(none, np.inf, 0.0)).max(axis=1))
            Hmin[ph] = np.minimum(Hmin[ph], np.where(b > 0, root, np.where(none, 0.0, np.inf)).min(axis=1))
        i = groups["neg"]
        if i.size:
            # a < 0: forbidden y ∈ (r_lo, r_hi) where the roots are real.
            b = cs * K2.real[i] - sn * K2.imag[i]
            r_lo, r_hi, disc = _roots(b, a[i], c[i])
            valid = disc > 0
            lo = np.where(valid, r_lo, np.inf)
            hi = np.where(valid, r_hi, -np.inf)
            # The union is one interval when the interval reaching lowest and the one reaching
            # highest overlap (every other lies inside their span); only the remaining phases
            # need the general sort-and-merge.
            rows = np.arange(lo.shape[0])
            j_lo, j_hi = lo.argmin(axis=1), hi.argmax(axis=1)
            lo_min, hi_max = lo[rows, j_lo], hi[rows, j_hi]
            simple = (lo[rows, j_hi] <= hi[rows, j_lo]) | ~valid.any(axis=1)
            if not simple.all():
                # Otherwise walk down from the top: [t, hi_max] is covered and connected,
                # so every interval reaching t extends it down to its own lower end.
                hard = np.flatnonzero(~simple)
                t = lo[hard, j_hi[hard]]
                for _ in range(8):
                    t_new = np.where(hi[hard] >= t[:, None], lo[hard], np.inf).min(axis=1)
                    done = t_new <= lo_min[hard]
                    simple[hard[done]] = True
                    moved = t_new < t
                    keep = ~done & moved
                    hard, t = hard[keep], t_new[keep]
                    if not hard.size:
                        break
            if simple.all():
                mlo, mhi = lo_min[:, None], hi_max[:, None]
            else:
                hard = ~simple
                glo, ghi = _merge(lo[hard], hi[hard])
                mlo = np.full((len(rows), glo.shape[1]), np.nan)
                mhi = mlo.copy()
                mlo[simple, 0], mhi[simple, 0] = lo_min[simple], hi_max[simple]
                mlo[hard], mhi[hard] = glo, ghi
            f_lo.append((ph, mlo))
            f_hi.append((ph, mhi))
    k = max([x.shape[1] for _, x in f_lo], default=0)
    lo = np.full((n_phase, k + 2), np.inf)
    hi = np.full((n_phase, k + 2), -np.inf)
    lo[:, 0], hi[:, 0] = 0.0, Lmax
    lo[:, 1], hi[:, 1] = np.maximum(Hmin, 0.0), np.inf
    for (ph, mlo), (_, mhi) in zip(f_lo, f_hi):
        lo[ph, 2 : 2 + mlo.shape[1]] = np.where(np.isnan(mlo), np.inf, np.maximum(mlo, 0.0))
        hi[ph, 2 : 2 + mhi.shape[1]] = np.where(np.isnan(mhi), -np.inf, mhi)
    lo, hi = _merge(lo, hi)
    with np.errstate(divide="ignore"):
        return 20 * np.log10(lo), 20 * np.log10(hi)


@dataclass(frozen=True, eq=False)
class _Part:
    """One specification at its design frequencies: the exact inequality data and its bound."""

    spec: Spec
    omega: np.ndarray
    p0: np.ndarray  # (n_f,) nominal plant
    A: np.ndarray  # (n_f, n_c)
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    W: np.ndarray
    forbidden_db: np.ndarray  # (n_f, n_phase, k, 2)

    def ok(self, fi, L0, rtol=1e-9):
        """Spec met at frequency index fi for nominal loop values L0 (any shape) → bool."""
        return _met(self.A[fi], self.B[fi], self.C[fi], self.D[fi], self.W[fi], L0[..., None] / self.p0[fi], rtol)

    def ok_each(self, L0, rtol=1e-9):
        """Spec met at each design frequency for the nominal loop L0 there, shape (n_f,) → bool (n_f,)."""
        return _met(self.A, self.B, self.C, self.D, self.W, (L0 / self.p0)[:, None], rtol)


def _met(A, B, C, D, W, G, rtol):
    """|A + B·G| ≤ W·|C + D·G| for every case (last axis), squared, with a relative tolerance."""
    lhs = np.abs(A + B * G) ** 2
    rhs = W**2 * np.abs(C + D * G) ** 2
    return np.all(lhs <= rhs * (1 + rtol) + 1e-300, axis=-1)


def bounds(template: Template, kind: str | Spec, weight: object = None, phases_deg: ArrayLike | None = None, *,
           band: tuple | None = None, name: str | None = None, n_disk: int = 24, **kind_args) -> Bounds:
    """Exact QFT bounds of one specification at the template's design frequencies.

    Parameters
    ----------
    template : Template
        The plant cases at the design frequencies (rad/s).
    kind : str or Spec
        One of :data:`~loopshaping.specs.KINDS`, or a :class:`~loopshaping.specs.Spec`
        (then ``weight``/``band``/``name``/kind args must not be given). Kinds, with
        L = P·G: "stability" |L/(1+L)| ≤ W, "sensitivity" |1/(1+L)| ≤ W,
        "input_disturbance" |P/(1+L)| ≤ W, "control_effort" |G/(1+L)| ≤ W, "noise"
        |G·H/(1+P·G·H)| ≤ W (``sensor=H``), "tracking" max|T|/min|T| over cases ≤ W (or
        ``upper=``, ``lower=``: W = |upper|/|lower|), "general" |(A+B·G)/(C+D·G)| ≤ W.
    weight : float or array_like or control LTI or callable, optional
        W as a linear magnitude (not dB): a number, a per-frequency array, an
        (n_omega, n_cases) array, an LTI or a callable of ω (rad/s). np.inf = unconstrained
        at that frequency.
    phases_deg : array_like, optional
        Phase grid of L0, degrees; default −360…0 in 1° steps.
    band : tuple of float, optional
        ``(low, high)`` in rad/s: the spec applies only there.
    name : str, optional
        Name of the spec in tables; default the kind.
    n_disk : int
        Points sampling each case's disk when the template has ``disk_radius``.
    **kind_args
        The kind's arguments (``sensor``; ``upper``, ``lower``; ``A``, ``B``, ``C``, ``D``).

    Returns
    -------
    Bounds
        The bounds of this spec; warns :class:`BoundsWarning` for frequencies where no
        controller meets it (``Bounds.empty``).

    Raises
    ------
    TypeError
        If ``template`` is not a Template, or a Spec is given together with kind arguments.
    ValueError
        If the band or infinite weights leave no design frequency, or a weight is invalid.

    Examples
    --------
    >>> import control as ct
    >>> T = Template.from_systems([ct.tf([1], [1, 1]), ct.tf([3], [1, 1])], [0.1, 1.0])
    >>> b = bounds(T, "sensitivity", 2.0)
    >>> b.forbidden_db.shape[:2], bool(b.empty.any())
    ((2, 361), False)
    """
    if not isinstance(template, Template):
        raise TypeError(f"template must be a loopshaping.qft.Template; got {type(template).__name__}")
    if isinstance(kind, Spec):
        if weight is not None or band is not None or kind_args or name is not None:
            raise TypeError("pass either a Spec or kind/weight/band/kind args, not both")
        spec = kind
    else:
        spec = Spec(kind, weight, band, name, dict(kind_args))
    phases = check_phases(phases_deg)
    w_all = template.omega
    keep = spec.in_band(w_all)
    if not np.any(keep):
        raise ValueError(f"band={spec.band} excludes every design frequency {w_all.tolist()}")
    if spec.kind == "general":
        if template.disk_radius is not None:
            raise ValueError("kind='general' takes A, B, C, D per case; the template's disk is not applied "
                             "to them: expand it into cases yourself (Template.expanded())")
        A, B, C, D = spec.coefficients(w_all, template.responses, design=w_all)
    elif spec.kind == "tracking":
        A, B, C, D = tracking_pairs(template.expanded(n_disk))
    else:
        A, B, C, D = spec.coefficients(w_all, template.expanded(n_disk), design=w_all)
    W = spec.weights(w_all, A.shape[1], design=w_all)
    keep &= ~np.all(np.isinf(W), axis=1)
    if np.any(np.isinf(W[keep])):
        raise ValueError(f"weight of spec {spec.name!r} may be np.inf only for all cases of a frequency at once")
    if not np.any(keep):
        raise ValueError(f"spec {spec.name!r} constrains no design frequency (all weights infinite or out of band)")
    idx = np.flatnonzero(keep)
    p0 = template.nominal_response
    rad = np.deg2rad(phases)
    cos, sin = np.cos(rad), np.sin(rad)
    pieces = []
    for f in idx:
        lo, hi = _bound_at(A[f], B[f] / p0[f], C[f], D[f] / p0[f], W[f], cos, sin)
        pieces.append(np.stack([lo, hi], axis=-1))
    k = max(p.shape[1] for p in pieces)
    forb = np.full((len(idx), len(phases), k, 2), np.nan)
    for i, p in enumerate(pieces):
        forb[i, :, : p.shape[1]] = p
    part = _Part(spec, w_all[idx], p0[idx], A[idx], B[idx], C[idx], D[idx], W[idx], forb)
    out = Bounds(part.omega, phases, forb, (part,))
    if np.any(out.empty):
        warnings.warn(f"spec {spec.name!r} cannot be met by any controller at ω = "
                      f"{out.omega[out.empty].tolist()} rad/s (empty bound)", BoundsWarning, stacklevel=2)
    return out


@dataclass(frozen=True, eq=False)
class Bounds:
    """Exact bounds on the nominal open loop L0 = P0·G at the design frequencies.

    Made by :func:`bounds` and :func:`intersect`, not by hand.

    Parameters
    ----------
    omega : numpy.ndarray
        (n_omega,) design frequencies, rad/s.
    phases_deg : numpy.ndarray
        (n_phase,) phase grid of L0, degrees.
    forbidden_db : numpy.ndarray
        (n_omega, n_phase, k, 2): ``forbidden_db[i, j]`` lists, for ω = ``omega[i]`` and
        phase ``phases_deg[j]``, the sorted disjoint open intervals of |L0| in dB (±inf
        allowed, NaN padding) where some spec fails for some case; everything else is allowed.
    parts : tuple
        Each spec's inequality data, so :meth:`is_allowed` is exact at any phase.
    """

    omega: np.ndarray
    phases_deg: np.ndarray
    forbidden_db: np.ndarray
    parts: tuple

    @property
    def names(self) -> tuple:
        """Names of the specs, one per part."""
        return tuple(p.spec.name for p in self.parts)

    @property
    def specs(self) -> tuple:
        """The :class:`~loopshaping.specs.Spec` of each part."""
        return tuple(p.spec for p in self.parts)

    @property
    def empty(self) -> np.ndarray:
        """(n_omega,) True where every phase and magnitude is forbidden."""
        f = self.forbidden_db[..., 0, :]
        return np.all((f[..., 0] == -np.inf) & (f[..., 1] == np.inf), axis=1)

    @property
    def n_allowed_pieces(self) -> np.ndarray:
        """(n_omega, n_phase) number of disjoint allowed magnitude ranges at each phase."""
        lo, hi = self.forbidden_db[..., 0], self.forbidden_db[..., 1]
        k = np.sum(~np.isnan(lo), axis=-1)
        starts_low = lo[..., 0] == -np.inf
        ends_high = np.take_along_axis(hi, np.maximum(k - 1, 0)[..., None], -1)[..., 0] == np.inf
        return k + 1 - starts_low.astype(int) - (ends_high & (k > 0)).astype(int)

    @property
    def non_connected(self) -> np.ndarray:
        """(n_omega,) True where at some phase the allowed set has an island.

        "Above or below a forbidden region" (the usual U-shaped stability bound) is one bound
        curve; an allowed range closed on both sides next to another allowed range is not,
        and needs care when shaping (multiple-valued bounds).
        """
        k = np.sum(~np.isnan(self.forbidden_db[..., 0]), axis=-1)
        return np.any((self.n_allowed_pieces >= 2) & (k >= 2), axis=1)

    def edges(self):
        """Bound curves in dB, each (n_omega, n_phase, k), NaN where absent.

        Returns
        -------
        lower : numpy.ndarray
            The top of each forbidden interval (L0 must lie above; drawn solid), dB.
        upper : numpy.ndarray
            Its bottom (L0 must lie below; drawn dashed), dB.
        """
        lo, hi = self.forbidden_db[..., 0], self.forbidden_db[..., 1]
        lower = np.where(np.isfinite(hi), hi, np.nan)
        upper = np.where(np.isfinite(lo), lo, np.nan)
        return lower, upper

    def is_allowed(self, omega, phase_deg, magnitude_db) -> np.ndarray:
        """True where L0 = 10^(magnitude_db/20)·e^{j·phase} meets every spec for every case.

        Evaluated exactly from the inequalities, not from the phase grid.

        Parameters
        ----------
        omega : array_like
            Design frequencies of these bounds, rad/s.
        phase_deg : array_like
            Phase of L0, degrees.
        magnitude_db : array_like
            |L0|, dB.

        Returns
        -------
        numpy.ndarray
            Bool, the broadcast shape of the three arguments.

        Raises
        ------
        ValueError
            If a frequency is not a design frequency.
        """
        omega, phase, mag = np.broadcast_arrays(np.asarray(omega, float), np.asarray(phase_deg, float),
                                                np.asarray(magnitude_db, float))
        idx = grid_indices(self.omega, omega.ravel(), "omega").reshape(omega.shape)
        L0 = 10 ** (mag / 20) * np.exp(1j * np.deg2rad(phase))
        out = np.ones(omega.shape, bool)
        for part in self.parts:
            for fi, w in enumerate(part.omega):
                sel = self.omega[idx] == w
                if np.any(sel):
                    out[sel] &= part.ok(fi, L0[sel])
        return out

    def lower_bound_db(self) -> np.ndarray:
        """Top of the highest finite forbidden interval at each design frequency and phase.

        Above it L0 meets every spec; it is the solid curve toolbox users read first.

        Returns
        -------
        numpy.ndarray
            Shape (n_omega, n_phase), dB of |L0| (−inf where no spec forbids anything).
        """
        lower, _ = self.edges()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            top = np.nanmax(np.where(np.isnan(lower), -np.inf, lower), axis=-1)
        return top

    def dominant(self) -> np.ndarray:
        """Which spec sets :meth:`lower_bound_db` at each design frequency and phase.

        Returns
        -------
        numpy.ndarray
            Shape (n_omega, n_phase), integer index into ``parts``; −1 where no spec puts a
            lower bound there.
        """
        total = self.lower_bound_db()
        out = np.full(total.shape, -1)
        best = np.full(total.shape, -np.inf)
        for k, part in enumerate(self.parts):
            sub = Bounds(part.omega, self.phases_deg, part.forbidden_db, (part,)).lower_bound_db()
            rows = grid_indices(self.omega, part.omega, "omega")
            better = sub > best[rows]
            best[rows] = np.where(better, sub, best[rows])
            out[rows] = np.where(better & np.isfinite(sub), k, out[rows])
        return out

    def to_table(self, phases_deg=(-270.0, -225.0, -180.0, -135.0, -90.0)) -> str:
        """Plain-text table: per design frequency, status, dominant spec, forbidden |L0|.

        Parameters
        ----------
        phases_deg : sequence of float
            Phases (degrees) of the columns; the nearest grid phases are shown.

        Returns
        -------
        str
            The table, forbidden |L0| ranges in dB.
        """
        cols = _indices_of_nearest(self.phases_deg, phases_deg)
        dom = self.dominant()
        head = f"{'ω [rad/s]':>10}  {'status':<13} {'dominant':<18}" + "".join(
            f" {f'forbidden |L0| [dB] at {self.phases_deg[c]:g}°':<30}" for c in cols)
        lines = [head, "-" * len(head)]
        empty, nonc = self.empty, self.non_connected
        for i, w in enumerate(self.omega):
            status = "EMPTY" if empty[i] else ("non-connected" if nonc[i] else "ok")
            counts = np.bincount(dom[i][dom[i] >= 0], minlength=len(self.parts))
            dname = self.parts[int(np.argmax(counts))].spec.name if counts.sum() else "-"
            cells = []
            for c in cols:
                iv = [(lo, hi) for lo, hi in self.forbidden_db[i, c] if not np.isnan(lo)]
                cells.append(" ∪ ".join(f"({_fmt(lo)}, {_fmt(hi)})" for lo, hi in iv) or "none")
            lines.append(f"{w:>10.4g}  {status:<13} {dname:<18}" + "".join(f" {c:<30}" for c in cells))
        return "\n".join(lines)

    def __str__(self):
        return self.to_table()


def _fmt(x):
    return "-inf" if x == -np.inf else ("inf" if x == np.inf else f"{x:.2f}")


def _indices_of_nearest(grid, values):
    values = np.atleast_1d(np.asarray(values, float))
    return np.abs(grid[None, :] - values[:, None]).argmin(axis=1)


def intersect(*bounds_list: Bounds) -> Bounds:
    """Intersection of several :class:`Bounds` (same phase grid): all their specs at once.

    Design frequencies are united; a spec constrains only its own frequencies.

    Parameters
    ----------
    *bounds_list : Bounds
        The bounds to intersect, on the same ``phases_deg`` grid.

    Returns
    -------
    Bounds
        All their specs.

    Raises
    ------
    ValueError
        If no bounds are given or their phase grids differ.
    TypeError
        If an argument is not a Bounds.
    """
    if not bounds_list:
        raise ValueError("intersect needs at least one Bounds")
    for i, b in enumerate(bounds_list):
        if not isinstance(b, Bounds):
            raise TypeError(f"argument {i} of intersect is a {type(b).__name__}, not Bounds")
    phases = bounds_list[0].phases_deg
    for b in bounds_list[1:]:
        if b.phases_deg.shape != phases.shape or not np.allclose(b.phases_deg, phases):
            raise ValueError("intersect needs bounds on the same phases_deg grid; recompute them with the same grid")
    parts = tuple(p for b in bounds_list for p in b.parts)
    omega = np.unique(np.concatenate([p.omega for p in parts]))
    lo_all, hi_all = [], []
    for part in parts:
        rows = grid_indices(omega, part.omega, "omega")
        k = part.forbidden_db.shape[2]
        lo = np.full((len(omega), len(phases), k), np.inf)
        hi = np.full((len(omega), len(phases), k), -np.inf)
        lo[rows] = np.nan_to_num(part.forbidden_db[..., 0], nan=np.inf, posinf=np.inf, neginf=-np.inf)
        hi[rows] = np.nan_to_num(part.forbidden_db[..., 1], nan=-np.inf, posinf=np.inf, neginf=-np.inf)
        lo_all.append(lo)
        hi_all.append(hi)
    lo, hi = _merge(np.concatenate(lo_all, -1), np.concatenate(hi_all, -1))
    return Bounds(omega, phases, np.stack([lo, hi], -1), parts)


def as_specs(specs: Bounds | Spec | Iterable[Spec]) -> list:
    """A Bounds (its specs), one Spec, or an iterable of Spec → a non-empty list of Spec.

    Parameters
    ----------
    specs : Bounds or Spec or iterable of Spec
        The specifications.

    Returns
    -------
    list of Spec
        Non-empty.

    Raises
    ------
    TypeError
        If ``specs`` is empty or holds something else than :class:`Spec`.

    Examples
    --------
    >>> [sp.name for sp in as_specs(Spec("stability", 1.2))]
    ['stability']
    """
    if isinstance(specs, Bounds):
        specs = list(specs.specs)
    elif isinstance(specs, Spec):
        specs = [specs]
    else:
        specs = list(specs)
    if not specs or not all(isinstance(sp, Spec) for sp in specs):
        raise TypeError("specs must be a Bounds, a Spec or a non-empty list of Spec")
    return specs
