"""QFT templates and exact bounds.

A *template* holds the frequency responses of the plant cases at the design frequencies,
shape (n_omega, n_cases), with one nominal case P0. A *bound* at a design frequency is the
set of nominal open-loop values L0 = P0·G (phase in degrees, magnitude in dB) for which a
specification holds for every case.

Every specification is written in the general form |(A + B·G)/(C + D·G)| ≤ W per case
(the classic kinds only choose A, B, C, D from the plant P). With G = L0/P0 and
L0 = y·e^{jφ}, squaring gives, per case and phase, a quadratic inequality in y = |L0|:

    a·y² + b(φ)·y + c ≤ 0,  a = |B'|² − W²|D'|², b = 2 Re(K e^{jφ}), c = |A|² − W²|C|²,

with B' = B/P0, D' = D/P0 and K = conj(A)·B' − W²·conj(C)·D'. Its solution is an interval
(a > 0), the complement of an interval (a < 0) or a half-line (a = 0), in closed form. The
bound is the intersection over cases: a band [max lower, min upper] minus the union of the
forbidden intervals. No magnitude grid is involved, so the bound is exact on the phase grid,
and :meth:`Bounds.is_allowed` evaluates the inequalities directly at any phase.

Frequencies in rad/s; magnitudes in dB only in the bound tables (``forbidden_db``).
"""
from __future__ import annotations

import itertools
import numbers
import warnings
from dataclasses import dataclass, field

import numpy as np

KINDS = ("stability", "sensitivity", "input_disturbance", "control_effort", "noise", "tracking", "general")
_KIND_ARGS = {
    "stability": (),
    "sensitivity": (),
    "input_disturbance": (),
    "control_effort": (),
    "noise": ("sensor",),
    "tracking": ("upper", "lower"),
    "general": ("A", "B", "C", "D"),
}
DEFAULT_PHASES_DEG = np.linspace(-360.0, 0.0, 361)
# Phases × cases evaluated at once: small enough to stay in cache (measured optimum).
_BLOCK = 50_000


class BoundsWarning(UserWarning):
    """A bound is empty at some design frequency: no controller meets the spec there."""


# ----------------------------------------------------------------------------- evaluation
def _is_lti(obj) -> bool:
    import control as ct

    return isinstance(obj, ct.LTI)


def evaluate(obj, omegas, name="system") -> np.ndarray:
    """Complex response of ``obj`` at s = jω, shape (n_omega,) (ω in rad/s).

    ``obj`` may be a number, a SISO python-control LTI or a callable ``fn(omegas)``.
    """
    omegas = np.asarray(omegas, float)
    if isinstance(obj, numbers.Number):
        return np.full(omegas.shape, complex(obj))
    if _is_lti(obj):
        if obj.ninputs != 1 or obj.noutputs != 1:
            raise ValueError(f"{name} must be SISO; select a channel first, e.g. sys[out, in]")
        if obj.isdtime(strict=True):
            raise ValueError(f"{name} is discrete-time; loopshaping works with continuous-time models")
        import control as ct

        if isinstance(obj, ct.TransferFunction):
            num, den = obj.num[0][0], obj.den[0][0]
            s = 1j * omegas
            with np.errstate(divide="ignore", invalid="ignore"):  # a pole on jω is reported by callers
                return np.polyval(num, s) / np.polyval(den, s)
        return np.asarray(obj(1j * omegas), complex).reshape(omegas.shape)
    if callable(obj):
        out = np.asarray(obj(omegas), complex)
        if out.shape[:1] != omegas.shape:
            raise ValueError(f"{name}(omegas) must return an array whose first axis has length {omegas.size}")
        return out
    raise TypeError(f"{name} must be a number, a SISO LTI system or a callable of ω; got {type(obj).__name__}")


def _check_grid(omegas, name="omegas") -> np.ndarray:
    w = np.atleast_1d(np.asarray(omegas, float))
    if w.ndim != 1 or w.size == 0:
        raise ValueError(f"{name} must be a non-empty 1-D array of frequencies in rad/s")
    if not np.all(np.isfinite(w)) or np.any(w <= 0):
        raise ValueError(f"{name} must be finite and > 0 (rad/s)")
    if np.any(np.diff(w) <= 0):
        raise ValueError(f"{name} must be strictly increasing; sort it (np.unique)")
    return w


