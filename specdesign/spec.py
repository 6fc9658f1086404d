"""Fatigue-based specifications: W_y(s) = baseline T_{y,w}(s) × shaping elements.

The seed paper's main contribution (Sect. 3): from the damage sensitivity ΔD%(ω) of the
baseline closed loop (Eq. 7), shape a specification W_y(s) with notch filters where ΔD% is
high, and quantify the fatigue it promises, by Eq. (10) (linear in the spectral change) and
exactly (Dirlik on |W_y|² S_W). Damage is the quantity that Eq. (10) is linear in; the DEL
change follows as DEL ratio = damage ratio^(1/m), reported beside it.

Units: ω in rad/s, depths in dB (positive = attenuation), PSDs one-sided per rad/s.

Typical use:

>>> from specdesign.spec import baseline_analysis, shape_to_target
>>> from specdesign.turbine import iea15mw
>>> base = baseline_analysis(iea15mw(), 19.0)    # T_{MyT,w}, S_W, ΔD%(ω) at 19 m/s
>>> res = shape_to_target(base, 15.0)            # notches promising 15 % less damage
>>> w_myt = res.specification.tf()               # W_MyT(s)

That is the paper's shaper (notches above 0.6 rad/s, no feasibility guarantee). The
specification to hand to a design is ``feasibility.shape_whole_band(base, 25.0)`` (a DEL
target): the whole band, certified over the plant cases, in ``res.certified``
(:func:`specdesign.feasibility.shape_whole_band`, on this module's baseline).
"""
from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import control as ct
import numpy as np
from numpy.typing import ArrayLike

from loopshaping import controller as lc
from loopshaping.controller import Controller, Element

from . import closedloop, spectral, turbine, wind
from .wind import LOWEST_OMEGA, RECORD_LENGTH, record_window
from ._checks import as_omega, as_psd, positive_scalar, real_scalar
from ._docs import docstring_of
from ._kkt import kkt_point
from .closedloop import siso_response
from .fatigue import TOWER_M
from .rosco import rosco_baseline, rosco_gain_schedule

if TYPE_CHECKING:
    from loopshaping.controller import Controller, Element

    from .turbine import TurbineModel

__all__ = [
    "SLSQP_OPTIONS",
    "KEEP_BELOW",
    "SPEC_REDUCTION",
    "TOWER_RELAX_DB",
    "TOWER_RELAX_OMEGA",
    "check_shaping_request",
    "Notch",
    "Gain",
    "LeadLag",
    "LowPass",
    "Specification",
    "Baseline",
    "Promise",
    "ShapingResult",
    "baseline_controller",
    "baseline_controllers",
    "baseline_analysis",
    "baseline_from_response",
    "default_omega",
    "promise_of",
    "shape_to_target",
    "speed_specification",
    "specification_table",
    "DesignSpecifications",
    "design_specifications",
    "specification_pair",
    "from_element",
]

#: SciPy SLSQP settings of the workbench's constrained fits (the notch shaper here, the QFT
#: tuner's polish): at most 300 iterations, converged when the cost changes by less than 1e-10.
SLSQP_OPTIONS = {"maxiter": 300, "ftol": 1e-10}
#: No notch below this frequency (rad/s) by default: the low frequencies are kept for power
#: regulation (the seed paper shapes around the tower mode, ≈ 1.1 rad/s on the IEA 15 MW).
KEEP_BELOW = 0.6
#: Damage reduction (%) the notch-shaped tower specification of the notch designs promises by
#: default (qft.spec_notch, hinf.spec_like_qft, the demo).
SPEC_REDUCTION = 15.0
#: High-frequency relaxation (dB) of the notch designs' tower specification and the corner
#: (rad/s) above which it applies: ΔD% is negligible there (:func:`design_specifications`).
TOWER_RELAX_DB, TOWER_RELAX_OMEGA = 6.0, 1.3


# --------------------------------------------------------------------------------------
# Shaping elements: frozen records with an exact transfer function and a fast response.
# --------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Notch:
    """Second-order notch N(s) = (s² + 2ζ_z ω_n s + ω_n²) / (s² + 2ζ_p ω_n s + ω_n²).

    Parameters
    ----------
    omega_n : float
        Centre frequency, rad/s.
    depth_db : float
        Attenuation at ω_n in dB (> 0 attenuates; |N(jω_n)| = ζ_z/ζ_p = 10^(−depth/20)).
    width : float
        Damping ratio ζ_p of the pole pair (dimensionless, 0 < width ≤ 2): the relative
        bandwidth of the notch; 0.1 is narrow, 0.7 wide. Unity gain at DC and at ∞.

    Raises
    ------
    ValueError
        If ``omega_n`` is not positive and finite, ``depth_db`` is not finite, or ``width``
        is outside (0, 2].

    Examples
    --------
    >>> from specdesign.spec import Notch
    >>> n = Notch(1.0, 6.0, 0.2)         # 6 dB deep at 1 rad/s
    >>> print(f"{n.zeta_zero:.4f} {abs(n.response([1.0])[0]):.4f}")
    0.1002 0.5012
    """

    omega_n: float
    depth_db: float
    width: float = 0.3

    def __post_init__(self):
        positive_scalar(self.omega_n, "Notch.omega_n (rad/s)")
        if not np.isfinite(self.depth_db):
            raise ValueError(f"Notch.depth_db={self.depth_db!r} must be finite (dB)")
        if not 0 < self.width <= 2:
            raise ValueError(f"Notch.width={self.width!r} is the pole damping ratio; use 0 < width <= 2")

    @property
    def zeta_zero(self) -> float:
        """Damping ratio ζ_z = ζ_p·10^(−depth/20) of the zero pair (-)."""
        return self.width * 10 ** (-self.depth_db / 20)

    def tf(self) -> ct.TransferFunction:
        """The element as a transfer function (the formula of its class docstring).

        Returns
        -------
        control.TransferFunction
            Dimensionless, s in rad/s.
        """
        w = self.omega_n
        return ct.tf([1, 2 * self.zeta_zero * w, w * w], [1, 2 * self.width * w, w * w])

    def response(self, omega: ArrayLike) -> np.ndarray:
        """The element's response on a frequency grid (the formula of its class docstring at s = jω).

        Parameters
        ----------
        omega : array_like
            Frequencies, rad/s (any shape).

        Returns
        -------
        numpy.ndarray
            Complex response (-), shaped like ``omega``.
        """
        s = 1j * np.asarray(omega, dtype=float)
        w = self.omega_n
        return (s * s + 2 * self.zeta_zero * w * s + w * w) / (s * s + 2 * self.width * w * s + w * w)

    def to_elements(self) -> tuple[Element, ...]:
        """The same factor as :mod:`loopshaping.controller` elements.

        Returns
        -------
        tuple of loopshaping.controller.Element
            A :class:`Notch`: one ``notch(omega_n, zeta_zero, width)``; a :class:`Gain`: one
            ``gain(10^(gain_db/20))`` (linear); a :class:`LeadLag`: one ``lead_lag(omega_zero,
            omega_pole)``; a :class:`LowPass`: a ``complex_pole`` (ζ < 1) or two ``real_pole`` at
            ω_c(ζ ± √(ζ² − 1)) (ζ ≥ 1), unity gain at DC.
        """
        return (lc.notch(self.omega_n, self.zeta_zero, self.width),)


