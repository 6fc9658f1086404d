"""Input validation shared by every module: checks at the door that name the argument.

Each function returns the validated array (float64, C-contiguous) or raises a ValueError /
TypeError whose message names the argument and says how to fix it.
"""
from __future__ import annotations

import warnings

import numpy as np

__all__ = ["as_omega", "as_psd", "as_signal", "as_real", "real_scalar", "positive_scalar", "del_target",
           "distinct_keys", "bisection_tolerance", "MAX_BISECTIONS", "finite_system", "spec_made_at",
           "bad_measurements", "margin_db", "search_options"]

#: Most halvings of a bisection: 100 halve any interval a search starts from (≤ 1e3 dB or m/s)
#: below 1e-27, far under any tolerance a user asks for, so a tolerance float64 cannot resolve
#: (1e-300 dB next to 3 dB) still ends.
MAX_BISECTIONS = 100


def as_real(x, name: str) -> np.ndarray:
    """``x`` (argument ``name``, any unit) as a float64 array; complex or non-numeric input is a TypeError.

    Taking the real part silently would drop the imaginary part of, e.g., a frequency response
    passed where |T|² belongs.
    """
    a = np.asarray(x)
    if np.iscomplexobj(a):
        raise TypeError(f"{name} is complex; pass real values (e.g. np.abs(T)**2 for a squared magnitude, "
                        f"or np.real(...) if the imaginary part is meant to be dropped)")
    try:
        return np.asarray(a, dtype=float)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be an array of real numbers, got {a.dtype}") from None


def as_omega(omega, name: str = "omega", *, allow_zero: bool = True) -> np.ndarray:
    """Validate a frequency grid in rad/s: 1-D, finite, strictly increasing, non-negative."""
    w = as_real(omega, name)
    if w.ndim != 1:
        raise ValueError(f"{name} must be a 1-D grid of frequencies in rad/s, got shape {w.shape}")
    if w.size < 2:
        raise ValueError(f"{name} needs at least 2 frequencies, got {w.size}")
    if not np.all(np.isfinite(w)):
        raise ValueError(f"{name} contains NaN or inf; pass finite frequencies in rad/s")
    if np.any(np.diff(w) <= 0):
        i = int(np.argmax(np.diff(w) <= 0))
        raise ValueError(
            f"{name} must be strictly increasing (rad/s); {name}[{i}]={w[i]!r} >= {name}[{i + 1}]={w[i + 1]!r}. "
            "Sort it (np.sort) and remove duplicates (np.unique)."
        )
    if w[0] < 0 or (not allow_zero and w[0] == 0):
        raise ValueError(f"{name} must be {'non-negative' if allow_zero else 'positive'} (one-sided, rad/s), got {name}[0]={w[0]!r}")
    return np.ascontiguousarray(w)


def as_psd(psd, n: int, name: str = "psd") -> np.ndarray:
    """Validate a one-sided PSD stack (load units² per rad/s) of shape (..., n): finite, non-negative."""
    s = as_real(psd, name)
    if s.ndim == 0 or s.shape[-1] != n:
        raise ValueError(f"{name} must have shape (..., {n}) to match the frequency grid, got {s.shape}")
    if not np.all(np.isfinite(s)):
        raise ValueError(f"{name} contains NaN or inf values")
    if np.any(s < 0):
        idx = np.unravel_index(int(np.argmin(s)), s.shape)
        raise ValueError(f"{name} must be non-negative (a one-sided PSD); {name}{list(idx)}={s[idx]!r}")
    return np.ascontiguousarray(s)


def as_signal(x, name: str = "x", *, min_samples: int = 2) -> np.ndarray:
    """Validate a 1-D, finite time series (load units) of at least ``min_samples`` samples."""
    a = as_real(x, name)
    if a.ndim != 1:
        raise ValueError(f"{name} must be a 1-D time series, got shape {a.shape}")
    if a.size < min_samples:
        raise ValueError(f"{name} needs at least {min_samples} samples, got {a.size}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} contains NaN or inf; remove or interpolate them first")
    return np.ascontiguousarray(a)