def _check_phases(phases_deg) -> np.ndarray:
    if phases_deg is None:
        return DEFAULT_PHASES_DEG.copy()
    p = np.atleast_1d(np.asarray(phases_deg, float))
    if p.ndim != 1 or p.size < 2 or not np.all(np.isfinite(p)) or np.any(np.diff(p) <= 0):
        raise ValueError("phases_deg must be a strictly increasing 1-D array of ≥ 2 finite phases in degrees")
    return p


# ----------------------------------------------------------------------------- templates
@dataclass(frozen=True, eq=False)
class Template:
    """Plant cases at the design frequencies.

    Attributes
    ----------
    omegas : (n_omega,) design frequencies, rad/s, strictly increasing.
    responses : (n_omega, n_cases) complex frequency responses P_i(jω).
    nominal : index of the nominal case P0.
    disk_radius : (n_omega,) radius r(ω) ≥ 0 of an unstructured multiplicative uncertainty
        P_i·(1 + Δ), |Δ| ≤ r, around every case, or None.
    systems : the LTI models of the cases when known (needed by the dense check).
    parameters : (n_cases, n_params) parameter values of each case when gridded, names in
        ``parameter_names``.
    """

    omegas: np.ndarray
    responses: np.ndarray
    nominal: int = 0
    disk_radius: np.ndarray | None = None
    systems: tuple | None = None
    parameters: np.ndarray | None = None
    parameter_names: tuple = ()

    def __post_init__(self):
        w = _check_grid(self.omegas)
        r = np.asarray(self.responses, complex)
        if r.ndim == 1:
            r = r[:, None]
        if r.ndim != 2 or r.shape[0] != w.size or r.shape[1] == 0:
            raise ValueError(f"responses must have shape (n_omega={w.size}, n_cases ≥ 1); got {np.shape(self.responses)}")
        if not np.all(np.isfinite(r)):
            raise ValueError("responses must be finite; a plant has a pole on the imaginary axis at a design frequency")
        nominal = _case_index(self.nominal, r.shape[1])
        if not -r.shape[1] <= nominal < r.shape[1]:
            raise ValueError(f"nominal={self.nominal} is not a case index (n_cases={r.shape[1]})")
        nominal %= r.shape[1]
        if np.any(r[:, nominal] == 0):
            raise ValueError("the nominal case is zero at a design frequency; choose another nominal")
        disk = None
        if self.disk_radius is not None:
            disk = np.broadcast_to(np.asarray(self.disk_radius, float), w.shape).copy()
            if not np.all(np.isfinite(disk)) or np.any(disk < 0):
                raise ValueError("disk_radius must be finite and ≥ 0 (relative, multiplicative)")
        if self.systems is not None and len(self.systems) != r.shape[1]:
            raise ValueError("systems must have one LTI per case")
        for name, value in (("omegas", w), ("responses", r), ("nominal", nominal), ("disk_radius", disk)):
            object.__setattr__(self, name, value)
        if self.systems is not None:
            object.__setattr__(self, "systems", tuple(self.systems))

    @property
    def n_cases(self) -> int:
        return self.responses.shape[1]

    @property
    def nominal_response(self) -> np.ndarray:
        """P0(jω) at the design frequencies, (n_omega,) complex."""
        return self.responses[:, self.nominal]

    def expanded(self, n_disk: int = 24) -> np.ndarray:
        """Responses with the disk uncertainty sampled: (n_omega, n_cases·(1 + n_disk)).

        Each case keeps its centre and gains ``n_disk`` points P_i(1 + r·e^{jψ}) on its disk.
        The closed-loop functions of the classic kinds are Möbius maps of P, so their extreme
        moduli over a disk lie on its boundary circle; sampling it with n points
        under-estimates the radius by at most a factor cos(π/n) (0.9 % for n = 24).
        Without disk uncertainty the responses are returned unchanged.
        """
        if self.disk_radius is None or not np.any(self.disk_radius > 0):
            return self.responses
        psi = np.exp(2j * np.pi * np.arange(n_disk) / n_disk)
        ring = self.responses[:, :, None] * (1 + self.disk_radius[:, None, None] * psi)
        return np.concatenate([self.responses, ring.reshape(len(self.omegas), -1)], axis=1)

    def at(self, omegas) -> Template:
        """The template restricted to some of its design frequencies (rad/s)."""
        idx = _indices_of(self.omegas, omegas, "omegas")
        disk = None if self.disk_radius is None else self.disk_radius[idx]
        return Template(self.omegas[idx], self.responses[idx], self.nominal, disk, self.systems,
                        self.parameters, self.parameter_names)

    # -- constructors
    @classmethod
    def from_responses(cls, omegas, responses, nominal=0, disk_radius=None) -> Template:
        """From frequency responses, shape (n_omega, n_cases) complex, ω in rad/s."""
        return cls(omegas, responses, nominal, disk_radius)

    @classmethod
    def from_systems(cls, systems, omegas, nominal=0, disk_radius=None) -> Template:
        """From a list of SISO python-control LTI plant cases, evaluated at ``omegas`` (rad/s)."""
        systems = list(systems)
        if not systems:
            raise ValueError("systems is empty; give at least one plant case")
        w = _check_grid(omegas)
        resp = np.stack([evaluate(P, w, f"systems[{i}]") for i, P in enumerate(systems)], axis=1)
        return cls(w, resp, nominal, disk_radius, tuple(systems))

    @classmethod
    def from_parameter_grid(cls, fn, ranges, omegas, n=10, edges_only=False, nominal=None,
                            disk_radius=None) -> Template:
        """Grid a parameter box: ``fn(**params) -> LTI``, ``ranges = {name: (low, high)}``.

        ``n`` points per parameter (an int or ``{name: n}``), linearly spaced. With
        ``edges_only`` only the points on the 1-D edges of the box are kept (at most one
        parameter strictly inside its range), which is where the template boundary of most
        parametric plants lies. ``nominal`` is a dict of parameter values (added as a case
        when not on the grid) or None for the first grid point (all parameters at ``low``).
        """
        if not ranges:
            raise ValueError("ranges is empty; give {name: (low, high)} for at least one parameter")
        names = tuple(ranges)
        counts = {k: (n[k] if isinstance(n, dict) else n) for k in names}
        axes = []
        for k in names:
            lo, hi = (float(v) for v in ranges[k])
            if not hi >= lo:
                raise ValueError(f"ranges[{k!r}] must be (low, high) with high ≥ low")
            m = 1 if hi == lo else int(counts[k])
            if m < 1:
                raise ValueError(f"n must be ≥ 1 points per parameter; got {counts[k]} for {k!r}")
            axes.append(np.linspace(lo, hi, m))
        grid = np.array(list(itertools.product(*axes)), float)
        if edges_only:
            inside = np.zeros(len(grid), int)
            for j, ax in enumerate(axes):
                inside += (grid[:, j] > ax[0]) & (grid[:, j] < ax[-1])
            grid = grid[inside <= 1]
        nom_idx = 0
        if nominal is not None:
            if set(nominal) != set(names):
                raise ValueError(f"nominal must give every parameter {names}")
            row = np.array([float(nominal[k]) for k in names])
            hit = np.flatnonzero(np.all(np.isclose(grid, row, rtol=1e-12, atol=0), axis=1))
            if hit.size:
                nom_idx = int(hit[0])
            else:
                grid = np.vstack([grid, row])
                nom_idx = len(grid) - 1
        systems = [fn(**dict(zip(names, row))) for row in grid]
        t = cls.from_systems(systems, omegas, nom_idx, disk_radius)
        return cls(t.omegas, t.responses, nom_idx, t.disk_radius, t.systems, grid, names)

    @classmethod
    def from_operating_points(cls, systems, omegas, nominal=0, n_between=0, disk_radius=None) -> Template:
        """From linear models at neighbouring operating points (ordered, e.g. by wind speed).

        ``n_between`` extra cases are inserted between consecutive points as convex
        combinations (1 − t)·P_k + t·P_{k+1}, the responses a scheduled plant passes through
        between the linearisations; the combinations are kept as LTI (parallel connections).
        ``nominal`` indexes the original list.
        """
        systems = list(systems)
        if not systems:
            raise ValueError("systems is empty; give the models at the operating points")
        if int(n_between) < 0:
            raise ValueError(f"n_between={n_between} must be ≥ 0")
        nominal = _case_index(nominal, len(systems)) % len(systems)
        cases, nom = [], 0
        for k, P in enumerate(systems):
            if k == nominal:
                nom = len(cases)
            cases.append(P)
            if k + 1 < len(systems):
                for t in np.linspace(0, 1, int(n_between) + 2)[1:-1]:
                    cases.append((1 - t) * P + t * systems[k + 1])
        return cls.from_systems(cases, omegas, nom, disk_radius)