@dataclass(frozen=True)
class Gain:
    """Constant gain in dB (negative attenuates everywhere).

    Parameters
    ----------
    gain_db : float
        The gain, dB of the linear factor 10^(gain_db/20).

    Examples
    --------
    >>> from specdesign.spec import Gain
    >>> Gain(-6.0).response([0.1, 1.0]).real.round(3)
    array([0.501, 0.501])
    """

    gain_db: float

    def __post_init__(self):
        # a NaN gain would make every response NaN (and a session saved with it unreadable)
        if isinstance(self.gain_db, (bool, np.bool_, str, bytes)) or not np.isfinite(self.gain_db):
            raise ValueError(f"Gain.gain_db={self.gain_db!r} must be a finite number of dB")

    @docstring_of(Notch)
    def tf(self) -> ct.TransferFunction:
        return ct.tf([10 ** (self.gain_db / 20)], [1])

    @docstring_of(Notch)
    def response(self, omega: ArrayLike) -> np.ndarray:
        return np.full(np.shape(omega), 10 ** (self.gain_db / 20), dtype=complex)

    @docstring_of(Notch)
    def to_elements(self) -> tuple[Element, ...]:
        return (lc.gain(10 ** (self.gain_db / 20)),)


@dataclass(frozen=True)
class LeadLag:
    """Lead-lag (1 + s/ω_z) / (1 + s/ω_p): lead if ω_z < ω_p, lag otherwise.

    Unity gain at DC, ω_p/ω_z at high frequency.

    Parameters
    ----------
    omega_zero : float
        Zero frequency ω_z, rad/s (> 0).
    omega_pole : float
        Pole frequency ω_p, rad/s (> 0).

    Raises
    ------
    ValueError
        If a frequency is not positive and finite.

    Examples
    --------
    >>> import numpy as np
    >>> from specdesign.spec import LeadLag
    >>> np.abs(LeadLag(1.0, 10.0).response([0.0, 1e3])).round(2)   # +20 dB at high ω
    array([ 1., 10.])
    """

    omega_zero: float
    omega_pole: float

    def __post_init__(self):
        positive_scalar(self.omega_zero, "LeadLag.omega_zero (rad/s)")
        positive_scalar(self.omega_pole, "LeadLag.omega_pole (rad/s)")

    @docstring_of(Notch)
    def tf(self) -> ct.TransferFunction:
        return ct.tf([1 / self.omega_zero, 1], [1 / self.omega_pole, 1])

    @docstring_of(Notch)
    def response(self, omega: ArrayLike) -> np.ndarray:
        s = 1j * np.asarray(omega, dtype=float)
        return (1 + s / self.omega_zero) / (1 + s / self.omega_pole)

    @docstring_of(Notch)
    def to_elements(self) -> tuple[Element, ...]:
        return (lc.lead_lag(self.omega_zero, self.omega_pole),)


@dataclass(frozen=True)
class LowPass:
    """Second-order low-pass ω_c² / (s² + 2ζ ω_c s + ω_c²), unity gain at DC.

    Parameters
    ----------
    omega_c : float
        Corner (natural) frequency ω_c, rad/s (> 0).
    zeta : float
        Damping ratio ζ of the pole pair (-, > 0).

    Raises
    ------
    ValueError
        If ``omega_c`` or ``zeta`` is not positive and finite.

    Examples
    --------
    >>> import numpy as np
    >>> from specdesign.spec import LowPass
    >>> np.abs(LowPass(2.0, 0.7).response([0.0, 2.0])).round(4)   # 1/(2ζ) at ω_c
    array([1.    , 0.7143])
    """

    omega_c: float
    zeta: float = 0.7

    def __post_init__(self):
        positive_scalar(self.omega_c, "LowPass.omega_c (rad/s)")
        positive_scalar(self.zeta, "LowPass.zeta")

    @docstring_of(Notch)
    def tf(self) -> ct.TransferFunction:
        w = self.omega_c
        return ct.tf([w * w], [1, 2 * self.zeta * w, w * w])

    @docstring_of(Notch)
    def response(self, omega: ArrayLike) -> np.ndarray:
        s = 1j * np.asarray(omega, dtype=float)
        w = self.omega_c
        return w * w / (s * s + 2 * self.zeta * w * s + w * w)

    @docstring_of(Notch)
    def to_elements(self) -> tuple[Element, ...]:
        if self.zeta < 1:
            return (lc.complex_pole(self.omega_c, self.zeta),)
        r = math.sqrt(self.zeta ** 2 - 1)
        return (lc.real_pole(self.omega_c * (self.zeta - r)), lc.real_pole(self.omega_c * (self.zeta + r)))


_ELEMENTS = (Notch, Gain, LeadLag, LowPass)


def from_element(element: Element) -> Gain | LeadLag | Notch | LowPass:
    """The shaping element equal to one :class:`loopshaping.controller.Element`.

    Parameters
    ----------
    element : loopshaping.controller.Element
        A ``gain`` (> 0), ``lead_lag``, ``notch`` (ζ_z ≤ ζ_p: an attenuation) or
        ``complex_pole`` (a unity-DC-gain low-pass).

    Returns
    -------
    Gain, LeadLag, Notch or LowPass
        The specification element with the same frequency response.

    Raises
    ------
    TypeError
        If ``element`` is not a :class:`loopshaping.controller.Element`.
    ValueError
        For an element with no specification counterpart (integrators, differentiators,
        real or right-half-plane poles and zeros, a negative gain): a specification is a
        stable, minimum-phase reshaping of the baseline.

    Examples
    --------
    >>> from loopshaping import controller as lc
    >>> from specdesign.spec import from_element
    >>> from_element(lc.notch(1.0, 0.05, 0.2))       # ζ_z/ζ_p = 1/4: 12 dB deep
    Notch(omega_n=1.0, depth_db=12.041199826559248, width=0.2)
    """
    if not isinstance(element, Element):
        raise TypeError(f"element must be a loopshaping.controller.Element, got {type(element).__name__}")
    k, p = element.kind, element.params
    if k == "gain" and p["k"] > 0:
        return Gain(20 * math.log10(p["k"]))
    if k == "lead_lag":
        return LeadLag(p["zero"], p["pole"])
    if k == "notch" and 0 < p["zeta_zero"] <= p["zeta_pole"] <= 2:
        return Notch(p["omega"], -20 * math.log10(p["zeta_zero"] / p["zeta_pole"]), p["zeta_pole"])
    if k == "complex_pole" and p["zeta"] > 0:
        return LowPass(p["omega"], p["zeta"])
    raise ValueError(f"a loopshaping {element} has no specification element: a specification takes positive gains, "
                     "lead-lags, notches (0 < ζ_z ≤ ζ_p ≤ 2) and stable complex poles (low-pass)")


