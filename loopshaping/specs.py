"""QFT specifications: |(A + B·G)/(C + D·G)| ≤ W per plant case, by kind name.

Every specification is written in the general form |(A + B·G)/(C + D·G)| ≤ W per case; the
classic kinds (:data:`KINDS`) only choose A, B, C, D from the plant P. :class:`Spec` holds
one specification (kind, weight, band, name, kind arguments) and evaluates its weight and
coefficients at any frequencies; :func:`loopshaping.bounds.as_specs` normalises "a Bounds, a Spec or a list of
Spec" arguments.

Frequencies in rad/s; weights are linear magnitudes (not dB).
"""
from __future__ import annotations

import numbers
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from .freqresp import evaluate, is_lti

__all__ = ["KINDS", "Spec", "controller_gain"]

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

@dataclass(frozen=True, eq=False)
class Spec:
    """One specification |(A + B·G)/(C + D·G)| ≤ W, by kind name (see :data:`KINDS`).

    Numbers, arrays, real values a callable returns and static LTIs are linear magnitudes and
    must be > 0 (a negative one is an error, not silently |·|: it is likely dB); no form may
    be 0 at a design frequency (|T| ≤ 0 cannot be met).

    Parameters
    ----------
    kind : str
        One of :data:`KINDS`.
    weight : float or array_like or control LTI or callable, optional
        The bound W, linear magnitude (not dB): a number, an array (one value per design
        frequency, or (n_omega, n_cases)), a SISO LTI (|W(jω)| is used) or a callable
        ``fn(omega)`` (ω in rad/s); np.inf means "no constraint". Required except for
        ``tracking`` given ``upper``/``lower``.
    band : tuple of float, optional
        ``(low, high)`` in rad/s: the spec applies only there.
    name : str, optional
        Name in tables and reports; default the kind.
    kind_args : dict
        ``sensor`` (noise: the sensor dynamics H), ``upper``/``lower`` (tracking: the weight
        is then the ratio |upper|/|lower|, or give ``weight`` = the ratio), ``A``, ``B``,
        ``C``, ``D`` (general: each a number, an (n_omega, n_cases) array at the design
        frequencies, a callable ``fn(omega) -> (n_omega, n_cases)``, an LTI, or a list of one
        LTI per case).

    Raises
    ------
    ValueError
        For an unknown kind or a bad band; weights are checked when evaluated (a wrong
        value is a ValueError, a wrong form a TypeError, each naming the argument).
    TypeError
        For missing or unknown kind arguments, or a missing weight.

    Examples
    --------
    >>> Spec("sensitivity", 2.0, band=(0, 10)).in_band([1.0, 20.0])
    array([ True, False])
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

    def in_band(self, omega: ArrayLike) -> np.ndarray:
        """Where the spec applies.

        Parameters
        ----------
        omega : array_like
            Frequencies, rad/s.

        Returns
        -------
        numpy.ndarray
            Bool, shape of ``omega``: inside ``band`` (everywhere without one).
        """
        omega = np.asarray(omega, float)
        if self.band is None:
            return np.ones(omega.shape, bool)
        return (omega >= self.band[0]) & (omega <= self.band[1])

    def weights(self, omega: ArrayLike, n_cases: int, design: ArrayLike | None = None) -> np.ndarray:
        """|W| at ``omega``; for tracking, the allowed ratio.

        Parameters
        ----------
        omega : array_like
            Frequencies, rad/s.
        n_cases : int
            Number of plant cases (columns of the result).
        design : array_like, optional
            The design frequencies, when ``omega`` are them (arrays given per design
            frequency are only valid there).

        Returns
        -------
        numpy.ndarray
            Linear magnitudes, (n_omega, n_cases).

        Raises
        ------
        ValueError
            For a weight ≤ 0, 0 at some frequency or NaN.
        TypeError
            For a weight of the wrong form.
        """
        if self.kind == "tracking" and self.weight is None:
            up = self._magnitude(self.kind_args["upper"], omega, 1, "upper", design)
            low = self._magnitude(self.kind_args["lower"], omega, 1, "lower", design)
            with np.errstate(divide="ignore"):
                w = up / low
        else:
            w = self._magnitude(self.weight, omega, n_cases, "weight", design)
        w = np.broadcast_to(w, (len(omega), w.shape[1] if w.shape[1] != 1 else n_cases)).copy()
        if np.any(np.isnan(w)):
            raise ValueError(f"weight of spec {self.name!r} is NaN at some frequency (np.inf for no constraint)")
        return w

    def _magnitude(self, obj, omega, n_cases, what, design):
        """|obj| at ``omega``; numbers, arrays and callables returning real values must be
        > 0 (a linear magnitude: not dB, and taking |·| of a negative one silently would hide
        the mistake), and no magnitude may be 0 (|T| ≤ 0 is a bound no controller meets)."""
        raw = obj(np.asarray(omega, float)) if callable(obj) and not is_lti(obj) else obj
        ltis = [raw] if is_lti(raw) else list(raw) if isinstance(raw, (list, tuple)) and raw and all(
            is_lti(o) for o in raw) else None
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
        w = np.abs(self._value(obj, omega, n_cases, what, design)).astype(float)
        if np.any(w == 0):
            i = int(np.argmax(np.any(w == 0, axis=1)))
            raise ValueError(f"{what} of spec {self.name!r} is 0 at ω = {np.asarray(omega, float)[i]:g} rad/s "
                             "(|T| ≤ 0 cannot be met; a zero of the weighting function on the jω axis?)")
        return w

    def coefficients(self, omega: ArrayLike, plants: np.ndarray, design: ArrayLike | None = None) -> tuple:
        """General-form coefficients A, B, C, D at ``omega`` for the plant responses ``plants``.

        Parameters
        ----------
        omega : array_like
            Frequencies, rad/s.
        plants : numpy.ndarray
            Plant responses, (n_omega, n_cases) complex.
        design : array_like, optional
            The design frequencies, when ``omega`` are them (arrays given per design
            frequency are only valid there).

        Returns
        -------
        tuple of numpy.ndarray
            ``(A, B, C, D)``, each (n_omega, n_cases) complex.

        Raises
        ------
        ValueError
            For ``tracking`` (see :func:`~loopshaping.templates.tracking_pairs`) or
            general-form coefficients that disagree on the number of cases.
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
            H = self._value(self.kind_args.get("sensor", 1.0), omega, 1, "sensor", design)
            H = np.broadcast_to(H, P.shape)
            return zero, H, one, P * H
        if k == "general":
            out = []
            for key in "ABCD":
                v = self._value(self.kind_args[key], omega, None, key, design)
                out.append(v)
            n = max(v.shape[1] for v in out)
            for i, v in enumerate(out):
                if v.shape[1] not in (1, n):
                    raise ValueError(f"A, B, C, D of spec {self.name!r} disagree on the number of cases")
                out[i] = np.broadcast_to(v, (len(omega), n))
            return tuple(out)
        raise ValueError("tracking has no single-case coefficients; see tracking_pairs")

    def _value(self, obj, omega, n_cases, what, design):
        omega = np.asarray(omega, float)
        if isinstance(obj, (list, tuple)) and obj and all(is_lti(o) for o in obj):
            return np.stack([evaluate(o, omega, f"{what}[{i}]") for i, o in enumerate(obj)], axis=1)
        if isinstance(obj, numbers.Number) or is_lti(obj) or callable(obj):
            v = evaluate(obj, omega, what)
            return v[:, None] if v.ndim == 1 else v
        arr = np.asarray(obj)
        if arr.ndim == 0:
            return np.full((len(omega), 1), arr.item())
        if design is None or len(design) != len(omega) or not np.allclose(design, omega):
            raise ValueError(f"{what} of spec {self.name!r} is an array given at the design frequencies; "
                             "to evaluate it elsewhere (dense check) give an LTI or a callable of ω")
        if arr.ndim > 2 or arr.shape[0] != len(omega):
            raise ValueError(f"{what} of spec {self.name!r} must have one value (or row) per design frequency "
                             f"({len(omega)}); got shape {arr.shape}")
        return arr.reshape(len(omega), -1) if arr.ndim == 1 else arr


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