def real_scalar(value, name: str) -> float:
    """A finite real scalar (in the unit of argument ``name``) as a float.

    A bool, a string or bytes is a TypeError (``float`` would read True as 1 and "0.01" as
    0.01); NaN or inf a ValueError.
    """
    if np.iscomplexobj(value):
        raise TypeError(f"{name} is complex; pass a real number")
    if isinstance(value, (bool, np.bool_, str, bytes)):
        raise TypeError(f"{name} must be a real number, got {type(value).__name__} {value!r}")
    if np.ndim(value) != 0:
        raise TypeError(f"{name} must be a single real number, got an array of shape {np.shape(value)}")
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be a real number, got {type(value).__name__}") from None
    if not np.isfinite(v):
        raise ValueError(f"{name}={value!r} must be finite")
    return v


def bisection_tolerance(value, name: str = "tolerance_db") -> float:
    """A bisection's tolerance (in the unit of argument ``name``): finite and > 0, else the
    bisection would never end (0 or a negative width is never reached)."""
    v = real_scalar(value, name)
    if v <= 0:
        raise ValueError(f"{name}={value!r} must be > 0: a bisection to a width ≤ 0 never ends (e.g. 0.05)")
    return v


def margin_db(value, name: str) -> float:
    """A margin or slack (dB, argument ``name``): a finite real number ≥ 0."""
    v = real_scalar(value, name)
    if v < 0:
        raise ValueError(f"{name}={value!r} must be a finite margin ≥ 0 dB")
    return v


def search_options(tolerance_db, max_relax_db, speed_relax_db=None):
    """A certificate search's (tolerance dB, largest relaxation dB, fixed relaxation dB or None),
    checked: a tolerance ≤ 0 would never end its bisection, a relaxation is ≥ 0 dB."""
    tol = bisection_tolerance(tolerance_db, "tolerance_db")
    top = real_scalar(max_relax_db, "max_relax_db")
    if top < 0:
        raise ValueError(f"max_relax_db={max_relax_db!r} must be a relaxation ≥ 0 dB (e.g. 12)")
    g = None if speed_relax_db is None else real_scalar(speed_relax_db, "speed_relax_db")
    if g is not None and g < 0:
        raise ValueError(f"speed_relax_db={speed_relax_db!r} must be a relaxation ≥ 0 dB, or None to search it")
    return tol, top, g


def positive_scalar(value, name: str) -> float:
    """Validate a finite, strictly positive real scalar (in the unit of argument ``name``) and return it as a float."""
    if np.iscomplexobj(value):
        raise TypeError(f"{name} is complex; pass a real number")
    if isinstance(value, (bool, np.bool_, str, bytes)):  # float() would take True as 1 and "0.01" as 0.01
        raise TypeError(f"{name} must be a real number, got {type(value).__name__} {value!r}")
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be a real number, got {type(value).__name__}") from None
    if not np.isfinite(v) or v <= 0:
        raise ValueError(f"{name}={value!r} must be finite and > 0")
    return v


def del_target(value, name: str = "target_reduction") -> float:
    """Validate a DEL-reduction target in % (0 < value < 100) and return it as a float.

    A bool or a string is a TypeError (True would read as a 1 % target).
    """
    t = real_scalar(value, name)
    if not 0 < t < 100:
        raise ValueError(f"{name}={value!r} must be a DEL reduction in % strictly between 0 and 100")
    return t


def representable(value, positive, what: str, hint: str) -> np.ndarray:
    """Return ``value`` (a damage, any unit) unchanged if float64 holds it, else raise OverflowError naming ``what``.

    Held means finite, and a normal number (>= ~2.2e-308 in magnitude) wherever ``positive``
    (a bool array, or a bool) says the true value is nonzero.

    The error names ``what`` (e.g. "damage_rate(m=50)") and adds ``hint``: a damage ∝ load^m
    leaves float64's range both ways at a large Wöhler exponent, and an inf or a 0 in its
    place would only turn up later as a silently wrong ratio or DEL.
    """
    v = np.asarray(value)
    mag = np.abs(v)
    bad_over = ~np.isfinite(mag)
    bad_under = np.asarray(positive, dtype=bool) & (mag < np.finfo(float).tiny)
    if np.any(bad_over):
        raise OverflowError(f"{what} exceeds float64's range (~1.8e308); {hint}")
    if np.any(bad_under):
        raise OverflowError(f"{what} underflows float64's range (a nonzero value below ~2.2e-308); {hint}")
    return v


def distinct_keys(make_error=None):
    """A ``json.loads`` object_pairs_hook that refuses a repeated key (json keeps the last silently).

    Parameters
    ----------
    make_error : callable, optional
        key → the exception to raise (default ``ValueError("key 'k' appears twice")``).

    Returns
    -------
    callable
        The hook.
    """
    def pairs(items):
        out = {}
        for k, v in items:
            if k in out:
                raise make_error(k) if make_error is not None else ValueError(f"key {k!r} appears twice")
            out[k] = v
        return out

    return pairs