@dataclass(frozen=True)
class Specification:
    """A specification W_y(s) = baseline(s) × Π elements(s).

    Parameters
    ----------
    baseline : control.LTI
        The closed-loop map wind (m/s) → y of the baseline controller: a SISO, proper,
        stable python-control LTI, in output units per m/s (e.g. ``closed_loop(...)[y, "wind"]``).
    elements : tuple
        Shaping elements (:class:`Notch`, :class:`Gain`, :class:`LeadLag`, :class:`LowPass`),
        dimensionless factors.
    name : str
        Name of the specification (e.g. ``W_tower_base_my``).

    Raises
    ------
    TypeError
        If ``baseline`` is not an LTI system, or an element is not a shaping element.
    ValueError
        If ``baseline`` is not SISO, is improper, or is unstable.

    Examples
    --------
    >>> import control
    >>> from specdesign.spec import Notch, Specification
    >>> w = Specification(control.tf([1.0], [1.0, 1.0]), (Notch(1.0, 6.0, 0.2),))
    >>> print(f"{abs(w.response([1.0])[0]):.4f}")       # |1/(j+1)| × 10^(-6/20)
    0.3544
    """

    baseline: object
    elements: tuple = ()
    name: str = "W"

    def __post_init__(self):
        if not isinstance(self.baseline, ct.LTI):
            raise TypeError(f"baseline must be a python-control LTI system (wind → output), got {type(self.baseline).__name__}")
        if self.baseline.ninputs != 1 or self.baseline.noutputs != 1:
            raise ValueError(f"baseline must be SISO (one wind input, one output), got {self.baseline.noutputs}x{self.baseline.ninputs}")
        _check_proper_stable(self.baseline, "baseline")
        object.__setattr__(self, "elements", tuple(self.elements))
        for i, e in enumerate(self.elements):
            if not isinstance(e, _ELEMENTS):
                raise TypeError(f"elements[{i}] must be one of {[c.__name__ for c in _ELEMENTS]}, got {type(e).__name__}")

    def shaping(self, omega: ArrayLike) -> np.ndarray:
        """Product of the elements' responses, W_y/baseline, on a frequency grid.

        Parameters
        ----------
        omega : array_like
            Frequencies, rad/s.

        Returns
        -------
        numpy.ndarray
            Complex Π elements(jω) (-), shaped like ``omega``.
        """
        out = np.ones(np.shape(omega), dtype=complex)
        for e in self.elements:
            out = out * e.response(omega)
        return out

    def response(self, omega: ArrayLike) -> np.ndarray:
        """W_y(jω) on a frequency grid.

        Parameters
        ----------
        omega : array_like
            Frequencies, rad/s.

        Returns
        -------
        numpy.ndarray
            Complex W_y(jω), output units per m/s, shaped like ``omega``.
        """
        omega = np.asarray(omega, dtype=float)
        # all frequencies at once: a certified W is a ~25-state map evaluated on dense grids
        return siso_response(self.baseline, omega, "baseline", method="batched") * self.shaping(omega)

    def magnitude(self, omega: ArrayLike) -> np.ndarray:
        """|W_y(jω)|, output units per m/s (linear, not dB): the modulus of :meth:`response`.

        Parameters
        ----------
        omega : array_like
            As :meth:`response`'s (rad/s).

        Returns
        -------
        numpy.ndarray
            Real, shaped like ``omega``.
        """
        return np.abs(self.response(omega))

    def tf(self) -> ct.TransferFunction:
        """W_y(s) as a transfer function (minimal realisation of the product).

        Returns
        -------
        control.TransferFunction
            W_y(s), output units per m/s.
        """
        w = ct.tf(self.baseline)
        for e in self.elements:
            w = w * e.tf()
        return ct.minreal(w, verbose=False)

    def add(self, element: Notch | Gain | LeadLag | LowPass) -> "Specification":
        """A copy with one more shaping element.

        Parameters
        ----------
        element : Notch, Gain, LeadLag or LowPass
            The element appended to :attr:`elements`.

        Returns
        -------
        Specification
            The new specification (this one is unchanged).

        Raises
        ------
        TypeError
            If ``element`` is not a shaping element.
        """
        return replace(self, elements=self.elements + (element,))

    def shaping_controller(self) -> Controller:
        """The shaping Π elements(s) as a :class:`loopshaping.controller.Controller`.

        That is the vocabulary a controller is edited in (gains, lead-lags, notches, poles),
        so a specification and a controller can be shaped, plotted and saved alike.

        Returns
        -------
        loopshaping.controller.Controller
            The elements' product (-), without the baseline.
        """
        return Controller(tuple(x for e in self.elements for x in e.to_elements()))


def _check_proper_stable(sys, name):
    if isinstance(sys, ct.TransferFunction):
        num, den = sys.num[0][0], sys.den[0][0]
        if len(np.trim_zeros(num, "f")) > len(np.trim_zeros(den, "f")):
            raise ValueError(f"{name} is improper (numerator degree > denominator degree); a specification must be a proper transfer function")
    poles = ct.poles(sys)
    if sys.isctime() and np.any(poles.real >= 0):
        bad = poles[poles.real >= 0]
        raise ValueError(f"{name} is not stable (poles {np.round(bad, 4)} in the closed right half-plane); a specification must be a stable closed-loop map")


# --------------------------------------------------------------------------------------
# Baseline analysis and promises
# --------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Baseline:
    """The baseline loop seen by one output: everything Eq. (7) and Eq. (10) need.

    Made by :func:`baseline_analysis` or :func:`baseline_from_response`.

    Parameters
    ----------
    omega : numpy.ndarray
        Frequency grid, rad/s.
    t_response : numpy.ndarray
        Complex T_{y,w}(jω) on ``omega``, output units per m/s.
    wind_psd : numpy.ndarray
        Wind PSD S_W(ω), one-sided, (m/s)² per rad/s.
    psd : numpy.ndarray
        Output PSD |T|² S_W, one-sided, output units² per rad/s.
    damage_rate : float
        Damage rate, 1/s (S-N curve with S_ref = 1 in the output's units).
    sensitivity : numpy.ndarray
        ΔD%(ω): % damage change per 1 % reduction of S_y at each grid point (computed with a
        finite step ``reduction``).
    m : float
        Wöhler exponent (-), range-based S-N curve.
    method : str
        Damage method name (:func:`specdesign.spectral.damage_rate`).
    reduction : float
        Finite relative step of the sensitivity (-; 0.01 is 1 %).
    system : control.LTI, optional
        T_{y,w}(s) as a system, when known (needed for a :class:`Specification`).
    output : str
        Name of the output y.
    wind_speed : float
        Operating point, m/s (nan when unknown).
    extras : dict
        Free-form extra data; :func:`baseline_analysis` records ``turbulence_class`` and
        ``controller`` (None for ROSCO's) there.
    model : TurbineModel or LinearTurbine, optional
        The turbine the baseline was made on (:func:`baseline_analysis`), so that
        :func:`specdesign.feasibility.shape_whole_band` can certify a specification on its plant.
    """

    omega: np.ndarray
    t_response: np.ndarray
    wind_psd: np.ndarray
    psd: np.ndarray
    damage_rate: float
    sensitivity: np.ndarray
    m: float
    method: str
    reduction: float
    system: object = None
    output: str = ""
    wind_speed: float = float("nan")
    extras: dict = field(default_factory=dict)
    model: object = field(default=None, repr=False, compare=False)

    @property
    def del_1hz(self) -> float:
        """DEL at 1 Hz of the baseline output, a range in the output's units (N·m for MyT)."""
        return float(self.damage_rate ** (1.0 / self.m))


