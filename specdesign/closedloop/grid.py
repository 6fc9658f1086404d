"""Frequency grids that cannot step over a narrow resonance or dip of a lightly damped loop."""
from __future__ import annotations

from collections.abc import Iterable
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

if TYPE_CHECKING:
    import control

__all__ = ["CASE_TOLERANCE", "FREQUENCY_RTOL", "case_speeds", "lightly_damped", "merge_frequencies", "refine_grid",
           "system_roots"]

#: Plant cases closer than this (m/s) to another one are the same operating point.
CASE_TOLERANCE = 1e-6
#: Frequencies closer than this, relative, are one grid point: the same root computed twice (the
#: tower mode as a pole of the wind → speed and of the wind → tower-load map) differs by round-off
#: (≈ 1e-12 relative), and a grid that keeps both copies or one by that round-off is a different
#: problem for a tuner whose constraints are one per grid point.
FREQUENCY_RTOL = 1e-8


def merge_frequencies(*grids: ArrayLike, rtol: float = FREQUENCY_RTOL) -> np.ndarray:
    """The union of frequency grids (rad/s), with points closer than ``rtol`` relative merged.

    Sorted, then every run of points whose neighbours are within ``rtol``·ω of each other is
    kept as its smallest point, which moves continuously with the data (``np.unique`` would keep
    copies that differ by round-off and merge those that happen to be equal).

    Parameters
    ----------
    *grids : array_like
        Frequencies, rad/s (any order, positive).
    rtol : float
        Relative distance (-) under which two neighbouring points are one.

    Returns
    -------
    numpy.ndarray
        Increasing frequencies, rad/s.

    Raises
    ------
    ValueError
        If a frequency is not finite and positive, or ``rtol`` is not in [0, 1e-3].

    Examples
    --------
    >>> from specdesign.closedloop import merge_frequencies
    >>> merge_frequencies([1.0, 2.0], [1.0 + 1e-13, 3.0])
    array([1., 2., 3.])
    """
    if not 0 <= rtol <= 1e-3:
        raise ValueError(f"rtol={rtol!r} must be in [0, 1e-3] (a relative distance under which frequencies are one)")
    w = np.sort(np.concatenate([np.atleast_1d(np.asarray(g, float)).reshape(-1) for g in grids]) if grids else np.zeros(0))
    if w.size and not (np.all(np.isfinite(w)) and w[0] > 0):
        raise ValueError("grids must hold finite positive frequencies in rad/s")
    if w.size < 2:
        return w
    new_run = np.r_[True, np.diff(w) > rtol * w[1:]]
    return w[new_run]


def system_roots(sys: control.LTI) -> np.ndarray:
    """Poles and zeros of a SISO LTI (or of every channel of a MIMO one).

    Parameters
    ----------
    sys : control.LTI
        Continuous-time system (any units: only its roots matter).

    Returns
    -------
    numpy.ndarray
        Complex roots, 1/s (rad/s): the poles, then the zeros of each channel that has states.
        A channel's zeros come from its transfer function, so zeros at infinity of a
        non-minimal channel may show up as very large finite roots.

    Examples
    --------
    >>> import control
    >>> from specdesign.closedloop import system_roots
    >>> system_roots(control.tf([1.0], [1.0, 0.02, 1.0]))   # ζ = 0.01 at 1 rad/s
    array([-0.01+0.99995j, -0.01-0.99995j])
    """
    import control

    sys = control.ss(sys)
    out = [np.asarray(sys.poles(), dtype=complex)]
    for i in range(sys.noutputs):
        for j in range(sys.ninputs):
            sub = sys[i, j]
            if sub.nstates:
                out.append(np.asarray(control.tf(sub).zeros(), dtype=complex))
    return np.concatenate(out) if out else np.zeros(0, complex)