def _case_index(nominal, n_cases, name="nominal") -> int:
    """An integer case index (negative counts from the end); a float, a bool or a string is
    an error rather than a silently truncated index."""
    if isinstance(nominal, (bool, np.bool_)) or not isinstance(nominal, (numbers.Integral, np.integer)):
        raise ValueError(f"{name}={nominal!r} must be an integer index of a plant case (0..{n_cases - 1})")
    nominal = int(nominal)
    if not -n_cases <= nominal < n_cases:
        raise ValueError(f"{name}={nominal} is not a case index (n_cases={n_cases})")
    return nominal


def _indices_of(grid, values, name) -> np.ndarray:
    values = np.atleast_1d(np.asarray(values, float))
    idx = np.searchsorted(grid, values)
    idx = np.clip(idx, 0, len(grid) - 1)
    lower = np.clip(idx - 1, 0, len(grid) - 1)
    idx = np.where(np.abs(grid[lower] - values) < np.abs(grid[idx] - values), lower, idx)
    bad = ~np.isclose(grid[idx], values, rtol=1e-9, atol=0)
    if np.any(bad):
        raise ValueError(f"{name}={values[bad].tolist()} rad/s are not design frequencies {grid.tolist()}")
    return idx


# ----------------------------------------------------------------------------- specifications
@dataclass(frozen=True, eq=False)
class Spec:
    """One specification |(A + B·G)/(C + D·G)| ≤ W, by kind name (see :data:`KINDS`).

    ``weight``: a number, an array (one value per design frequency, or (n_omega, n_cases)),
    a SISO LTI (|W(jω)| is used) or a callable ``fn(omegas)``; np.inf means "no constraint".
    Numbers, arrays, real values a callable returns and static LTIs are linear magnitudes and
    must be > 0 (a negative one is an error, not silently |·|: it is likely dB); no form may
    be 0 at a design frequency (|T| ≤ 0 cannot be met). A wrong form is a TypeError and a
    wrong value a ValueError, each naming the argument (``weight``, ``upper``, ``lower``).
    ``band = (low, high)`` in rad/s restricts the spec to those frequencies. ``kind_args``:
    ``sensor`` (noise: the sensor dynamics H), ``upper``/``lower`` (tracking: the weight is
    then the ratio |upper|/|lower|, or give ``weight`` = the ratio), ``A``, ``B``, ``C``,
    ``D`` (general: each a number, an (n_omega, n_cases) array at the design frequencies, a
    callable ``fn(omegas) -> (n_omega, n_cases)``, an LTI, or a list of one LTI per case).
    """

    kind: str
    weight: object = None
    band: tuple | None = None
    name: str | None = None
    kind_args: dict = field(default_factory=dict)

    def __post_init__(self):
        if self.kind not in KINDS:
            raise ValueError(f"kind={self.kind!r} is not one of {KINDS}")
        unknown = set(self.kind_args) - set(_KIND_ARGS[self.kind])
        if unknown:
            raise TypeError(f"unknown keyword(s) {sorted(unknown)} for kind={self.kind!r}; "
                            f"it takes {_KIND_ARGS[self.kind] or 'none'}")
        if self.kind == "general":
            missing = [k for k in "ABCD" if k not in self.kind_args]
            if missing:
                raise TypeError(f"kind='general' needs A, B, C and D; missing {missing}")
        if self.kind == "tracking":
            has_ul = "upper" in self.kind_args or "lower" in self.kind_args
            if has_ul == (self.weight is not None):
                raise TypeError("kind='tracking' takes either weight (the allowed ratio max|T|/min|T|) "
                                "or both upper= and lower=")
            if has_ul and not ("upper" in self.kind_args and "lower" in self.kind_args):
                raise TypeError("kind='tracking' needs both upper= and lower=")
        elif self.weight is None:
            raise TypeError(f"kind={self.kind!r} needs a weight (number, array, LTI or callable)")
        if self.band is not None:
            try:
                lo, hi = (float(v) for v in self.band)
            except (TypeError, ValueError):
                raise ValueError(f"band={self.band!r} must be (low, high) in rad/s") from None
            if not 0 <= lo <= hi:
                raise ValueError(f"band={self.band} must be (low, high) in rad/s with 0 ≤ low ≤ high")
            object.__setattr__(self, "band", (lo, hi))
        if self.name is None:
            object.__setattr__(self, "name", self.kind)

    def in_band(self, omegas) -> np.ndarray:
        omegas = np.asarray(omegas, float)
        if self.band is None:
            return np.ones(omegas.shape, bool)
        return (omegas >= self.band[0]) & (omegas <= self.band[1])

    def weights(self, omegas, n_cases, design=None) -> np.ndarray:
        """|W| at ``omegas`` (rad/s), shape (n_omega, n_cases). Tracking: the ratio."""
        if self.kind == "tracking" and self.weight is None:
            up = self._magnitude(self.kind_args["upper"], omegas, 1, "upper", design)
            low = self._magnitude(self.kind_args["lower"], omegas, 1, "lower", design)
            with np.errstate(divide="ignore"):
                w = up / low
        else:
            w = self._magnitude(self.weight, omegas, n_cases, "weight", design)
        w = np.broadcast_to(w, (len(omegas), w.shape[1] if w.shape[1] != 1 else n_cases)).copy()
        if np.any(np.isnan(w)):
            raise ValueError(f"weight of spec {self.name!r} is NaN at some frequency (np.inf for no constraint)")
        return w

    def _magnitude(self, obj, omegas, n_cases, what, design):
        """|obj| at ``omegas``; numbers, arrays and callables returning real values must be
        > 0 (a linear magnitude: not dB, and taking |·| of a negative one silently would hide
        the mistake), and no magnitude may be 0 (|T| ≤ 0 is a bound no controller meets)."""
        raw = obj(np.asarray(omegas, float)) if callable(obj) and not _is_lti(obj) else obj
        ltis = [raw] if _is_lti(raw) else list(raw) if isinstance(raw, (list, tuple)) and raw and all(
            _is_lti(o) for o in raw) else None
        if ltis is None:
            arr = np.asarray(float(raw) if isinstance(raw, numbers.Real) and not isinstance(raw, bool) else raw)
            if arr.dtype.kind not in "iufc" or isinstance(raw, (bool, np.bool_)):
                kind = "a callable returning " if callable(obj) else ""
                raise TypeError(f"{what} of spec {self.name!r} must be a number, an array of numbers, an LTI or a "
                                f"callable of ω returning numbers; got {kind}{type(raw).__name__} {raw!r:.60}")
            if arr.dtype.kind != "c" and np.any(arr <= 0):
                raise ValueError(f"{what} of spec {self.name!r} must be > 0 (a linear magnitude, not dB; np.inf for "
                                 f"no constraint), got a minimum of {np.min(arr)!r}")
        else:
            for i, o in enumerate(ltis):  # a static LTI is a number: checked like one
                if o.ninputs == 1 and o.noutputs == 1 and _static_gain(o) is not None and _static_gain(o) <= 0:
                    at = f"[{i}]" if len(ltis) > 1 else ""
                    raise ValueError(f"{what}{at} of spec {self.name!r} is the static gain {_static_gain(o):g}; it must "
                                     "be > 0 (a linear magnitude, not dB)")
        w = np.abs(self._value(obj, omegas, n_cases, what, design)).astype(float)
        if np.any(w == 0):
            i = int(np.argmax(np.any(w == 0, axis=1)))
            raise ValueError(f"{what} of spec {self.name!r} is 0 at ω = {np.asarray(omegas, float)[i]:g} rad/s "
                             "(|T| ≤ 0 cannot be met; a zero of the weighting function on the jω axis?)")
        return w

    def coefficients(self, omegas, plants, design=None):
        """A, B, C, D (n_omega, n_cases) complex at ``omegas`` for plant responses ``plants``.

        ``design``: the design frequencies, when ``omegas`` are them (arrays given per design
        frequency are only valid there).
        """
        P = plants
        one, zero = np.ones_like(P), np.zeros_like(P)
        k = self.kind
        if k == "stability":
            return zero, P, one, P
        if k == "sensitivity":
            return one, zero, one, P
        if k == "input_disturbance":
            return P, zero, one, P
        if k == "control_effort":
            return zero, one, one, P
        if k == "noise":
            H = self._value(self.kind_args.get("sensor", 1.0), omegas, 1, "sensor", design)
            H = np.broadcast_to(H, P.shape)
            return zero, H, one, P * H
        if k == "general":
            out = []
            for key in "ABCD":
                v = self._value(self.kind_args[key], omegas, None, key, design)
                out.append(v)
            n = max(v.shape[1] for v in out)
            for i, v in enumerate(out):
                if v.shape[1] not in (1, n):
                    raise ValueError(f"A, B, C, D of spec {self.name!r} disagree on the number of cases")
                out[i] = np.broadcast_to(v, (len(omegas), n))
            return tuple(out)
        raise ValueError("tracking has no single-case coefficients; see tracking_pairs")

    def _value(self, obj, omegas, n_cases, what, design):
        omegas = np.asarray(omegas, float)
        if isinstance(obj, (list, tuple)) and obj and all(_is_lti(o) for o in obj):
            return np.stack([evaluate(o, omegas, f"{what}[{i}]") for i, o in enumerate(obj)], axis=1)
        if isinstance(obj, numbers.Number) or _is_lti(obj) or callable(obj):
            v = evaluate(obj, omegas, what)
            return v[:, None] if v.ndim == 1 else v
        arr = np.asarray(obj)
        if arr.ndim == 0:
            return np.full((len(omegas), 1), arr.item())
        if design is None or len(design) != len(omegas) or not np.allclose(design, omegas):
            raise ValueError(f"{what} of spec {self.name!r} is an array given at the design frequencies; "
                             "to evaluate it elsewhere (dense check) give an LTI or a callable of ω")
        if arr.ndim > 2 or arr.shape[0] != len(omegas):
            raise ValueError(f"{what} of spec {self.name!r} must have one value (or row) per design frequency "
                             f"({len(omegas)}); got shape {arr.shape}")
        return arr.reshape(len(omegas), -1) if arr.ndim == 1 else arr