def baseline_from_response(omega: ArrayLike, t_response: ArrayLike, wind_psd: ArrayLike, m: float = TOWER_M, *,
                           method: str = "dirlik", reduction: float = 0.01, system: ct.LTI | None = None,
                           output: str = "", wind_speed: float = float("nan")) -> Baseline:
    """Baseline from a closed-loop frequency response T(jω) and an input spectrum S_W(ω).

    Parameters
    ----------
    omega : array_like
        Frequencies, rad/s: 1-D, increasing, non-negative.
    t_response : array_like
        Complex T_{y,w}(jω) on ``omega``, output units per m/s.
    wind_psd : array_like
        One-sided wind PSD S_W on ``omega``, (m/s)² per rad/s.
    m : float
        Wöhler exponent (-), range-based S-N curve.
    method : str
        Damage method (:func:`specdesign.spectral.damage_rate`).
    reduction : float
        Finite relative step of ΔD% (-); the result is rescaled to "per 1 %" (Eq. 10).
    system : control.LTI, optional
        T_{y,w}(s) as a system, kept in :attr:`Baseline.system`.
    output : str
        Name of the output y.
    wind_speed : float
        Operating point, m/s (informative).

    Returns
    -------
    Baseline
        T, S_W, S_y = |T|² S_W, the damage rate and ΔD%(ω).

    Raises
    ------
    TypeError
        If ``omega`` or ``wind_psd`` is complex.
    ValueError
        If ``omega`` is not a valid grid, ``t_response`` or ``wind_psd`` does not match it,
        ``wind_psd`` is negative or non-finite, or the output spectrum carries no damage.

    Examples
    --------
    A lightly damped mode at 1 rad/s driven by white wind:

    >>> import numpy as np
    >>> from specdesign.spec import baseline_from_response
    >>> omega = np.linspace(0.0, 2.0, 201)                         # rad/s
    >>> base = baseline_from_response(omega, 1 / (1 - omega**2 + 0.2j * omega), np.ones_like(omega))
    >>> print(f"{base.del_1hz:.3f}")
    5.758
    """
    omega = as_omega(omega)
    t_response = np.asarray(t_response, dtype=complex)
    if t_response.shape != omega.shape:
        raise ValueError(f"t_response must have the shape of omega {omega.shape}, got {t_response.shape}")
    wind_psd = as_psd(wind_psd, omega.size, "wind_psd")
    psd = np.abs(t_response) ** 2 * wind_psd
    d0 = float(spectral.damage_rate(omega, psd, m, method=method))
    if not d0 > 0:
        raise ValueError("the baseline output spectrum carries no damage (all-zero PSD); check the output and the wind spectrum")
    # Eq. (10) reads ΔD% as "per 1 % reduction"; a different finite step is rescaled to it.
    sens = spectral.sensitivity(omega, psd, m, reduction=reduction, method=method) * (0.01 / reduction)
    return Baseline(omega, t_response, wind_psd, psd, d0, np.asarray(sens), float(m), method, float(reduction), system, output, float(wind_speed))


def default_omega(n: int = 400, lo: float = LOWEST_OMEGA, hi: float = 10.0) -> np.ndarray:
    """Log-spaced design grid in rad/s (covers the wind band, the tower mode and 3P).

    The band starts at :data:`LOWEST_OMEGA` (a tenth of a 10-minute record's fundamental), where
    :func:`record_window` has made the spectrum negligible, and ends at 10 rad/s, above 3P
    (2.4 rad/s on the IEA 15 MW): the spectral figures computed on it are converged in both.

    Parameters
    ----------
    n : int
        Number of points.
    lo : float
        First frequency, rad/s.
    hi : float
        Last frequency, rad/s.

    Returns
    -------
    numpy.ndarray
        ``n`` log-spaced frequencies from ``lo`` to ``hi``, rad/s.
    """
    return np.logspace(np.log10(lo), np.log10(hi), n)


def baseline_controller(model, wind_speed: float) -> ct.LTI:
    """The baseline pitch controller C_β of ``model`` at ``wind_speed`` (ROSCO's PI, tower damping off).

    A model that carries its own baseline (a :class:`specdesign.openfast.LinearTurbine`:
    ROSCO's pole placement on its linearisations) gives it through its
    ``baseline_controller(wind_speed)``; a :class:`specdesign.turbine.TurbineModel` gets
    :func:`specdesign.rosco.rosco_baseline`.

    Parameters
    ----------
    model : TurbineModel or LinearTurbine
        The turbine.
    wind_speed : float
        Operating point, m/s.

    Returns
    -------
    control.LTI
        C_β from ``gen_speed`` (rad/s) to ``pitch_cmd`` (rad), β = −C_β·Ω_g.

    Examples
    --------
    >>> from specdesign.spec import baseline_controller
    >>> from specdesign.turbine import iea15mw
    >>> baseline_controller(iea15mw(), 19.0).name
    'ROSCO_PI@19mps'
    """
    own = getattr(model, "baseline_controller", None)
    if callable(own):
        return own(wind_speed)
    return turbine.rosco_baseline(model, wind_speed)


def baseline_controllers(model, wind_speeds: Sequence[float]) -> list:
    """:func:`baseline_controller` at several wind speeds, ROSCO's schedule fitted once.

    Parameters
    ----------
    model : TurbineModel or LinearTurbine
        The turbine.
    wind_speeds : sequence of float
        Operating points, m/s.

    Returns
    -------
    list of control.LTI
        One C_β per speed, as :func:`baseline_controller` gives it (for a TurbineModel
        :func:`specdesign.rosco.rosco_baseline` on one :func:`specdesign.rosco.rosco_gain_schedule`).

    Examples
    --------
    >>> from specdesign.spec import baseline_controllers
    >>> from specdesign.turbine import iea15mw
    >>> [c.name for c in baseline_controllers(iea15mw(), (17.0, 19.0))]
    ['ROSCO_PI@17mps', 'ROSCO_PI@19mps']
    """
    if callable(getattr(model, "baseline_controller", None)):
        return [model.baseline_controller(float(v)) for v in wind_speeds]
    schedule = rosco_gain_schedule(model)  # once for every speed (the same fit each call would redo)
    return [rosco_baseline(model, float(v), schedule=schedule) for v in wind_speeds]


