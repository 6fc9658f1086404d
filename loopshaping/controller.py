"""Controllers as ordered lists of elements, as in loop shaping on a Nichols chart.

Every element is normalised to unit DC gain except ``gain`` itself (and the pure
integrator/differentiator), so the overall gain is the product of the ``gain`` elements and
moving a pole or zero does not change the low-frequency gain:

============== ============================= ====================================
kind           parameters                    factor
============== ============================= ====================================
gain           k (finite, ≠ 0, may be < 0)   k
integrator     order n, 1 ≤ n ≤ 4            1/s^n
differentiator order n, 1 ≤ n ≤ 4            s^n
real_pole      omega (rad/s, ≠ 0; < 0: RHP)  1/(s/ω + 1)
real_zero      omega (rad/s, ≠ 0; < 0: RHP)  s/ω + 1
complex_pole   omega > 0 (rad/s), |zeta| < 1 1/((s/ω)² + 2ζ s/ω + 1)
complex_zero   omega > 0 (rad/s), |zeta| < 1 (s/ω)² + 2ζ s/ω + 1
lead_lag       zero, pole > 0 (rad/s)        (s/zero + 1)/(s/pole + 1)
notch          omega > 0,                    (s² + 2ζ_z ω s + ω²)/(s² + 2ζ_p ω s + ω²)
               0 ≤ zeta_zero ≤ 10,
               0 < zeta_pole ≤ 10
============== ============================= ====================================

Bounds (so that a typo is an error, not a hang or a silently degenerate polynomial): every
parameter is a finite number; every frequency |ω| lies in [MIN_OMEGA, MAX_OMEGA] = [1e-12,
1e12] rad/s; integrator/differentiator orders are integers up to MAX_ORDER = 4; notch damping
ratios are at most MAX_NOTCH_ZETA = 10; a controller has at most MAX_DEGREE = 64 poles and at
most 64 zeros. An error names the parameter, and the element index when read by
:meth:`Controller.from_dict` (``element 2: notch: ...``).

Controllers are immutable: ``add``, ``replace``, ``remove`` and ``set`` return new ones.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike


__all__ = [
    "KINDS", "MAX_DEGREE", "MAX_NOTCH_ZETA", "MAX_OMEGA", "MAX_ORDER", "MIN_OMEGA", "Controller", "Element",
    "complex_pole", "complex_zero", "differentiator", "gain", "integrator", "lead_from_phase", "lead_lag",
    "notch", "real_pole", "real_zero",
]

_PARAMS = {
    "gain": ("k",),
    "integrator": ("order",),
    "differentiator": ("order",),
    "real_pole": ("omega",),
    "real_zero": ("omega",),
    "complex_pole": ("omega", "zeta"),
    "complex_zero": ("omega", "zeta"),
    "lead_lag": ("zero", "pole"),
    "notch": ("omega", "zeta_zero", "zeta_pole"),
}
KINDS = tuple(_PARAMS)
_JSON_VERSION = 1
#: Largest order of an integrator or differentiator element: a controller is a low-order
#: filter, and s^n of a larger n has no use in loop shaping (n = 1e9 hung the polynomial product).
MAX_ORDER = 4
#: Range of every element frequency |ω| (rad/s): outside it 1/ω² under- or overflows towards a
#: degenerate polynomial, and no loop is shaped at 1e-12 or 1e12 rad/s.
MIN_OMEGA, MAX_OMEGA = 1e-12, 1e12
#: Largest damping ratio of a notch (ζ_z and ζ_p): beyond it the "notch" is a plain gain change.
MAX_NOTCH_ZETA = 10.0
#: Largest number of poles (and of zeros) of a controller: polynomial coefficients of a higher
#: degree carry no significant digits, and a controller of thousands of elements only hangs.
MAX_DEGREE = 64


@dataclass(frozen=True)
class Element:
    """One factor of a controller; ``params`` by name (see the module table).

    Parameters
    ----------
    kind : str
        One of :data:`KINDS`.
    params : dict
        The parameters of that kind by name (frequencies ``omega``, ``zero``, ``pole`` in
        rad/s, damping ratios dimensionless, ``order`` an integer, ``k`` the gain).

    Raises
    ------
    ValueError
        For an unknown kind or a parameter out of its range (the message names it).
    TypeError
        For missing or unknown parameters.

    Examples
    --------
    >>> Element("real_pole", {"omega": 2.0}).polys()
    (array([1.]), array([0.5, 1. ]))
    """

    kind: str
    params: dict = field(default_factory=dict)

    def __post_init__(self):
        if not isinstance(self.kind, str) or self.kind not in _PARAMS:
            raise ValueError(f"element kind={self.kind!r} is not one of {KINDS}")
        want = set(_PARAMS[self.kind])
        if not isinstance(self.params, dict):
            raise TypeError(f"element {self.kind!r}: params must be a dict {_PARAMS[self.kind]}, got {type(self.params).__name__}")
        if set(self.params) != want:
            raise TypeError(f"element {self.kind!r} takes parameters {_PARAMS[self.kind]}; got {sorted(self.params)}")
        p = {}
        for k in _PARAMS[self.kind]:
            v = self.params[k]
            if isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating)) or not math.isfinite(v):
                raise ValueError(f"{self.kind}: parameter {k}={v!r} must be a finite number")
            p[k] = int(v) if k == "order" else float(v)
        k = self.kind
        if k == "gain" and p["k"] == 0:
            raise ValueError("gain: k must be non-zero (a zero controller has no loop to shape)")
        if k in ("integrator", "differentiator") and not (1 <= p["order"] <= MAX_ORDER and p["order"] == self.params["order"]):
            raise ValueError(f"{k}: order={self.params['order']!r} must be an integer from 1 to {MAX_ORDER}")
        if k in ("real_pole", "real_zero") and p["omega"] == 0:
            raise ValueError(f"{k}: omega must be ≠ 0 rad/s; use an integrator/differentiator for s = 0")
        if k in ("complex_pole", "complex_zero"):
            if p["omega"] <= 0 or not abs(p["zeta"]) < 1:
                raise ValueError(f"{k}: needs omega > 0 rad/s and |zeta| < 1 (else use two real elements); "
                                 f"got omega={p['omega']!r}, zeta={p['zeta']!r}")
        if k == "lead_lag" and (p["zero"] <= 0 or p["pole"] <= 0):
            raise ValueError(f"lead_lag: zero and pole must be > 0 rad/s; got zero={p['zero']!r}, pole={p['pole']!r}")
        if k == "notch":
            if p["omega"] <= 0:
                raise ValueError(f"notch: omega={p['omega']!r} must be > 0 rad/s")
            if not (0 <= p["zeta_zero"] <= MAX_NOTCH_ZETA and 0 < p["zeta_pole"] <= MAX_NOTCH_ZETA):
                raise ValueError(f"notch: needs 0 ≤ zeta_zero ≤ {MAX_NOTCH_ZETA:g} and 0 < zeta_pole ≤ "
                                 f"{MAX_NOTCH_ZETA:g}; got zeta_zero={p['zeta_zero']!r}, zeta_pole={p['zeta_pole']!r}")
        for name in ("omega", "zero", "pole"):
            if name in p and not MIN_OMEGA <= abs(p[name]) <= MAX_OMEGA:
                raise ValueError(f"{k}: {name}={p[name]!r} rad/s must have |{name}| in [{MIN_OMEGA:g}, {MAX_OMEGA:g}] rad/s")
        object.__setattr__(self, "params", p)

    def polys(self) -> tuple[np.ndarray, np.ndarray]:
        """Numerator and denominator coefficients in s, highest power first.

        Returns
        -------
        tuple of numpy.ndarray
            ``(numerator, denominator)``.
        """
        p, k = self.params, self.kind
        if k == "gain":
            return np.array([p["k"]]), np.array([1.0])
        if k == "integrator":
            return np.array([1.0]), np.r_[1.0, np.zeros(p["order"])]
        if k == "differentiator":
            return np.r_[1.0, np.zeros(p["order"])], np.array([1.0])
        if k in ("real_pole", "real_zero"):
            f = np.array([1 / p["omega"], 1.0])
            return (f, np.array([1.0])) if k == "real_zero" else (np.array([1.0]), f)
        if k in ("complex_pole", "complex_zero"):
            w = p["omega"]
            f = np.array([1 / w**2, 2 * p["zeta"] / w, 1.0])
            return (f, np.array([1.0])) if k == "complex_zero" else (np.array([1.0]), f)
        if k == "lead_lag":
            return np.array([1 / p["zero"], 1.0]), np.array([1 / p["pole"], 1.0])
        w = p["omega"]
        return np.array([1.0, 2 * p["zeta_zero"] * w, w * w]), np.array([1.0, 2 * p["zeta_pole"] * w, w * w])

    def response(self, omega: ArrayLike) -> np.ndarray:
        """Complex response at s = jω.

        Parameters
        ----------
        omega : array_like
            Frequencies, rad/s.

        Returns
        -------
        numpy.ndarray
            Complex response, shape of ``omega``.
        """
        num, den = self.polys()
        s = 1j * np.asarray(omega, float)
        return np.polyval(num, s) / np.polyval(den, s)

    def __str__(self):
        return f"{self.kind}(" + ", ".join(f"{k}={v:.6g}" for k, v in self.params.items()) + ")"


# Factories, for readable controller definitions.
def gain(k: float) -> Element:
    """A constant gain k (the only element not normalised to unit DC gain).

    Parameters
    ----------
    k : float
        Gain, finite and non-zero (may be negative).

    Returns
    -------
    Element
        The ``gain`` element.

    Examples
    --------
    >>> gain(2.0).params
    {'k': 2.0}
    """
    return Element("gain", {"k": k})


def integrator(order: int = 1) -> Element:
    """1/s^order.

    Parameters
    ----------
    order : int
        Number of integrators, 1 to :data:`MAX_ORDER`.

    Returns
    -------
    Element
        The ``integrator`` element.
    """
    return Element("integrator", {"order": order})


def differentiator(order: int = 1) -> Element:
    """s^order: the inverse of :func:`integrator`, whose ``order`` (1 to :data:`MAX_ORDER`) it takes.

    Parameters
    ----------
    order : int
        Number of differentiators.

    Returns
    -------
    Element
        ``differentiator``.
    """
    return Element("differentiator", {"order": order})


def real_pole(omega: float) -> Element:
    """1/(s/ω + 1): a real pole at s = −ω, unit DC gain.

    Parameters
    ----------
    omega : float
        Corner frequency ω, rad/s, ≠ 0 (negative: a right-half-plane pole).

    Returns
    -------
    Element
        The ``real_pole`` element.
    """
    return Element("real_pole", {"omega": omega})


def real_zero(omega: float) -> Element:
    """s/ω + 1: a real zero at s = −ω, unit DC gain (the inverse of :func:`real_pole`, whose
    ``omega`` it takes: a negative one places the zero in the right half-plane).

    Parameters
    ----------
    omega : float
        As :func:`real_pole`'s, rad/s.

    Returns
    -------
    Element
        ``real_zero``.
    """
    return Element("real_zero", {"omega": omega})


def complex_pole(omega: float, zeta: float) -> Element:
    """1/((s/ω)² + 2ζ s/ω + 1): a complex pair, unit DC gain.

    Parameters
    ----------
    omega : float
        Natural frequency ω > 0, rad/s.
    zeta : float
        Damping ratio ζ, |ζ| < 1 (negative: right-half-plane pair).

    Returns
    -------
    Element
        The ``complex_pole`` element.
    """
    return Element("complex_pole", {"omega": omega, "zeta": zeta})


def complex_zero(omega: float, zeta: float) -> Element:
    """(s/ω)² + 2ζ s/ω + 1: a complex pair of zeros, unit DC gain (the inverse of
    :func:`complex_pole`, whose ``omega`` and ``zeta`` it takes).

    Parameters
    ----------
    omega, zeta : float
        As :func:`complex_pole`'s: ω in rad/s, ζ with |ζ| < 1.

    Returns
    -------
    Element
        ``complex_zero``.
    """
    return Element("complex_zero", {"omega": omega, "zeta": zeta})


def lead_lag(zero: float, pole: float) -> Element:
    """(s/zero + 1)/(s/pole + 1): a lead when zero < pole, a lag otherwise.

    Parameters
    ----------
    zero : float
        Zero frequency, rad/s, > 0.
    pole : float
        Pole frequency, rad/s, > 0.

    Returns
    -------
    Element
        The ``lead_lag`` element.
    """
    return Element("lead_lag", {"zero": zero, "pole": pole})


def lead_from_phase(phase_deg: float, omega: float) -> Element:
    """Lead (phase_deg > 0) or lag (< 0) whose phase peaks at ω with ``phase_deg``.

    Parameters
    ----------
    phase_deg : float
        Peak phase, degrees, in (−90, 90) and non-zero.
    omega : float
        Frequency of the peak, rad/s (the geometric mean of zero and pole).

    Returns
    -------
    Element
        A ``lead_lag`` element.

    Raises
    ------
    ValueError
        If ``phase_deg`` is 0 or not within (−90, 90).

    Examples
    --------
    >>> round(lead_from_phase(30.0, 1.0).params["pole"], 4)
    1.7321
    """
    if not 0 < abs(phase_deg) < 90:
        raise ValueError(f"phase_deg={phase_deg} must be within (−90, 90) degrees and non-zero")
    sin = math.sin(math.radians(abs(phase_deg)))
    alpha = (1 + sin) / (1 - sin)
    lo, hi = omega / math.sqrt(alpha), omega * math.sqrt(alpha)
    return lead_lag(lo, hi) if phase_deg > 0 else lead_lag(hi, lo)


def notch(omega: float, zeta_zero: float, zeta_pole: float) -> Element:
    """(s² + 2ζ_z ω s + ω²)/(s² + 2ζ_p ω s + ω²): depth ζ_z/ζ_p at ω.

    Parameters
    ----------
    omega : float
        Notch frequency ω > 0, rad/s.
    zeta_zero : float
        Damping ratio ζ_z of the zeros, 0 ≤ ζ_z ≤ :data:`MAX_NOTCH_ZETA`.
    zeta_pole : float
        Damping ratio ζ_p of the poles, 0 < ζ_p ≤ :data:`MAX_NOTCH_ZETA`.

    Returns
    -------
    Element
        The ``notch`` element (gain ζ_z/ζ_p at ω, i.e. 20·log10(ζ_z/ζ_p) dB).
    """
    return Element("notch", {"omega": omega, "zeta_zero": zeta_zero, "zeta_pole": zeta_pole})


@dataclass(frozen=True)
class Controller:
    """An ordered tuple of :class:`Element`; the transfer function is their product.

    Parameters
    ----------
    elements : tuple of Element
        The factors, in order.

    Raises
    ------
    TypeError
        If an element is not an :class:`Element`.
    ValueError
        If the controller has more than :data:`MAX_DEGREE` poles or zeros.

    Examples
    --------
    >>> C = Controller((gain(10.0), integrator(), real_zero(1.0)))
    >>> C.polys()
    (array([10., 10.]), array([1., 0.]))
    """

    elements: tuple = ()

    def __post_init__(self):
        els = tuple(self.elements)
        for i, e in enumerate(els):
            if not isinstance(e, Element):
                raise TypeError(f"elements[{i}] is a {type(e).__name__}, not a loopshaping.controller.Element")
        degrees = np.array([[len(n) - 1, len(d) - 1] for n, d in (e.polys() for e in els)]).reshape(-1, 2).sum(axis=0)
        if degrees.max(initial=0) > MAX_DEGREE:
            raise ValueError(f"a controller of {degrees[1]} poles and {degrees[0]} zeros: at most {MAX_DEGREE} of each")
        object.__setattr__(self, "elements", els)

    # -- editing (new objects)
    def add(self, element: Element, index: int | None = None) -> Controller:
        """A new controller with ``element`` inserted at ``index`` (default: appended).

        Parameters
        ----------
        element : Element
            The element to insert.
        index : int, optional
            Position (as ``list.insert``); None appends.

        Returns
        -------
        Controller
            The new controller.
        """
        els = list(self.elements)
        els.insert(len(els) if index is None else index, element)
        return Controller(tuple(els))

    def replace(self, index: int, element: Element) -> Controller:
        """A new controller with element ``index`` replaced by ``element``.

        Parameters
        ----------
        index : int
            Position of the element to replace.
        element : Element
            The new element.

        Returns
        -------
        Controller
            The new controller.

        Raises
        ------
        IndexError
            If ``index`` is out of range.
        """
        self._check_index(index)
        els = list(self.elements)
        els[index] = element
        return Controller(tuple(els))

    def remove(self, index: int) -> Controller:
        """A new controller without element ``index``.

        Parameters
        ----------
        index : int
            Position of the element to remove.

        Returns
        -------
        Controller
            The new controller.

        Raises
        ------
        IndexError
            If ``index`` is out of range.
        """
        self._check_index(index)
        els = list(self.elements)
        del els[index]
        return Controller(tuple(els))

    def set(self, index: int, **params) -> Controller:
        """A new controller with some parameters of element ``index`` changed.

        Parameters
        ----------
        index : int
            Position of the element.
        **params
            New parameter values by name (rad/s for frequencies).

        Returns
        -------
        Controller
            The new controller.
        """
        self._check_index(index)
        e = self.elements[index]
        return self.replace(index, Element(e.kind, {**e.params, **params}))

    def _check_index(self, index):
        if not -len(self.elements) <= index < len(self.elements):
            raise IndexError(f"index={index} out of range for a controller of {len(self.elements)} elements")

    # -- evaluation
    def polys(self) -> tuple[np.ndarray, np.ndarray]:
        """Numerator and denominator coefficients in s, highest power first.

        Returns
        -------
        tuple of numpy.ndarray
            ``(numerator, denominator)``, the products of the elements' polynomials.
        """
        num, den = np.array([1.0]), np.array([1.0])
        for e in self.elements:
            n, d = e.polys()
            num, den = np.polymul(num, n), np.polymul(den, d)
        return num, den

    def tf(self):
        """The python-control transfer function.

        Returns
        -------
        control.TransferFunction
            The product of the elements.
        """
        import control as ct

        num, den = self.polys()
        return ct.tf(num, den)

    def response(self, omega: ArrayLike) -> np.ndarray:
        # evaluated factor by factor, not from the product polynomials of :meth:`polys`
        out = np.ones(np.shape(omega), complex)
        for e in self.elements:
            out = out * e.response(omega)
        return out

    response.__doc__ = Element.response.__doc__  # the same contract as an element's, documented once

    @property
    def is_proper(self) -> bool:
        """True if the numerator degree does not exceed the denominator degree."""
        num, den = self.polys()
        return len(np.trim_zeros(num, "f")) <= len(np.trim_zeros(den, "f"))

    # -- conversion
    @classmethod
    def from_zpk(cls, zeros, poles, k: float) -> Controller:
        """From the zeros, poles and gain of k·Π(s − z)/Π(s − p).

        Parameters
        ----------
        zeros, poles : array_like
            Roots, rad/s (complex ones in conjugate pairs).
        k : float
            The leading gain k.

        Returns
        -------
        Controller
            A ``gain`` element followed by the normalised factors.

        Raises
        ------
        ValueError
            If complex roots are not in conjugate pairs or k is 0.
        """
        elements, scale = [], float(k)
        for roots, is_zero in ((np.asarray(zeros, complex), True), (np.asarray(poles, complex), False)):
            els, f = _elements_from_roots(roots, is_zero)
            elements += els
            scale = scale * f if is_zero else scale / f
        if scale == 0:
            raise ValueError("k must be non-zero")
        return cls((gain(scale), *elements))

    @classmethod
    def from_tf(cls, sys) -> Controller:
        """From a SISO python-control LTI system, factored into elements.

        Parameters
        ----------
        sys : control LTI
            SISO transfer function or state space.

        Returns
        -------
        Controller
            Its factorisation.

        Raises
        ------
        ValueError
            If ``sys`` is not SISO, is zero (no loop to shape: a zero transfer function has no
            factors), or has a non-finite coefficient.
        """
        import control as ct

        sys = ct.tf(sys)
        if sys.ninputs != 1 or sys.noutputs != 1:
            raise ValueError("sys must be SISO")
        num, den = np.trim_zeros(sys.num[0][0], "f"), np.trim_zeros(sys.den[0][0], "f")
        if not (np.all(np.isfinite(num)) and np.all(np.isfinite(den))):
            raise ValueError(f"sys has a non-finite coefficient (num {num!r}, den {den!r})")
        if num.size == 0:
            raise ValueError("sys is zero: a zero transfer function has no factors (no loop to shape); give a "
                             "non-zero controller")
        if den.size == 0:
            raise ValueError("sys has a zero denominator")
        return cls.from_zpk(np.roots(num), np.roots(den), num[0] / den[0])

    def to_dict(self) -> dict:
        """A JSON-ready dict ``{"version": 1, "elements": [{"kind", "params"}, ...]}``.

        Returns
        -------
        dict
            The controller, read back by :meth:`from_dict`.
        """
        return {"version": _JSON_VERSION, "elements": [{"kind": e.kind, "params": dict(e.params)} for e in self.elements]}

    @classmethod
    def from_dict(cls, data: dict) -> Controller:
        """The controller of :meth:`to_dict`; every key is checked.

        Parameters
        ----------
        data : dict
            As written by :meth:`to_dict`.

        Returns
        -------
        Controller
            The controller.

        Raises
        ------
        ValueError
            For unknown keys, a wrong version or an invalid element (naming its index).
        """
        if not isinstance(data, dict) or "elements" not in data:
            raise ValueError("data must be a dict with an 'elements' list (from Controller.to_dict)")
        extra = set(data) - {"version", "elements"}
        if extra:
            raise ValueError(f"unknown controller keys {sorted(extra)}; allowed: 'version', 'elements'")
        version = data.get("version", _JSON_VERSION)
        if type(version) is not int or version != _JSON_VERSION:
            raise ValueError(f"unsupported controller format version {version!r} (this version reads the integer {_JSON_VERSION})")
        if not isinstance(data["elements"], list):
            raise ValueError(f"'elements' must be a list of {{'kind', 'params'}} objects, got {type(data['elements']).__name__}")
        out = []
        for i, e in enumerate(data["elements"]):
            if not isinstance(e, dict) or set(e) != {"kind", "params"} or not isinstance(e["params"], dict):
                raise ValueError(f"element {i}: must be an object with exactly 'kind' and 'params' (an object), got {e!r}")
            try:
                out.append(Element(e["kind"], dict(e["params"])))
            except (TypeError, ValueError) as err:
                raise ValueError(f"element {i}: {err}") from None
        return cls(tuple(out))

    def to_json(self, **kwargs) -> str:
        """JSON text; floats are written with repr precision, so the round trip is exact.

        Parameters
        ----------
        **kwargs
            Passed to :func:`json.dumps` (e.g. ``indent``).

        Returns
        -------
        str
            The JSON text of :meth:`to_dict`.
        """
        return json.dumps(self.to_dict(), **kwargs)

    @classmethod
    def from_json(cls, text: str) -> Controller:
        """The controller of :meth:`to_json`.

        Parameters
        ----------
        text : str
            JSON text.

        Returns
        -------
        Controller
            The controller (checked as by :meth:`from_dict`).
        """
        return cls.from_dict(json.loads(text))

    def __str__(self):
        return " · ".join(str(e) for e in self.elements) or "1"


def _elements_from_roots(roots, is_zero):
    """Elements for a set of roots and the factor f with Π(s − r) = f·Π(normalised factors)."""
    els, f = [], 1.0
    tol = 1e-9 * max(1.0, float(np.max(np.abs(roots), initial=0)))
    origin = np.abs(roots) <= tol
    if origin.sum():
        els.append(differentiator(int(origin.sum())) if is_zero else integrator(int(origin.sum())))
    rest = roots[~origin]
    real = rest[np.abs(rest.imag) <= 1e-9 * np.abs(rest)]
    cplx = rest[rest.imag > 1e-9 * np.abs(rest)]
    if len(real) + 2 * len(cplx) != len(rest):
        raise ValueError("complex roots must come in conjugate pairs")
    for r in np.sort(real.real):
        w = -r  # s − r = (−r)(s/ω + 1) with ω = −r
        els.append(real_zero(w) if is_zero else real_pole(w))
        f *= w
    for r in sorted(cplx, key=abs):
        wn = abs(r)
        zeta = -r.real / wn  # (s − r)(s − r̄) = ωn²((s/ωn)² + 2ζ s/ωn + 1)
        els.append(complex_zero(wn, zeta) if is_zero else complex_pole(wn, zeta))
        f *= wn * wn
    return els, f
