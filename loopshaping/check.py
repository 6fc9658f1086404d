"""Check a controller on a dense frequency grid over every plant case.

QFT bounds hold at the design frequencies only; between them a loop can still violate a
spec (the QFT Toolbox's ``chksiso``). This module evaluates every spec on a dense grid for
every case, reports the worst margin per frequency, and, which the toolbox does not, checks
closed-loop stability of every case from the characteristic polynomial (no cancellation, so
unstable pole-zero cancellations between plant and controller are caught), with gain and
phase margins.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from .bounds import as_specs
from .controller import Controller
from .freqresp import check_grid, evaluate, is_lti
from .templates import Template

if TYPE_CHECKING:  # annotations only
    from collections.abc import Sequence

    import control

    from .bounds import Bounds
    from .specs import Spec

__all__ = ["CheckResult", "check", "feedback_poles"]


@dataclass(frozen=True, eq=False)
class CheckResult:
    """Outcome of :func:`check`.

    Parameters
    ----------
    omega : numpy.ndarray
        (n,) dense grid, rad/s.
    names : tuple of str
        Spec names, one per row of ``margins_db``.
    margins_db : numpy.ndarray
        (n_specs, n) worst margin over cases, 20·log10(W/|f|) in dB (≥ 0: met); NaN outside
        a spec's band.
    worst_case : numpy.ndarray
        (n_specs, n) index of the case setting the worst margin (−1 outside band).
    stable : numpy.ndarray
        (n_cases,) closed-loop stability of each case.
    max_pole_real : numpy.ndarray
        (n_cases,) largest real part of the closed-loop poles, 1/s.
    gain_margin_db : numpy.ndarray
        (n_cases,) gain margin nearest 0 dB over the phase crossovers, dB (inf if none).
    phase_margin_deg : numpy.ndarray
        (n_cases,) smallest distance of the loop phase from −180° at the gain crossovers,
        degrees (inf if none).
    tol_db : float
        Margin (dB) below 0 still counted as met (rounding).
    """

    omega: np.ndarray
    names: tuple
    margins_db: np.ndarray
    worst_case: np.ndarray
    stable: np.ndarray
    max_pole_real: np.ndarray
    gain_margin_db: np.ndarray
    phase_margin_deg: np.ndarray
    tol_db: float = 1e-9

    @property
    def spec_passed(self) -> np.ndarray:
        """(n_specs,) each spec met on the whole grid for every case."""
        m = np.where(np.isnan(self.margins_db), np.inf, self.margins_db)
        return np.all(m >= -self.tol_db, axis=1)

    @property
    def passed(self) -> bool:
        """Every spec met on the grid for every case and every closed loop stable."""
        return bool(np.all(self.spec_passed) and np.all(self.stable))

    def worst(self, name: str) -> tuple[float, float, int]:
        """Where spec ``name`` is closest to failing.

        Parameters
        ----------
        name : str
            A spec name.

        Returns
        -------
        tuple
            ``(ω in rad/s, margin in dB, case index)``.

        Raises
        ------
        KeyError
            If there is no spec of that name.
        """
        i = self._row(name)
        m = np.where(np.isnan(self.margins_db[i]), np.inf, self.margins_db[i])
        j = int(np.argmin(m))
        return float(self.omega[j]), float(m[j]), int(self.worst_case[i, j])

    def violated_ranges(self, name: str) -> list:
        """Intervals of the grid where spec ``name`` fails.

        Parameters
        ----------
        name : str
            A spec name.

        Returns
        -------
        list of tuple
            ``(ω_low, ω_high)`` in rad/s, grid points at both ends included.

        Raises
        ------
        KeyError
            If there is no spec of that name.
        """
        i = self._row(name)
        bad = np.nan_to_num(self.margins_db[i], nan=np.inf) < -self.tol_db
        edges = np.flatnonzero(np.diff(np.r_[0, bad.astype(int), 0]))
        return [(float(self.omega[a]), float(self.omega[b - 1])) for a, b in zip(edges[::2], edges[1::2])]

    def _row(self, name):
        if name not in self.names:
            raise KeyError(f"no spec named {name!r}; specs are {self.names}")
        return self.names.index(name)

    def summary(self) -> str:
        """Human-readable report: worst margins, violated ranges, stability, margins.

        Returns
        -------
        str
            One line per spec (worst margin in dB, its frequency in rad/s and plant case), then
            stability and the nominal gain and phase margins.
        """
        lines = [f"check on {len(self.omega)} frequencies {self.omega[0]:.3g}…{self.omega[-1]:.3g} rad/s, "
                 f"{len(self.stable)} plant cases: {'PASSED' if self.passed else 'FAILED'}"]
        for name, ok in zip(self.names, self.spec_passed):
            w, m, c = self.worst(name)
            line = f"  {name:<18} {'ok  ' if ok else 'FAIL'} worst margin {m:+.2f} dB at ω = {w:.4g} rad/s (case {c})"
            if not ok:
                line += "; violated on " + ", ".join(f"[{a:.4g}, {b:.4g}]" for a, b in self.violated_ranges(name)) + " rad/s"
            lines.append(line)
        n_unstable = int(np.sum(~self.stable))
        lines.append(f"  closed-loop stability: {len(self.stable) - n_unstable}/{len(self.stable)} cases stable"
                     + ("" if not n_unstable else f"; unstable cases {np.flatnonzero(~self.stable).tolist()}"))
        lines.append(f"  worst gain margin {np.min(np.abs(self.gain_margin_db)):.2f} dB, "
                     f"worst phase margin {np.min(self.phase_margin_deg):.1f} deg")
        return "\n".join(lines)

    def __str__(self):
        return self.summary()


def _as_tf(sys, name):
    import control as ct

    if isinstance(sys, Controller):
        num, den = sys.polys()
        return np.asarray(num, float), np.asarray(den, float)
    if not is_lti(sys):
        raise TypeError(f"{name} must be a Controller or a SISO python-control LTI; got {type(sys).__name__}")
    if sys.ninputs != 1 or sys.noutputs != 1:
        raise ValueError(f"{name} must be SISO")
    tf = ct.tf(sys)
    return np.trim_zeros(tf.num[0][0], "f"), np.trim_zeros(tf.den[0][0], "f")


def feedback_poles(plant: "Controller | control.LTI", controller: "Controller | control.LTI") -> np.ndarray:
    """Poles of the loop of ``plant`` and ``controller`` with negative unit feedback.

    The roots of n_P·n_G + d_P·d_G, without cancellation, so hidden unstable modes (an
    unstable pole of P cancelled by a zero of G) are kept.

    Parameters
    ----------
    plant : control LTI or Controller
        SISO plant P.
    controller : control LTI or Controller
        SISO controller G.

    Returns
    -------
    numpy.ndarray
        Complex closed-loop poles, 1/s.

    Raises
    ------
    TypeError
        If an argument is neither a Controller nor an LTI.
    ValueError
        If an argument is MIMO or the loop P·G is improper.

    Examples
    --------
    >>> import control as ct
    >>> feedback_poles(ct.tf([1], [1, 0]), ct.tf([2], [1]))
    array([-2.])
    """
    nG, dG = _as_tf(controller, "controller")
    nP, dP = _as_tf(plant, "plant")
    num, den = np.polymul(nP, nG), np.polymul(dP, dG)
    if len(np.trim_zeros(num, "f")) > len(np.trim_zeros(den, "f")):
        raise ValueError("the loop P·G is improper; the closed loop is not well posed (add controller poles)")
    return np.roots(np.polyadd(num, den))


def _margins(L, omega):
    """Per case (columns of L): gain margin nearest 0 dB and smallest phase margin, on the grid."""
    n = L.shape[1]
    gm = np.full(n, np.inf)
    pm = np.full(n, np.inf)
    mag = np.abs(L)
    # Phase crossovers: Im L changes sign with Re L < 0 (interpolated linearly).
    im, re = L.imag, L.real
    i, c = np.nonzero((np.sign(im[:-1]) != np.sign(im[1:])) & (im[:-1] != 0))
    if i.size:
        t = im[i, c] / (im[i, c] - im[i + 1, c])
        x = re[i, c] + t * (re[i + 1, c] - re[i, c])
        keep = x < 0
        g = -20 * np.log10(-x[keep])
        for cc, gg in zip(c[keep], g):
            if abs(gg) < abs(gm[cc]):
                gm[cc] = gg
    # Gain crossovers: |L| crosses 1 (a zero loop, e.g. an absent ATD, lies at −∞ dB: none).
    with np.errstate(divide="ignore"):
        ldb = 20 * np.log10(mag)
    i, c = np.nonzero(np.sign(ldb[:-1]) != np.sign(ldb[1:]))
    if i.size:
        t = ldb[i, c] / (ldb[i, c] - ldb[i + 1, c])
        z = L[i, c] + t * (L[i + 1, c] - L[i, c])
        # Distance of the crossover phase from −180° (stability itself is checked by poles).
        margin = 180 - np.abs(np.degrees(np.angle(z)))
        np.minimum.at(pm, c, margin)
    return gm, pm


def check(plants: "Template | Sequence[control.LTI]", controller: "Controller | control.LTI",
          specs: "Bounds | Spec | Sequence[Spec]",
          omega: ArrayLike) -> CheckResult:
    """Every spec on a dense grid over every case, closed-loop stability and margins.

    Parameters
    ----------
    plants : Template or sequence of control LTI
        A :class:`~loopshaping.templates.Template` built from systems, or the SISO LTI plant
        cases.
    controller : Controller or control LTI
        The controller G.
    specs : Bounds or Spec or list of Spec
        Of a Bounds its specs are re-evaluated. Weights and general-form coefficients must be
        numbers, LTI or callables of ω (arrays given only at the design frequencies cannot be
        evaluated on the dense grid). Disk uncertainty is not applied.
    omega : array_like
        Strictly increasing dense grid, rad/s.

    Returns
    -------
    CheckResult
        Margins per spec and frequency, stability and margins per case.

    Raises
    ------
    ValueError
        For a bad grid, no plant cases, a Template without systems, or an improper loop.
    TypeError
        For specs or systems of the wrong type.

    Examples
    --------
    >>> import control as ct
    >>> from loopshaping.specs import Spec
    >>> res = check([ct.tf([1], [1, 1])], ct.tf([1], [1]), Spec("sensitivity", 2.0), [0.1, 1.0, 10.0])
    >>> res.passed
    True
    """
    w = check_grid(omega, "omega")
    if isinstance(plants, Template):
        if plants.systems is None:
            raise ValueError("plants: this Template has no systems (built from responses); "
                             "pass the plant cases as LTI, they are needed off the design frequencies")
        plants = list(plants.systems)
    else:
        plants = list(plants)
    if not plants:
        raise ValueError("plants is empty")
    specs = as_specs(specs)
    G = (controller.response(w) if isinstance(controller, Controller)
         else evaluate(controller, w, "controller"))[:, None]
    P = np.stack([evaluate(p, w, f"plant {i}") for i, p in enumerate(plants)], axis=1)
    L = P * G
    margins = np.full((len(specs), len(w)), np.nan)
    worst = np.full((len(specs), len(w)), -1)
    for k, sp in enumerate(specs):
        band = sp.in_band(w)
        if sp.kind == "tracking":
            T = np.abs(L / (1 + L))
            Wt = sp.weights(w, 1)[:, 0]
            with np.errstate(divide="ignore"):
                m = 20 * np.log10(Wt) - 20 * np.log10(T.max(1) / T.min(1))
            margins[k] = np.where(band, m, np.nan)
            worst[k] = np.where(band, T.argmax(1), -1)
            continue
        A, B, C, D = sp.coefficients(w, P)
        Wk = sp.weights(w, A.shape[1])
        with np.errstate(divide="ignore", invalid="ignore"):
            f = np.abs((A + B * G) / (C + D * G))
            m = 20 * np.log10(Wk) - 20 * np.log10(f)
        m = np.where(np.isnan(m), -np.inf, m)
        margins[k] = np.where(band, m.min(1), np.nan)
        worst[k] = np.where(band, m.argmin(1), -1)
    poles = [feedback_poles(p, controller) for p in plants]
    max_re = np.array([np.max(p.real, initial=-np.inf) for p in poles])
    gm, pm = _margins(L, w)
    return CheckResult(w, tuple(sp.name for sp in specs), margins, worst, max_re < 0, max_re, gm, pm)