def baseline_analysis(model: TurbineModel, wind_speed: float, output: str = "tower_base_my", *, m: float = TOWER_M,
                      omega: ArrayLike | None = None, controller: ct.LTI | None = None, turbulence_class: str = "B",
                      method: str = "dirlik", reduction: float = 0.01,
                      record_length: float | None = RECORD_LENGTH) -> Baseline:
    """ΔD%(ω) of the baseline closed loop of ``model`` at ``wind_speed`` for ``output``.

    The baseline controller is ROSCO's PI (tower damping off) unless ``controller`` is given;
    the disturbance is the rotor-effective wind spectrum (IEC NTM ``turbulence_class``).

    Parameters
    ----------
    model : specdesign.turbine.TurbineModel or specdesign.openfast.LinearTurbine
        The turbine (its ``linearize`` and ``rotor_radius``; the baseline of
        :func:`baseline_controller`).
    wind_speed : float
        Operating point, m/s.
    output : str
        Plant output y (``tower_base_my``, N·m, by default; ``gen_speed``, rad/s, ...).
    m : float
        Wöhler exponent (-), range-based S-N curve.
    omega : array_like, optional
        Frequency grid, rad/s, positive (default :func:`default_omega`: 400 points, 0.001-10).
    controller : control.LTI, optional
        Pitch controller C_β (rad per rad/s, β = −C_β·Ω_g); default ROSCO's PI
        (:func:`baseline_controller`).
    turbulence_class : str
        IEC turbulence class of the wind spectrum ("A", "B", "C", ...).
    method : str
        Damage method (:func:`specdesign.spectral.damage_rate`).
    reduction : float
        Finite relative step of ΔD% (-).
    record_length : float or None
        Length of the records the DEL is counted over, s: S_W is the wind spectrum times
        :func:`record_window` (the variance about each record's mean; default 600 s). None for
        the bare spectrum (then the figures depend on where the grid starts).

    Returns
    -------
    Baseline
        The baseline loop's T_{y,w}, S_W (windowed), S_y, damage rate and ΔD%(ω), with the closed-loop
        system in :attr:`Baseline.system`, ``model`` and ``wind_speed`` kept (and
        ``turbulence_class`` and ``controller`` in :attr:`Baseline.extras`).

    Raises
    ------
    ValueError
        If ``omega`` is not a valid positive grid, ``output`` is not a plant output, or the
        output spectrum carries no damage.

    Examples
    --------
    >>> from specdesign.spec import baseline_analysis
    >>> from specdesign.turbine import iea15mw
    >>> base = baseline_analysis(iea15mw(), 19.0)
    >>> print(f"{base.output}: DEL {base.del_1hz / 1e6:.1f} MN·m, ΣΔD% = {base.sensitivity.sum():.2f}")
    tower_base_my: DEL 32.4 MN·m, ΣΔD% = 2.00
    """
    omega = default_omega() if omega is None else as_omega(omega, allow_zero=False)
    plant = model.linearize(wind_speed)
    c = baseline_controller(model, wind_speed) if controller is None else controller
    cl = closedloop.closed_loop(plant, c)
    t_sys = cl[output, "wind"]
    t = closedloop.frequency_response(cl, omega, output, "wind")
    s_w = wind.rotor_effective_spectrum(omega, wind_speed, model.rotor_radius, turbulence_class=turbulence_class)
    if record_length is not None:
        s_w = s_w * record_window(omega, record_length)
    base = baseline_from_response(omega, t, s_w, m, method=method, reduction=reduction, system=t_sys, output=output,
                                  wind_speed=wind_speed)
    return replace(base, model=model, extras={"turbulence_class": turbulence_class, "controller": controller,
                                              "record_length": record_length})


@dataclass(frozen=True)
class Promise:
    """What a specification promises against its baseline (all in %, positive = less fatigue).

    The DEL reductions follow from DEL ratio = damage ratio^(1/m).

    Parameters
    ----------
    predicted_damage : float
        Damage reduction by Eq. (10), linear in the spectral change, %.
    exact_damage : float
        Damage reduction by the damage method (Dirlik) on |W|² S_W, %.
    predicted_del : float
        DEL reduction from ``predicted_damage``, %.
    exact_del : float
        DEL reduction from ``exact_damage``, %.
    """

    predicted_damage: float
    exact_damage: float
    predicted_del: float
    exact_del: float

    @property
    def linearisation_error(self) -> float:
        """Eq. (10) minus exact damage reduction, percentage points."""
        return self.predicted_damage - self.exact_damage


def promise_of(spec_or_shaping: Specification | ArrayLike, base: Baseline) -> Promise:
    """Promised fatigue reduction of a specification (or a shaping response) vs ``base``.

    Parameters
    ----------
    spec_or_shaping : Specification or array_like
        A :class:`Specification` (evaluated on ``base.omega``), or a complex / real array of
        the shaping W_y/T (-) on the baseline grid.
    base : Baseline
        The baseline (:func:`baseline_analysis`).

    Returns
    -------
    Promise
        Damage and DEL reductions, % (Eq. 10 and exact).

    Raises
    ------
    ValueError
        If a notch of the specification lies outside the baseline grid, or the shaping array
        does not have the grid's shape.

    Examples
    --------
    >>> from specdesign.spec import Notch, baseline_analysis, promise_of
    >>> from specdesign.turbine import iea15mw
    >>> base = baseline_analysis(iea15mw(), 19.0)
    >>> p = promise_of(Notch(1.0, 6.0, 0.2).response(base.omega), base)
    >>> print(f"damage −{p.exact_damage:.1f} % (Eq. 10: −{p.predicted_damage:.1f} %), DEL −{p.exact_del:.2f} %")
    damage −28.1 % (Eq. 10: −29.8 %), DEL −7.91 %
    """
    if isinstance(spec_or_shaping, Specification):
        for e in spec_or_shaping.elements:
            if isinstance(e, Notch) and not base.omega[0] <= e.omega_n <= base.omega[-1]:
                raise ValueError(
                    f"notch at omega_n={e.omega_n:g} rad/s lies outside the baseline grid "
                    f"[{base.omega[0]:.3g}, {base.omega[-1]:.3g}] rad/s: its effect cannot be evaluated there"
                )
        w_mag2 = np.abs(spec_or_shaping.response(base.omega)) ** 2
        t_mag2 = np.abs(base.t_response) ** 2
        ratio = np.divide(w_mag2, t_mag2, out=np.ones_like(w_mag2), where=t_mag2 > 0)
    else:
        shaping = np.asarray(spec_or_shaping)
        if shaping.shape != base.omega.shape:
            raise ValueError(f"shaping must have the shape of the baseline grid {base.omega.shape}, got {shaping.shape}")
        ratio = np.abs(shaping) ** 2
    return _promise(base, ratio)