def finite_system(sys, name: str) -> None:
    """Raise ValueError if the state-space matrices of ``sys`` (argument ``name``) hold NaN or inf.

    A NaN plant otherwise reaches LAPACK or SLICOT, whose "SVD did not converge" names nothing.
    Transfer functions are checked on their coefficients.
    """
    parts = [(k, getattr(sys, k, None)) for k in ("A", "B", "C", "D")]
    if all(m is None for _, m in parts):
        parts = [("num", np.concatenate([np.ravel(c) for row in sys.num for c in row])),
                 ("den", np.concatenate([np.ravel(c) for row in sys.den for c in row]))]
    for key, m in parts:
        a = np.asarray(m, dtype=complex)
        if a.size and not np.all(np.isfinite(a)):
            i = [int(j) for j in np.unravel_index(int(np.argmin(np.isfinite(a))), a.shape)]
            raise ValueError(f"{name} has a NaN or inf entry ({key}{i} = {float(a[tuple(i)].real)!r}); check the model or "
                             "the operating point it was linearised at")


def spec_made_at(spec, wind_speed: float, name: str = "spec") -> None:
    """Refuse a specification record made at another operating point than the design's.

    A specification (a :class:`specdesign.feasibility.TargetSpecification`, a
    :class:`specdesign.spec.DesignSpecifications`, a design record) carries the wind speed it
    was made and certified at (``wind_speed``, or ``base.wind_speed``) and its plant cases
    (``case_speeds``); its promise and its certificate hold there only. Records that carry no
    wind speed (a bare pair of transfer functions) pass.

    Parameters
    ----------
    spec : object
        The record.
    wind_speed : float
        The design's operating point, m/s.
    name : str
        The argument's name, for the message.

    Raises
    ------
    ValueError
        Naming both wind speeds, the plant cases and the fix.
    """
    made = getattr(spec, "wind_speed", None)
    if made is None and hasattr(spec, "base"):
        made = getattr(spec.base, "wind_speed", None)
    try:
        made = float(made)
    except (TypeError, ValueError):
        return
    if not np.isfinite(made) or made == float(wind_speed):
        return
    cases = tuple(float(c) for c in getattr(spec, "case_speeds", ()) or ())
    certified = f" and certified on the plant cases {cases} m/s" if cases else ""
    raise ValueError(f"{name} was made at {made:g} m/s{certified}, not at wind_speed={float(wind_speed):g} m/s: its "
                     f"promise holds there only; make one at {float(wind_speed):g} m/s (e.g. "
                     f"feasibility.specification_for_target(model, {float(wind_speed):g}, target)) or design at "
                     f"{made:g} m/s")


def bad_measurements(y, names, t: float, warned: set, who: str) -> np.ndarray:
    """The runs whose measurements ``names`` hold NaN or inf at time ``t``: the controllers'
    common convention for a bad sample.

    Every controller of the simulator's callable contract (:class:`specdesign.mpc.SampledController`
    and its subclasses, :class:`specdesign.mpc.HealthMPC`, :class:`specdesign.rosco.Discon`)
    treats such a run alike: it holds its last command, leaves its state (estimator,
    filters, counters) as it was, and resumes at the next finite sample; a RuntimeWarning
    names the signal, the time and the run, once per signal and run start (``warned``).

    Parameters
    ----------
    y : dict
        Output name → (R,) measurements (SI).
    names : sequence of str
        The measurements the controller reads.
    t : float
        Time (s), for the message.
    warned : set
        Signals already warned about since the controller's start (updated).
    who : str
        The controller's name, for the message.

    Returns
    -------
    numpy.ndarray
        (R,) bool, True where a run's sample is not finite.
    """
    bad = None
    for n in names:
        v = np.asarray(y[n], dtype=float)
        b = ~np.isfinite(v)
        bad = b if bad is None else bad | b
        if b.any() and n not in warned:
            warned.add(n)
            r = int(np.flatnonzero(b)[0])
            warnings.warn(f"{who}: measurement {n!r} = {float(np.ravel(v)[r])!r} at t = {t:g} s (run {r}): the run "
                          f"holds its last command until {n} is finite again (said once per signal)", RuntimeWarning,
                          stacklevel=3)
    return bad