def lightly_damped(roots: ArrayLike, zeta_max: float = 0.3) -> np.ndarray:
    """Select the complex roots whose resonance or dip is narrow.

    A root p (either half-plane, either sign of Re) is selected when its damping ratio
    ζ = −Re p/|p| < ``zeta_max``.

    Parameters
    ----------
    roots : array_like of complex
        Poles and/or zeros, 1/s (rad/s); non-finite values and roots at 0 are ignored.
    zeta_max : float
        Damping-ratio threshold (-).

    Returns
    -------
    numpy.ndarray
        The selected roots (complex, 1/s), in the order given; real roots are never selected.

    Examples
    --------
    >>> from specdesign.closedloop import lightly_damped
    >>> lightly_damped([-0.01 + 1j, -0.01 - 1j, -1 + 1j, -2.0])   # ζ = 0.01, 0.71, 1
    array([-0.01+1.j, -0.01-1.j])
    """
    p = np.atleast_1d(np.asarray(roots, complex)).reshape(-1)
    p = p[np.isfinite(p) & (np.abs(p) > 0)]
    return p[(np.abs(p.imag) > 0) & (-p.real < zeta_max * np.abs(p))]


def refine_grid(omega: ArrayLike, roots: ArrayLike | control.LTI | Iterable = (), *, zeta_max: float = 0.3,
                rel_width: float = 0.05, rel_step: float = 1e-4, points_per_width: float | None = None) -> np.ndarray:
    """Refine a frequency grid (rad/s) so that it cannot step over a narrow resonance or dip.

    ``omega`` refined around every lightly damped root: for each pole or zero p of
    ``roots`` with damping ratio ζ = −Re p/|p| < ``zeta_max`` (either sign, so unstable and
    right-half-plane roots count too) and |Im p| inside [omega[0], omega[-1]], the grid gets
    |Im p| and |p| exactly and geometric points with relative spacing ``rel_step`` over
    |Im p|·(1 ± ``rel_width``). A second-order peak of damping ζ has a relative half-power
    width 2ζ, so with the defaults every peak with ζ ≳ 5·10⁻⁵ gets ≥ 1 point inside its
    half-power band, and the exact |Im p| points bound the rest.

    Parameters
    ----------
    omega : array_like
        Base grid, rad/s, increasing and positive (at least 2 points).
    roots : array_like of complex, control.LTI, or iterable of arrays / LTI systems
        Poles and zeros to refine around, 1/s; LTI systems contribute their poles and the zeros
        of each channel (:func:`system_roots`).
    zeta_max : float
        Damping-ratio threshold (-): roots with ζ < ``zeta_max`` are refined around.
    rel_width : float
        Half-width of the refined band, relative to |Im p| (-).
    rel_step : float
        Relative spacing of the refined points (-).
    points_per_width : float, optional
        With it, the spacing at a root of damping ζ is the larger of ``rel_step`` and
        2ζ/``points_per_width``: that many points across its half-power band, and no more
        (a certificate's loop has a dozen roots with ζ ≈ 0.2, each of which gets 1000 points
        at ``rel_step``). Default: ``rel_step`` at every root.

    Returns
    -------
    numpy.ndarray
        Sorted unique grid in rad/s containing ``omega``, within [omega[0], omega[-1]].

    Raises
    ------
    ValueError
        If ``omega`` is not an increasing grid of at least 2 positive frequencies, or
        ``zeta_max``, ``rel_width`` or ``rel_step`` is not a positive finite number.

    Examples
    --------
    A resonance of damping ζ = 0.01 at 1 rad/s falls between the points of a coarse grid;
    the refined grid has |Im p| itself and about 1000 points within ±5 % of it:

    >>> import control
    >>> import numpy as np
    >>> from specdesign.closedloop import refine_grid
    >>> omega = np.logspace(-1, 1, 21)
    >>> grid = refine_grid(omega, control.tf([1.0], [1.0, 0.02, 1.0]))
    >>> bool(np.isin(omega, grid).all()), bool(np.isclose(grid, 0.99995).any())
    (True, True)
    >>> int(np.sum((grid > 0.95) & (grid < 1.05)))
    1004
    """
    import control

    omega = np.asarray(omega, dtype=float).reshape(-1)
    if omega.size < 2 or np.any(omega <= 0) or np.any(np.diff(omega) <= 0):
        raise ValueError("omega must be an increasing grid of positive frequencies in rad/s")
    for k, v in (("zeta_max", zeta_max), ("rel_width", rel_width), ("rel_step", rel_step),
                 ("points_per_width", 1.0 if points_per_width is None else points_per_width)):
        if not (np.isfinite(v) and v > 0):
            raise ValueError(f"{k}={v!r} must be positive")
    if isinstance(roots, control.LTI):
        roots = [roots]
    parts = []
    for r in ([roots] if isinstance(roots, np.ndarray) else roots):
        parts.append(system_roots(r) if isinstance(r, control.LTI) else np.atleast_1d(np.asarray(r, complex)))
    p = np.concatenate(parts) if parts else np.zeros(0, complex)
    light = lightly_damped(p, zeta_max)
    lo, hi = omega[0], omega[-1]
    extra = []
    span = np.log((1 + rel_width) / (1 - rel_width))
    # each distinct |Im p| once, with its least damping (the narrowest feature there)
    w_im, zeta = np.round(np.abs(light.imag), 12), -light.real / np.abs(light)
    for w0 in np.unique(w_im):
        if not lo <= w0 <= hi:
            continue
        step = rel_step
        if points_per_width is not None:
            step = max(rel_step, 2 * float(np.min(np.abs(zeta[w_im == w0]))) / points_per_width)
        n = int(np.ceil(span / np.log1p(step))) + 1
        extra.append(np.geomspace(w0 * (1 - rel_width), w0 * (1 + rel_width), n))
        extra.append([w0])
    extra.append(np.abs(light))
    grid = np.unique(np.concatenate([omega] + [np.asarray(e, float) for e in extra]))
    return grid[(grid >= lo) & (grid <= hi)]