def _promise(base: Baseline, ratio: np.ndarray) -> Promise:
    predicted = float(spectral.predicted_change(base.omega, base.sensitivity, np.ones_like(ratio), ratio))
    d_new = float(spectral.damage_rate(base.omega, base.psd * ratio, base.m, method=base.method))
    exact = 100.0 * (1 - d_new / base.damage_rate)
    return Promise(predicted, exact, float(spectral.del_reduction(predicted, base.m)), float(spectral.del_reduction(exact, base.m)))


# --------------------------------------------------------------------------------------
# Automatic shaping
# --------------------------------------------------------------------------------------
@dataclass(frozen=True)
class ShapingResult:
    """Outcome of :func:`shape_to_target`.

    Parameters
    ----------
    notches : tuple of Notch
        The notches placed.
    promise : Promise
        Their promise against the baseline (exact and Eq. 10), %.
    target : float
        The requested reduction, %.
    quantity : {"damage", "del"}
        What the target is a reduction of.
    success : bool
        Whether the target was reached (within the tolerance).
    message : str
        Human-readable outcome, saying why not when it failed.
    specification : Specification or None
        Baseline × notches (:func:`shape_to_target`) or × the whole-band elements
        (:func:`specdesign.feasibility.shape_whole_band`); None when no system is attached to
        the baseline.
    certified : specdesign.feasibility.TargetSpecification or None
        From :func:`specdesign.feasibility.shape_whole_band`: the certified pair (tower and
        generator-speed specifications, the certificate, the plant cases) to hand to
        ``design_qft(model, v, spec=qft.spec_from_certified(...))`` or to edit and :func:`specdesign.feasibility.recertify`;
        None from :func:`shape_to_target`.
    """

    notches: tuple
    promise: Promise
    target: float
    quantity: str
    success: bool
    message: str
    specification: Specification | None = None
    certified: Any = None

    @property
    def reached(self) -> float:
        """The exact reduction reached of ``quantity`` (damage or DEL), %."""
        return self.promise.exact_damage if self.quantity == "damage" else self.promise.exact_del


def _notch_mag2(omega, params):
    """|Π notches(jω)|² for params rows (ω_n, depth_db, width), vectorised."""
    s = 1j * omega[None, :]
    wn, depth, zp = params[:, 0:1], params[:, 1:2], params[:, 2:3]
    zz = zp * 10 ** (-depth / 20)
    n = (s * s + 2 * zz * wn * s + wn * wn) / (s * s + 2 * zp * wn * s + wn * wn)
    return np.prod(np.abs(n) ** 2, axis=0)


#: Most constraint violation (pp of damage reduction) SLSQP's end may have and still be refined to
#: its KKT point by :func:`_kkt_end`, and the parameter step (rad/s, dB, -) at which Newton's
#: method has converged there.
SHAPER_FEASIBLE_PP, SHAPER_STEP_TOL = 1e-6, 1e-9


def _kkt_end(x, cost, margin, bounds):
    """SLSQP's end ``x`` refined to the KKT point of ``cost`` subject to ``margin`` ≥ 0 and the box
    (``specdesign._kkt.kkt_point``): the end itself moves with round-off (1.7e-7 relative in a
    notch's width under a 1e-9 m/s nudge of the wind speed at 17 m/s, which a design built on the
    specification amplified to 2.4e-6 in its controller). ``x`` when SLSQP's end does not meet
    the target (no KKT point to refine to) or Newton's method does not converge."""
    lo, hi = np.array(bounds, float).T
    x = np.clip(np.asarray(x, float), lo, hi)
    if not margin(x) >= -SHAPER_FEASIBLE_PP:
        return x
    return kkt_point(cost, margin, x, lo, hi, active_tol=SHAPER_FEASIBLE_PP, feasible_tol=SHAPER_FEASIBLE_PP,
                     step_tol=SHAPER_STEP_TOL, iterations=30, limit_tol=1e-9)[0]


def check_shaping_request(base: Baseline, target_reduction: float, quantity: str) -> float:
    """The door checks shared by the shapers (:func:`shape_to_target` and
    :func:`specdesign.feasibility.shape_whole_band`): the target as a float.

    Parameters
    ----------
    base : Baseline
        The baseline to shape.
    target_reduction : float
        Requested reduction, % (strictly between 0 and 100).
    quantity : {"damage", "del"}
        What the target is a reduction of.

    Returns
    -------
    float
        ``target_reduction``.

    Raises
    ------
    TypeError
        If ``base`` is not a :class:`Baseline` or the target is not a real number.
    ValueError
        If ``quantity`` is unknown or the target is not in (0, 100).

    Examples
    --------
    >>> from specdesign.spec import baseline_analysis, check_shaping_request
    >>> from specdesign.turbine import iea15mw
    >>> check_shaping_request(baseline_analysis(iea15mw(), 19.0), 25, "del")
    25.0
    """
    if not isinstance(base, Baseline):
        raise TypeError(f"base must be a Baseline (see baseline_analysis), got {type(base).__name__}")
    if quantity not in ("damage", "del"):
        raise ValueError(f"quantity={quantity!r} must be 'damage' or 'del'")
    t = real_scalar(target_reduction, "target_reduction")
    if not 0 < t < 100:
        raise ValueError(f"target_reduction={target_reduction!r} must be a percentage strictly between 0 and 100")
    return t