def _static_gain(sys):
    """The gain of an LTI without dynamics (no states, or constant numerator and
    denominator), else None."""
    import control as ct

    if isinstance(sys, ct.TransferFunction):
        num, den = np.trim_zeros(sys.num[0][0], "f"), np.trim_zeros(sys.den[0][0], "f")
        if num.size <= 1 and den.size == 1:
            return float(np.real(num[0] / den[0])) if num.size else 0.0
        return None
    if isinstance(sys, ct.StateSpace) and sys.nstates == 0:
        return float(np.real(sys.D[0, 0]))
    return None


def tracking_pairs(P):
    """Coefficients of |T_i|/|T_j| ≤ δ over ordered pairs i ≠ j: (A, B, C, D), each (n, m).

    T_i/T_j = (P_i + P_i P_j G)/(P_j + P_i P_j G); m = n_cases·(n_cases − 1).
    """
    n = P.shape[1]
    i, j = np.nonzero(~np.eye(n, dtype=bool))
    Pi, Pj = P[:, i], P[:, j]
    return Pi, Pi * Pj, Pj, Pi * Pj


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
    omegas: np.ndarray
    p0: np.ndarray  # (n_f,) nominal plant
    A: np.ndarray  # (n_f, n_c)
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    W: np.ndarray
    forbidden_db: np.ndarray  # (n_f, n_phase, k, 2)

    def ok(self, fi, L0, rtol=1e-9):
        """Spec met at frequency index fi for nominal loop values L0 (any shape) → bool."""
        G = L0[..., None] / self.p0[fi]
        lhs = np.abs(self.A[fi] + self.B[fi] * G) ** 2
        rhs = self.W[fi] ** 2 * np.abs(self.C[fi] + self.D[fi] * G) ** 2
        return np.all(lhs <= rhs * (1 + rtol) + 1e-300, axis=-1)