def controller_gain(bound, band: tuple | None = None, name: str = "controller_gain") -> Spec:
    """The specification |G(jω)| ≤ bound(ω) on a band: a bound on the controller's own gain.

    The general form with A = 0, B = 1, C = 1, D = 0: the same for every plant case, so a
    dense check (:func:`loopshaping.check.check`) reports it beside the loop's specifications.

    Parameters
    ----------
    bound : float or array_like or control LTI or callable
        The allowed |G|, linear magnitude (as :class:`Spec`'s ``weight``; np.inf: no constraint).
    band : tuple of float, optional
        ``(low, high)`` in rad/s where it applies (everywhere without one).
    name : str
        Name in tables and reports.

    Returns
    -------
    Spec
        The specification.

    Examples
    --------
    >>> import control as ct
    >>> from loopshaping.check import check
    >>> g, w = ct.tf([10], [1, 1]), [0.5, 1.0, 3.0, 10.0]          # |G| = 8.9, 7.1, 3.2, 1.0
    >>> check([ct.tf([1], [1, 1])], g, controller_gain(5.0, band=(2.0, 10.0)), w).passed
    True
    >>> check([ct.tf([1], [1, 1])], g, controller_gain(5.0, band=(1.0, 10.0)), w).passed
    False
    """
    return Spec("general", bound, band=band, name=name, kind_args={"A": 0.0, "B": 1.0, "C": 1.0, "D": 0.0})