def shape_to_target(base: Baseline, target_reduction: float, *, quantity: str = "damage", keep_below: float = KEEP_BELOW,
                    n_notches: int | None = None, max_notches: int = 3, max_depth_db: float = 30.0,
                    width_range: tuple[float, float] = (0.05, 0.8), tolerance: float = 0.5) -> ShapingResult:
    """Shape a tower-load specification that promises a target reduction: notches above ``keep_below``.

    The seed paper's shaping (used by the notch designs, notebooks 03-06 and their documented
    numbers): notches where ΔD% is largest above ``keep_below``, no feasibility guarantee. The
    problem solved (scipy SLSQP, exact Dirlik in the constraint): minimise the mean squared
    log-magnitude change of the specification, Σ_k w_k (20 log10 |N(jω_k)|)², with w_k = 1
    above ``keep_below`` and 100 below, subject to reduction ≥ target. Notch centres are
    seeded at the largest ΔD% peaks above ``keep_below``.

    The specification to hand to a design, over the whole band and certified at every plant
    case, is :func:`specdesign.feasibility.shape_whole_band`'s (same baseline, same result
    record).

    Parameters
    ----------
    base : Baseline
        From :func:`baseline_analysis` or :func:`baseline_from_response`.
    target_reduction : float
        Requested reduction in percent (0 < target < 100) of ``quantity``.
    quantity : {"damage", "del"}
        Whether the target is a reduction of damage (Eq. 10's quantity) or of DEL at 1 Hz.
    keep_below : float
        Protected band upper edge, rad/s, the power-regulation band the notches must leave
        alone (their effect below it is penalised heavily and the notch centres stay above).
    n_notches : int, optional
        Fixed number of notches; by default 1, 2, ... up to ``max_notches``.
    max_notches : int
        Most notches tried, and most candidate centres seeded.
    max_depth_db : float
        Deepest notch allowed, dB.
    width_range : (float, float)
        Bounds of the notch width ζ_p (-).
    tolerance : float
        Accepted shortfall, percentage points.

    Returns
    -------
    ShapingResult
        The notches, their promise, whether the target was reached and the specification
        (baseline × notches, when the baseline has a system); ``certified`` is None.

    Raises
    ------
    TypeError
        If ``base`` is not a :class:`Baseline`.
    ValueError
        If ``quantity`` is unknown, ``target_reduction`` is not in (0, 100), ``keep_below``
        lies outside the grid, or no grid frequency lies above ``keep_below``.

    Warns
    -----
    RuntimeWarning
        When the target cannot be reached (the result then has ``success=False`` and says why).

    Examples
    --------
    >>> from specdesign.spec import baseline_analysis, shape_to_target
    >>> from specdesign.turbine import iea15mw
    >>> res = shape_to_target(baseline_analysis(iea15mw(), 19.0), 15.0)
    >>> res.message
    'reached 15.00 % damage reduction (target 15.00 %) with 1 notch(es)'
    >>> print(f"{res.notches[0].omega_n:.2f} rad/s")
    1.02 rad/s
    """
    from scipy.optimize import minimize

    t = check_shaping_request(base, target_reduction, quantity)
    omega = base.omega
    keep_below = float(keep_below)
    if not omega[0] <= keep_below < omega[-1]:
        raise ValueError(f"keep_below={keep_below} rad/s must lie inside the grid [{omega[0]:.3g}, {omega[-1]:.3g}] rad/s")
    target_damage = t if quantity == "damage" else 100.0 * (1 - (1 - t / 100.0) ** base.m)
    protected = omega < keep_below
    weights = np.where(protected, 100.0, 1.0) * np.gradient(np.log(omega))
    weights = weights / weights.sum()
    lo_w, hi_w = width_range

    def damage_reduction(x):
        ratio = _notch_mag2(omega, x.reshape(-1, 3))
        return 100.0 * (1 - spectral.damage_rate(omega, base.psd * ratio, base.m, method=base.method) / base.damage_rate)

    def cost(x):
        ratio = _notch_mag2(omega, x.reshape(-1, 3))
        return float(np.sum(weights * (10 * np.log10(ratio)) ** 2))

    # Seed centres at the largest ΔD% density peaks above the protected band: that is where a
    # given attenuation buys the most damage (Eq. 7).
    density = np.where(~protected, base.sensitivity, -np.inf)
    order = np.argsort(density)[::-1]
    candidates = []
    for k in order:
        if not np.isfinite(density[k]):
            break
        if all(abs(np.log(omega[k] / c)) > 0.25 for c in candidates):
            candidates.append(omega[k])
        if len(candidates) >= max_notches:
            break
    if not candidates:
        raise ValueError("no grid frequency lies above keep_below; extend the grid or lower keep_below")

    counts = [n_notches] if n_notches else range(1, max_notches + 1)
    best = None
    for n in counts:
        centres = (candidates * n)[:n]
        x0 = np.concatenate([[c, 6.0, 0.3] for c in centres])
        lo_omega = max(keep_below, omega[0])
        bounds = [(lo_omega, omega[-1]), (0.0, max_depth_db), (lo_w, hi_w)] * n
        # Upper bound first: the deepest, widest notches show whether the target is reachable.
        x_max = np.concatenate([[c, max_depth_db, hi_w] for c in centres])
        if damage_reduction(x_max) < target_damage - tolerance:
            best = best or (x_max, False)
            continue
        res = minimize(
            cost, x0, method="SLSQP", bounds=bounds,
            constraints=[{"type": "ineq", "fun": lambda x: damage_reduction(x) - target_damage}],
            options=dict(SLSQP_OPTIONS),
        )
        x = _kkt_end(res.x, cost, lambda x: damage_reduction(x) - target_damage, bounds)
        if damage_reduction(x) >= target_damage - tolerance:
            best = (x, True)
            break
        best = (x, False)

    x, ok = best
    notches = tuple(Notch(float(p[0]), float(p[1]), float(p[2])) for p in x.reshape(-1, 3))
    promise = _promise(base, _notch_mag2(omega, x.reshape(-1, 3)))
    reached = promise.exact_damage if quantity == "damage" else promise.exact_del
    success = ok and reached >= t - tolerance
    if success:
        message = f"reached {reached:.2f} % {quantity} reduction (target {t:.2f} %) with {len(notches)} notch(es)"
    else:
        message = (
            f"cannot reach {t:.2f} % {quantity} reduction with up to {max(counts)} notch(es) of at most {max_depth_db:g} dB "
            f"above {keep_below:g} rad/s (best {reached:.2f} %): the fatigue sits in the protected band; "
            "lower keep_below, allow deeper notches or lower the target"
        )
        warnings.warn(message, RuntimeWarning, stacklevel=2)
    spec = Specification(base.system, notches, name=f"W_{base.output}") if base.system is not None else None
    return ShapingResult(notches, promise, t, quantity, bool(success), message, spec)


def speed_specification(model: TurbineModel, wind_speed: float, *, margin_db: float = 0.0,
                        controller: ct.LTI | None = None) -> Specification:
    """Generator-speed specification: the baseline's T_{Ω,w}, optionally relaxed by ``margin_db``.

    Parameters
    ----------
    model : specdesign.turbine.TurbineModel
        The turbine.
    wind_speed : float
        Operating point, m/s.
    margin_db : float
        Relaxation, dB (a :class:`Gain`; 0 for none).
    controller : control.LTI, optional
        Baseline pitch controller C_β (rad per rad/s); default ROSCO's PI.

    Returns
    -------
    Specification
        W_Ω = T_{Ω,w}·10^(margin_db/20), (rad/s) per (m/s), named ``W_gen_speed``.

    Examples
    --------
    >>> from specdesign.spec import speed_specification
    >>> from specdesign.turbine import iea15mw
    >>> speed_specification(iea15mw(), 19.0, margin_db=3.0).elements
    (Gain(gain_db=3.0),)
    """
    plant = model.linearize(wind_speed)
    c = baseline_controller(model, wind_speed) if controller is None else controller
    cl = closedloop.closed_loop(plant, c)
    elements = (Gain(float(margin_db)),) if margin_db else ()
    return Specification(cl["gen_speed", "wind"], elements, name="W_gen_speed")