def bounds(template: Template, kind, weight=None, phases_deg=None, *, band=None, name=None, n_disk=24,
           **kind_args) -> Bounds:
    """Exact QFT bounds of one specification at the template's design frequencies.

    Parameters
    ----------
    template : :class:`Template` (ω in rad/s).
    kind : one of :data:`KINDS`, or a :class:`Spec` (then ``weight``/``band``/kind args must
        not be given). Kinds, with L = P·G: "stability" |L/(1+L)| ≤ W, "sensitivity"
        |1/(1+L)| ≤ W, "input_disturbance" |P/(1+L)| ≤ W, "control_effort" |G/(1+L)| ≤ W,
        "noise" |G·H/(1+P·G·H)| ≤ W (``sensor=H``), "tracking" max|T|/min|T| over cases ≤ W
        (or ``upper=``, ``lower=``: W = |upper|/|lower|), "general" |(A+B·G)/(C+D·G)| ≤ W.
    weight : number, per-frequency array, (n_omega, n_cases) array, LTI or callable (linear
        magnitude, not dB). np.inf = unconstrained at that frequency.
    phases_deg : phase grid of L0 in degrees, default −360…0 in 1° steps.
    band : (low, high) rad/s: the spec applies only there.
    n_disk : points sampling each case's disk when the template has ``disk_radius``.

    Returns a :class:`Bounds`; warns :class:`BoundsWarning` for frequencies where no
    controller meets the spec (``Bounds.empty``).
    """
    if not isinstance(template, Template):
        raise TypeError(f"template must be a loopshaping.qft.Template; got {type(template).__name__}")
    if isinstance(kind, Spec):
        if weight is not None or band is not None or kind_args or name is not None:
            raise TypeError("pass either a Spec or kind/weight/band/kind args, not both")
        spec = kind
    else:
        spec = Spec(kind, weight, band, name, dict(kind_args))
    phases = _check_phases(phases_deg)
    w_all = template.omegas
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
    out = Bounds(part.omegas, phases, forb, (part,))
    if np.any(out.empty):
        warnings.warn(f"spec {spec.name!r} cannot be met by any controller at ω = "
                      f"{out.omegas[out.empty].tolist()} rad/s (empty bound)", BoundsWarning, stacklevel=2)
    return out


