"""QFT templates: the plant cases' frequency responses at the design frequencies.

A *template* holds the frequency responses of the plant cases at the design frequencies,
shape (n_omega, n_cases), with one nominal case P0, and optionally a disk of unstructured
multiplicative uncertainty around every case. :func:`tracking_pairs` turns the cases into
the general-form coefficients of the tracking specification |T_i|/|T_j| ≤ δ.

Frequencies in rad/s.
"""
from __future__ import annotations

import itertools
import numbers
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from .freqresp import check_grid, evaluate, grid_indices

__all__ = ["Template", "tracking_pairs"]


@dataclass(frozen=True, eq=False)
class Template:
    """Plant cases at the design frequencies (build it with the ``from_*`` constructors).

    Parameters
    ----------
    omega : array_like
        (n_omega,) design frequencies, rad/s, strictly increasing.
    responses : array_like
        (n_omega, n_cases) complex frequency responses P_i(jω) (a 1-D array: one case).
    nominal : int
        Index of the nominal case P0 (negative counts from the end).
    disk_radius : array_like or float, optional
        (n_omega,) radius r(ω) ≥ 0 (relative) of an unstructured multiplicative uncertainty
        P_i·(1 + Δ), |Δ| ≤ r, around every case, or None.
    systems : tuple of control LTI, optional
        The LTI models of the cases when known (needed by the dense check).
    parameters : numpy.ndarray, optional
        (n_cases, n_params) parameter values of each case when gridded.
    parameter_names : tuple of str
        Names of the columns of ``parameters``.

    Raises
    ------
    ValueError
        For a bad grid, responses of the wrong shape or non-finite, a nominal case that is
        not an index or is zero at a design frequency, a negative disk radius.

    Examples
    --------
    >>> import control as ct
    >>> T = Template.from_systems([ct.tf([1], [1, 1]), ct.tf([2], [1, 1])], [0.1, 1.0])
    >>> T.responses.shape, T.n_cases
    ((2, 2), 2)
    """

    omega: np.ndarray
    responses: np.ndarray
    nominal: int = 0
    disk_radius: np.ndarray | None = None
    systems: tuple | None = None
    parameters: np.ndarray | None = None
    parameter_names: tuple = ()

    def __post_init__(self):
        w = check_grid(self.omega)
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
        for name, value in (("omega", w), ("responses", r), ("nominal", nominal), ("disk_radius", disk)):
            object.__setattr__(self, name, value)
        if self.systems is not None:
            object.__setattr__(self, "systems", tuple(self.systems))

    @property
    def n_cases(self) -> int:
        """Number of plant cases."""
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

        Parameters
        ----------
        n_disk : int
            Points on each disk's boundary circle.

        Returns
        -------
        numpy.ndarray
            Complex, (n_omega, n_cases·(1 + n_disk)), or ``responses`` without a disk.
        """
        if self.disk_radius is None or not np.any(self.disk_radius > 0):
            return self.responses
        psi = np.exp(2j * np.pi * np.arange(n_disk) / n_disk)
        ring = self.responses[:, :, None] * (1 + self.disk_radius[:, None, None] * psi)
        return np.concatenate([self.responses, ring.reshape(len(self.omega), -1)], axis=1)

    def at(self, omega: ArrayLike) -> Template:
        """The template restricted to some of its design frequencies.

        Parameters
        ----------
        omega : array_like
            Design frequencies to keep, rad/s (each must be one of ``self.omega``).

        Returns
        -------
        Template
            The cases at those frequencies.

        Raises
        ------
        ValueError
            If a frequency is not a design frequency.
        """
        idx = grid_indices(self.omega, omega, "omega")
        disk = None if self.disk_radius is None else self.disk_radius[idx]
        return Template(self.omega[idx], self.responses[idx], self.nominal, disk, self.systems,
                        self.parameters, self.parameter_names)

    # -- constructors
    @classmethod
    def from_responses(cls, omega: ArrayLike, responses: ArrayLike, nominal: int = 0, disk_radius: ArrayLike | None = None) -> Template:
        """From frequency responses.

        Parameters
        ----------
        omega : array_like
            Design frequencies, rad/s, strictly increasing.
        responses : array_like
            Complex responses, (n_omega, n_cases).
        nominal : int
            Index of the nominal case.
        disk_radius : array_like or float, optional
            Relative radius of the multiplicative uncertainty disk per frequency.

        Returns
        -------
        Template
            Without ``systems`` (the dense check then needs the plant cases as LTI).
        """
        return cls(omega, responses, nominal, disk_radius)

    @classmethod
    def from_systems(cls, systems: Sequence, omega: ArrayLike, nominal: int = 0, disk_radius: ArrayLike | None = None) -> Template:
        """From SISO python-control LTI plant cases, evaluated at ``omega``.

        Parameters
        ----------
        systems : sequence of control LTI
            The plant cases (SISO, continuous time).
        omega : array_like
            Design frequencies, rad/s, strictly increasing.
        nominal : int
            Index of the nominal case.
        disk_radius : array_like or float, optional
            Relative radius of the multiplicative uncertainty disk per frequency.

        Returns
        -------
        Template
            With ``systems`` kept.

        Raises
        ------
        ValueError
            If ``systems`` is empty or a case is MIMO, discrete-time or has a pole at a
            design frequency.
        """
        systems = list(systems)
        if not systems:
            raise ValueError("systems is empty; give at least one plant case")
        w = check_grid(omega)
        resp = np.stack([evaluate(P, w, f"systems[{i}]") for i, P in enumerate(systems)], axis=1)
        return cls(w, resp, nominal, disk_radius, tuple(systems))

    @classmethod
    def from_parameter_grid(cls, fn: Callable, ranges: dict, omega: ArrayLike, n: int | dict = 10,
                            edges_only: bool = False, nominal: dict | None = None,
                            disk_radius: ArrayLike | None = None) -> Template:
        """Grid a parameter box: ``fn(**params) -> LTI``, ``ranges = {name: (low, high)}``.

        ``n`` points per parameter (an int or ``{name: n}``), linearly spaced. With
        ``edges_only`` only the points on the 1-D edges of the box are kept (at most one
        parameter strictly inside its range), which is where the template boundary of most
        parametric plants lies.

        Parameters
        ----------
        fn : callable
            ``fn(**params)`` returns the SISO LTI plant for one parameter point.
        ranges : dict
            ``{name: (low, high)}`` for every parameter.
        omega : array_like
            Design frequencies, rad/s, strictly increasing.
        n : int or dict
            Points per parameter, or ``{name: n}``.
        edges_only : bool
            Keep only the points on the edges of the box.
        nominal : dict, optional
            Parameter values of the nominal case (added as a case when not on the grid);
            None for the first grid point (all parameters at ``low``).
        disk_radius : array_like or float, optional
            Relative radius of the multiplicative uncertainty disk per frequency.

        Returns
        -------
        Template
            With ``parameters`` and ``parameter_names`` set.

        Raises
        ------
        ValueError
            For empty or reversed ranges, ``n`` < 1, or a nominal missing a parameter.
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
        t = cls.from_systems(systems, omega, nom_idx, disk_radius)
        return cls(t.omega, t.responses, nom_idx, t.disk_radius, t.systems, grid, names)

    @classmethod
    def from_operating_points(cls, systems: Sequence, omega: ArrayLike, nominal: int = 0, n_between: int = 0,
                              disk_radius: ArrayLike | None = None) -> Template:
        """From linear models at neighbouring operating points (ordered, e.g. by wind speed).

        ``n_between`` extra cases are inserted between consecutive points as convex
        combinations (1 − t)·P_k + t·P_{k+1}, the responses a scheduled plant passes through
        between the linearisations; the combinations are kept as LTI (parallel connections).

        Parameters
        ----------
        systems : sequence of control LTI
            The models at the operating points, in order.
        omega : array_like
            Design frequencies, rad/s, strictly increasing.
        nominal : int
            Index of the nominal case in ``systems`` (the original list).
        n_between : int
            Cases inserted between two neighbouring points, ≥ 0.
        disk_radius : array_like or float, optional
            Relative radius of the multiplicative uncertainty disk per frequency.

        Returns
        -------
        Template
            With the inserted cases.

        Raises
        ------
        ValueError
            If ``systems`` is empty or ``n_between`` < 0.
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
        return cls.from_systems(cases, omega, nom, disk_radius)


def _case_index(nominal, n_cases, name="nominal") -> int:
    """An integer case index (negative counts from the end); a float, a bool or a string is
    an error rather than a silently truncated index."""
    if isinstance(nominal, (bool, np.bool_)) or not isinstance(nominal, (numbers.Integral, np.integer)):
        raise ValueError(f"{name}={nominal!r} must be an integer index of a plant case (0..{n_cases - 1})")
    nominal = int(nominal)
    if not -n_cases <= nominal < n_cases:
        raise ValueError(f"{name}={nominal} is not a case index (n_cases={n_cases})")
    return nominal



def tracking_pairs(P: np.ndarray) -> tuple:
    """General-form coefficients of |T_i|/|T_j| ≤ δ over the ordered pairs i ≠ j.

    T_i/T_j = (P_i + P_i P_j G)/(P_j + P_i P_j G); m = n_cases·(n_cases − 1).

    Parameters
    ----------
    P : numpy.ndarray
        Plant responses, (n_omega, n_cases) complex.

    Returns
    -------
    tuple of numpy.ndarray
        ``(A, B, C, D)``, each (n_omega, m) complex.
    """
    n = P.shape[1]
    i, j = np.nonzero(~np.eye(n, dtype=bool))
    Pi, Pj = P[:, i], P[:, j]
    return Pi, Pi * Pj, Pj, Pi * Pj