def case_speeds(wind_speed: float, offsets: ArrayLike, wind_range: tuple[float, float], *,
                name: str = "offsets") -> tuple[tuple[float, ...], int]:
    """The plant cases around an operating point: ``wind_speed`` + ``offsets`` clipped to ``wind_range``.

    A case that clips onto another, or onto the nominal speed, to within :data:`CASE_TOLERANCE`
    m/s is the same operating point and is listed once, so a design at 25 − 1e-9 m/s on a
    model valid up to 25 m/s checks the cases a design at 25 m/s checks (no 25.0 m/s case
    beside the nominal 24.999999999 m/s one).

    Parameters
    ----------
    wind_speed : float
        Nominal operating point, m/s (inside ``wind_range``).
    offsets : array_like
        Wind-speed offsets of the neighbouring cases, m/s (finite, 1-D; 0 and repeats allowed).
    wind_range : (float, float)
        The model's valid wind speeds, m/s.
    name : str
        The caller's name for ``offsets``, in the error message.

    Returns
    -------
    speeds : tuple of float
        The case wind speeds, increasing, m/s; the nominal one is ``wind_speed`` exactly.
    nominal : int
        Index of ``wind_speed`` in ``speeds``.

    Raises
    ------
    ValueError
        If ``offsets`` is not a 1-D array of finite numbers (the message names it ``name``).

    Examples
    --------
    >>> from specdesign.closedloop import case_speeds
    >>> case_speeds(24.999999999, (-1.0, -0.5, 0.5, 1.0), (10.6, 25.0))
    ((23.999999999, 24.499999999, 24.999999999), 2)
    """
    v = float(wind_speed)
    o = np.atleast_1d(np.asarray(offsets, float))
    if o.ndim != 1 or not np.all(np.isfinite(o)):
        raise ValueError(f"{name}={offsets!r} must be a 1-D array of finite wind-speed offsets in m/s")
    lo, hi = wind_range
    speeds = [v]
    for s in sorted(float(np.clip(v + x, lo, hi)) for x in o):
        if all(abs(s - t) > CASE_TOLERANCE for t in speeds):
            speeds.append(s)
    speeds.sort()
    return tuple(speeds), speeds.index(v)