@dataclass(frozen=True, eq=False)
class Bounds:
    """Exact bounds on the nominal open loop L0 = P0·G at the design frequencies.

    ``forbidden_db[i, j]`` lists, for ω = ``omegas[i]`` (rad/s) and phase ``phases_deg[j]``
    (degrees), the sorted disjoint open intervals of |L0| in dB (±inf allowed, NaN padding)
    where some spec fails for some case; everything else is allowed. ``parts`` keeps each
    spec's inequality data, so :meth:`is_allowed` is exact at any phase.
    """

    omegas: np.ndarray
    phases_deg: np.ndarray
    forbidden_db: np.ndarray
    parts: tuple

    @property
    def names(self) -> tuple:
        return tuple(p.spec.name for p in self.parts)

    @property
    def specs(self) -> tuple:
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

        ``lower``: the top of a forbidden interval (L0 must lie above; drawn solid);
        ``upper``: its bottom (L0 must lie below; drawn dashed).
        """
        lo, hi = self.forbidden_db[..., 0], self.forbidden_db[..., 1]
        lower = np.where(np.isfinite(hi), hi, np.nan)
        upper = np.where(np.isfinite(lo), lo, np.nan)
        return lower, upper

    def is_allowed(self, omega, phase_deg, magnitude_db) -> np.ndarray:
        """True where L0 = 10^(magnitude_db/20)·e^{j·phase} meets every spec for every case.

        ``omega`` (rad/s) must be design frequencies of these bounds; the three arguments
        broadcast. Evaluated exactly from the inequalities, not from the phase grid.
        """
        omega, phase, mag = np.broadcast_arrays(np.asarray(omega, float), np.asarray(phase_deg, float),
                                                np.asarray(magnitude_db, float))
        idx = _indices_of(self.omegas, omega.ravel(), "omega").reshape(omega.shape)
        L0 = 10 ** (mag / 20) * np.exp(1j * np.deg2rad(phase))
        out = np.ones(omega.shape, bool)
        for part in self.parts:
            for fi, w in enumerate(part.omegas):
                sel = self.omegas[idx] == w
                if np.any(sel):
                    out[sel] &= part.ok(fi, L0[sel])
        return out

    def lower_bound_db(self) -> np.ndarray:
        """(n_omega, n_phase) top of the highest finite forbidden interval (−inf if none), dB.

        Above it L0 meets every spec; it is the solid curve toolbox users read first.
        """
        lower, _ = self.edges()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            top = np.nanmax(np.where(np.isnan(lower), -np.inf, lower), axis=-1)
        return top

    def dominant(self) -> np.ndarray:
        """(n_omega, n_phase) index into ``parts`` of the spec setting :meth:`lower_bound_db`.

        −1 where no spec puts a lower bound there.
        """
        total = self.lower_bound_db()
        out = np.full(total.shape, -1)
        best = np.full(total.shape, -np.inf)
        for k, part in enumerate(self.parts):
            sub = Bounds(part.omegas, self.phases_deg, part.forbidden_db, (part,)).lower_bound_db()
            rows = _indices_of(self.omegas, part.omegas, "omegas")
            better = sub > best[rows]
            best[rows] = np.where(better, sub, best[rows])
            out[rows] = np.where(better & np.isfinite(sub), k, out[rows])
        return out

    def to_table(self, phases_deg=(-270.0, -225.0, -180.0, -135.0, -90.0)) -> str:
        """Plain-text table: per design frequency, status, dominant spec and the forbidden
        |L0| ranges in dB at a few phases (nearest grid phases)."""
        cols = _indices_of_nearest(self.phases_deg, phases_deg)
        dom = self.dominant()
        head = f"{'ω [rad/s]':>10}  {'status':<13} {'dominant':<18}" + "".join(
            f" {f'forbidden |L0| [dB] at {self.phases_deg[c]:g}°':<30}" for c in cols)
        lines = [head, "-" * len(head)]
        empty, nonc = self.empty, self.non_connected
        for i, w in enumerate(self.omegas):
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


def intersect(*bounds_list) -> Bounds:
    """Intersection of several :class:`Bounds` (same phase grid): all their specs at once.

    Design frequencies are united; a spec constrains only its own frequencies.
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
    omegas = np.unique(np.concatenate([p.omegas for p in parts]))
    lo_all, hi_all = [], []
    for part in parts:
        rows = _indices_of(omegas, part.omegas, "omegas")
        k = part.forbidden_db.shape[2]
        lo = np.full((len(omegas), len(phases), k), np.inf)
        hi = np.full((len(omegas), len(phases), k), -np.inf)
        lo[rows] = np.nan_to_num(part.forbidden_db[..., 0], nan=np.inf, posinf=np.inf, neginf=-np.inf)
        hi[rows] = np.nan_to_num(part.forbidden_db[..., 1], nan=-np.inf, posinf=np.inf, neginf=-np.inf)
        lo_all.append(lo)
        hi_all.append(hi)
    lo, hi = _merge(np.concatenate(lo_all, -1), np.concatenate(hi_all, -1))
    return Bounds(omegas, phases, np.stack([lo, hi], -1), parts)


def as_specs(specs) -> list:
    """A Bounds (its specs), one Spec, or an iterable of Spec → non-empty list of Spec."""
    if isinstance(specs, Bounds):
        specs = list(specs.specs)
    elif isinstance(specs, Spec):
        specs = [specs]
    else:
        specs = list(specs)
    if not specs or not all(isinstance(sp, Spec) for sp in specs):
        raise TypeError("specs must be a Bounds, a Spec or a non-empty list of Spec")
    return specs