def specification_table(model: TurbineModel, wind_speeds: Sequence[float] = (15, 17, 19, 21, 23, 25),
                        target_reduction: float = 15.0, **kwargs: Any) -> list[dict]:
    """The "Specifications" row of the paper's Table 3: promised reduction per wind speed.

    Parameters
    ----------
    model : specdesign.turbine.TurbineModel
        The turbine.
    wind_speeds : sequence of float
        Operating points, m/s.
    target_reduction : float
        Damage (or DEL) reduction the notches should promise, %.
    **kwargs : dict, optional
        :func:`shape_to_target` options (``quantity``, ``keep_below``, ``n_notches``,
        ``max_notches``, ``max_depth_db``, ``width_range``, ``tolerance``); the rest go to
        :func:`baseline_analysis`.

    Returns
    -------
    list of dict
        One per wind speed: ``wind_speed`` (m/s), ``notches``, ``promised_damage_pct`` and
        ``promised_del_pct`` (exact, %), ``eq10_damage_pct`` (%), ``success`` and the
        :class:`ShapingResult` as ``result``. Shortfall warnings are suppressed: see ``success``.
    """
    rows = []
    shape_kw = {k: kwargs.pop(k) for k in list(kwargs) if k in ("quantity", "keep_below", "n_notches", "max_notches", "max_depth_db", "width_range", "tolerance")}
    for v in wind_speeds:
        base = baseline_analysis(model, v, **kwargs)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            res = shape_to_target(base, target_reduction, **shape_kw)
        rows.append(
            {
                "wind_speed": float(v),
                "notches": res.notches,
                "promised_damage_pct": res.promise.exact_damage,
                "promised_del_pct": res.promise.exact_del,
                "eq10_damage_pct": res.promise.predicted_damage,
                "success": res.success,
                "result": res,
            }
        )
    return rows


@dataclass(frozen=True)
class DesignSpecifications:
    """The specifications a controller design at one operating point is given.

    Made by :func:`design_specifications`.

    Parameters
    ----------
    base : Baseline
        ROSCO's loop at the operating point (T_{MyT,w}, S_W, ΔD%).
    shaping : ShapingResult
        The notches of :func:`shape_to_target` and their promise (the unrelaxed notch
        specification, what the paper's Table 3 lists).
    tower : Specification
        W_MyT: the notch specification × the high-frequency relaxation (two leads).
    speed : Specification
        W_Ω: ROSCO's T_{Ω,w} relaxed by ``speed_relax_db``.
    """

    base: Baseline
    shaping: ShapingResult
    tower: Specification
    speed: Specification


def specification_pair(obj) -> tuple | None:
    """The (tower, speed) specifications a design is handed, or None if ``obj`` is not a pair.

    Parameters
    ----------
    obj : object
        A record with ``tower`` and ``speed`` attributes (a
        :class:`specdesign.feasibility.TargetSpecification`, :class:`DesignSpecifications`),
        or a tuple/list of two (W_MyT, W_Ω).

    Returns
    -------
    tuple or None
        ``(tower, speed)``; None for anything else (the caller says what it accepts).
    """
    pair = (obj.tower, obj.speed) if hasattr(obj, "tower") and hasattr(obj, "speed") else obj
    return tuple(pair) if isinstance(pair, (tuple, list)) and len(pair) == 2 else None


def design_specifications(model: TurbineModel, wind_speed: float, *, speed_relax_db: float = 4.5,
                          spec_reduction: float = SPEC_REDUCTION, tower_relax_db: float = TOWER_RELAX_DB,
                          tower_relax_omega: float = TOWER_RELAX_OMEGA, keep_below: float = KEEP_BELOW, m: float = TOWER_M,
                          omega: ArrayLike | None = None) -> DesignSpecifications:
    """The tower-load and generator-speed specifications that QFT and H∞ designs are given.

    Tower load: W_MyT = T^ROSCO_{MyT,w} × the notches of :func:`shape_to_target`
    (``spec_reduction`` % damage, notches above ``keep_below`` rad/s) × two leads
    (1 + s/ω_r)/(1 + s/(ω_r·10^(tower_relax_db/40))), ω_r = ``tower_relax_omega``: the spec is
    relaxed by ``tower_relax_db`` at high frequency, where ΔD% is negligible. Generator speed:
    W_Ω = T^ROSCO_{Ω,w}·10^(speed_relax_db/20) (:func:`speed_specification`).

    Parameters
    ----------
    model : specdesign.turbine.TurbineModel
        The turbine.
    wind_speed : float
        Operating point, m/s.
    speed_relax_db : float
        Relaxation of the generator-speed specification, dB (≥ 0).
    spec_reduction : float
        Damage reduction the notches promise, %.
    tower_relax_db : float
        High-frequency relaxation of the tower specification, dB (≥ 0; 0 for none).
    tower_relax_omega : float
        Corner of the relaxation, rad/s.
    keep_below : float
        No notch below this frequency, rad/s.
    m : float
        Wöhler exponent of the tower-base S-N curve (-).
    omega : array_like, optional
        Frequency grid of the baseline analysis, rad/s (default :func:`default_omega`).

    Returns
    -------
    DesignSpecifications
        The baseline, the shaping and both specifications.

    Raises
    ------
    ValueError
        For a negative or non-finite relaxation or a non-positive corner frequency.

    Examples
    --------
    >>> from specdesign.spec import design_specifications
    >>> from specdesign.turbine import iea15mw
    >>> ds = design_specifications(iea15mw(), 19.0)
    >>> ds.tower.name, len(ds.tower.elements), ds.speed.elements
    ('W_tower_base_my', 3, (Gain(gain_db=4.5),))
    """
    for k, v in (("speed_relax_db", speed_relax_db), ("tower_relax_db", tower_relax_db)):
        if not (np.isfinite(v) and v >= 0):
            raise ValueError(f"{k}={v!r} must be a finite relaxation ≥ 0 dB")
    positive_scalar(tower_relax_omega, "tower_relax_omega")
    v = float(wind_speed)
    base = baseline_analysis(model, v, m=m, omega=omega)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        shaping = shape_to_target(base, spec_reduction, keep_below=keep_below)
    relax = ()
    if tower_relax_db > 0:
        half = tower_relax_db / 2
        relax = (LeadLag(tower_relax_omega, tower_relax_omega * 10 ** (half / 20)),) * 2
    tower = Specification(base.system, tuple(shaping.notches) + relax, name="W_tower_base_my")
    speed = speed_specification(model, v, margin_db=float(speed_relax_db))
    return DesignSpecifications(base, shaping, tower, speed)
