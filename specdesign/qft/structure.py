"""The fixed structures of the automatic QFT design and their parameter vector.

    C_β(s)   = k·(s + z)/s · (s² + 2ζ_n ω_n s + ω_n²)/ω_n² · ω_d²/(s² + 2ζ_d ω_d s + ω_d²)
                           · ω_f²/(s² + 2ζ_f ω_f s + ω_f²),      k < 0
    C_atd(s) = k_a·(s/z_a + 1)/(s/p_a + 1),                        k_a < 0

The tuner works on a vector x of the 11 parameters, frequencies and gains in logarithms
(:data:`LOG_SCALED`), inside [:data:`LOWER`, :data:`UPPER`] (rad/s, -, and |k| in rad per rad/s).

Parameter units: ``k`` rad per rad/s (pitch per generator speed), ``k_atd`` rad per m/s (pitch
per tower-top velocity), ``z``, ``omega_*``, ``z_atd``, ``p_atd`` rad/s, ``zeta_*`` damping
ratios (-). The sign convention is the workbench's, β = −C_β·Ω_g − C_atd·ẋ_top, so both gains
are negative; the vector holds their magnitudes.
"""
from __future__ import annotations

from collections.abc import Mapping

import control as ct
import numpy as np
from numpy.typing import ArrayLike

__all__ = ["PARAMETER_NAMES", "LOG_SCALED", "LOWER", "UPPER", "to_vector", "from_vector", "controller_polys",
           "controllers", "rosco_start", "vector_bounds", "three_p_notch", "rolloff", "filter_polys"]

#: Names of the 11 parameters, in the order of the vector x.
PARAMETER_NAMES = ("k", "z", "omega_n", "zeta_n", "omega_d", "zeta_d", "omega_f", "zeta_f", "k_atd", "z_atd", "p_atd")
#: Which entries of x are logarithms (frequencies and gain magnitudes) rather than the value (damping ratios).
LOG_SCALED = np.array([True, True, True, False, True, False, True, False, True, True, True])
#: Lower and upper limits of the parameters (values, not logarithms; |k| and |k_atd| for the gains).
LOWER = np.array([1e-3, 0.01, 0.05, 0.1, 0.05, 0.3, 0.3, 0.3, 1e-4, 0.05, 0.02])
UPPER = np.array([10.0, 5.0, 10.0, 1.5, 5.0, 1.5, 5.0, 1.2, 2.0, 20.0, 20.0])


def to_vector(params: Mapping[str, float]) -> np.ndarray:
    """Pack controller parameters into the tuner's vector x.

    Parameters
    ----------
    params : mapping of str to float
        Every name of :data:`PARAMETER_NAMES`: gains ``k`` (rad per rad/s) and ``k_atd``
        (rad per m/s), of either sign (their magnitudes are used), frequencies in rad/s and
        damping ratios (-).

    Returns
    -------
    numpy.ndarray
        The vector x, shape (11,): natural logarithms of the :data:`LOG_SCALED` entries, the others as given.

    Raises
    ------
    KeyError
        If a name of :data:`PARAMETER_NAMES` is missing from ``params``.

    Examples
    --------
    >>> from specdesign.qft.structure import from_vector, to_vector
    >>> p = dict(k=-0.1, z=0.4, omega_n=1.0, zeta_n=0.7, omega_d=1.0, zeta_d=0.7, omega_f=1.0,
    ...          zeta_f=0.7, k_atd=-0.02, z_atd=4.0, p_atd=0.3)
    >>> round(from_vector(to_vector(p))["k"], 12)
    -0.1
    """
    p = np.array([abs(params[n]) if n in ("k", "k_atd") else params[n] for n in PARAMETER_NAMES], float)
    return np.where(LOG_SCALED, np.log(p), p)


def from_vector(x: ArrayLike) -> dict[str, float]:
    """Unpack the tuner's vector x into named controller parameters.

    Parameters
    ----------
    x : array_like
        Parameter vector, shape (11,), as made by :func:`to_vector`.

    Returns
    -------
    dict of str to float
        :data:`PARAMETER_NAMES` → value; the gains ``k`` (rad per rad/s) and ``k_atd`` (rad
        per m/s) negative (β = −C_β·Ω_g − C_atd·ẋ_top), frequencies in rad/s, damping ratios (-).

    Examples
    --------
    >>> import numpy as np
    >>> from specdesign.qft.structure import from_vector
    >>> p = from_vector(np.zeros(11))
    >>> p["k"], p["zeta_n"], p["z_atd"]
    (-1.0, 0.0, 1.0)
    """
    p = np.where(LOG_SCALED, np.exp(x), x)
    out = dict(zip(PARAMETER_NAMES, map(float, p)))
    out["k"], out["k_atd"] = -out["k"], -out["k_atd"]
    return out


def controller_polys(x: ArrayLike, measurement_filter: tuple | None = None
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Numerator and denominator polynomials of C_β and C_atd for a parameter vector.

    Parameters
    ----------
    x : array_like
        Parameter vector, shape (11,) (:func:`to_vector`).
    measurement_filter : (numpy.ndarray, numpy.ndarray), optional
        Numerator and denominator (descending powers of s) of a fixed filter F(s) on both
        measurements (e.g. :func:`three_p_notch`): both controllers are multiplied by it.

    Returns
    -------
    nb, db : numpy.ndarray
        Coefficients (descending powers of s) of C_β = nb/db, generator speed (rad/s) → pitch
        (rad): degree 3 over degree 5 (integrator, notch-like pair, two low-pass pairs).
    na, da : numpy.ndarray
        Coefficients of C_atd = na/da, tower-top velocity (m/s) → pitch (rad): the lead-lag
        k_a·(s/z_a + 1)/(s/p_a + 1).

    Examples
    --------
    >>> import numpy as np
    >>> from specdesign.qft.structure import controller_polys
    >>> [len(c) for c in controller_polys(np.zeros(11))]
    [4, 6, 2, 2]
    """
    p = from_vector(x)
    wn, wd, wf = p["omega_n"], p["omega_d"], p["omega_f"]
    nb = p["k"] * np.polymul([1.0, p["z"]], np.array([1.0, 2 * p["zeta_n"] * wn, wn * wn]) / wn**2) * wd**2 * wf**2
    db = np.polymul(np.polymul([1.0, 0.0], [1.0, 2 * p["zeta_d"] * wd, wd * wd]), [1.0, 2 * p["zeta_f"] * wf, wf * wf])
    na = p["k_atd"] * np.array([1.0 / p["z_atd"], 1.0])
    da = np.array([1.0 / p["p_atd"], 1.0])
    if measurement_filter is not None:
        fn, fd = measurement_filter
        nb, db, na, da = np.polymul(nb, fn), np.polymul(db, fd), np.polymul(na, fn), np.polymul(da, fd)
    return nb, db, na, da


def controllers(x: ArrayLike, v: float, measurement_filter: tuple | None = None
                ) -> tuple[ct.TransferFunction, ct.TransferFunction]:
    """The two controllers of a parameter vector as named python-control transfer functions.

    Parameters
    ----------
    x : array_like
        Parameter vector, shape (11,) (:func:`to_vector`).
    v : float
        Wind speed of the design, m/s (only used in the systems' names).
    measurement_filter : (numpy.ndarray, numpy.ndarray), optional
        A fixed filter on both measurements, included in both controllers (:func:`controller_polys`).

    Returns
    -------
    cb : control.TransferFunction
        C_β, input ``gen_speed`` (rad/s), output ``pitch_cmd`` (rad), named ``QFT_pitch@<v>mps``.
    ca : control.TransferFunction
        C_atd, input ``tower_top_vel`` (m/s), output ``pitch_cmd`` (rad), named ``QFT_ATD@<v>mps``.
        Both in the workbench sign β = −C_β·Ω_g − C_atd·ẋ_top.

    Examples
    --------
    >>> import numpy as np
    >>> from specdesign.qft.structure import controllers
    >>> cb, ca = controllers(np.zeros(11), 19.0)
    >>> cb.name, ca.name, ca.input_labels
    ('QFT_pitch@19mps', 'QFT_ATD@19mps', ['tower_top_vel'])
    """
    nb, db, na, da = controller_polys(x, measurement_filter)
    tag = f"{v:g}mps".replace(".", "p")
    cb = ct.tf(nb, db, inputs="gen_speed", outputs="pitch_cmd", name=f"QFT_pitch@{tag}")
    ca = ct.tf(na / da[0], da / da[0], inputs="tower_top_vel", outputs="pitch_cmd", name=f"QFT_ATD@{tag}")
    return cb, ca


def rosco_start(rosco: ct.TransferFunction) -> np.ndarray:
    """Parameters reproducing ROSCO's C = (Kp + Ki/s)·ω_f²/(s² + 2ζω_f s + ω_f²), weak ATD.

    The tuner's start: the PI and the speed filter of ROSCO, the notch-like pair and the
    first low-pass pair cancelling (ω_n = ω_d = 1 rad/s, ζ = 0.7), and a weak ATD
    (k_a = −0.02 rad per m/s, z_a = 4 rad/s, p_a = 0.3 rad/s). When ROSCO's fitted Kp is
    positive (a right-half-plane PI zero, at high wind speeds) the start keeps its Ki with a
    PI zero at 0.2 rad/s instead. The vector is clipped to :func:`vector_bounds`.

    Parameters
    ----------
    rosco : control.TransferFunction
        ROSCO's SISO controller, generator speed (rad/s) → pitch (rad), in the workbench sign
        (negative gains), e.g. :func:`specdesign.turbine.rosco_baseline`: numerator
        (Kp·s + Ki)·ω_f², denominator s·(s² + 2ζω_f s + ω_f²).

    Returns
    -------
    numpy.ndarray
        Parameter vector x, shape (11,) (:func:`from_vector` names it).

    Examples
    --------
    >>> import control as ct
    >>> from specdesign.qft.structure import from_vector, rosco_start
    >>> rosco = ct.tf([-0.113, -0.04409], [1, 1.411, 1.016, 0])  # ROSCO at 19 m/s
    >>> p = from_vector(rosco_start(rosco))
    >>> round(p["k"], 4), round(p["z"], 4), round(p["omega_f"], 3)
    (-0.1112, 0.3902, 1.008)
    """
    num, den = np.asarray(rosco.num[0][0], float), np.asarray(rosco.den[0][0], float)
    wf2 = den[-2]
    kp, ki = num[-2] / wf2, num[-1] / wf2
    wf = np.sqrt(wf2)
    zf = den[1] / (2 * wf)
    if not (kp < 0 and ki < 0):
        # ROSCO's fitted Kp turns positive at high wind speeds (a right-half-plane PI zero):
        # start from its integral gain with a left-half-plane zero at 0.2 rad/s instead
        kp = ki / 0.2
    start = dict(k=kp, z=ki / kp, omega_n=1.0, zeta_n=0.7, omega_d=1.0, zeta_d=0.7, omega_f=wf, zeta_f=zf,
                 k_atd=-0.02, z_atd=4.0, p_atd=0.3)
    return np.clip(to_vector(start), vector_bounds()[0], vector_bounds()[1])


def vector_bounds() -> tuple[np.ndarray, np.ndarray]:
    """Box limits of the parameter vector x (:data:`LOWER`, :data:`UPPER` in x's scaling).

    Returns
    -------
    lower, upper : numpy.ndarray
        Shape (11,) each: logarithms of the limits for the :data:`LOG_SCALED` entries, the
        limits themselves for the damping ratios.

    Examples
    --------
    >>> import numpy as np
    >>> from specdesign.qft.structure import vector_bounds
    >>> lower, upper = vector_bounds()
    >>> lower.shape, bool(np.all(lower < upper))
    ((11,), True)
    """
    return np.where(LOG_SCALED, np.log(LOWER), LOWER), np.where(LOG_SCALED, np.log(UPPER), UPPER)


def three_p_notch(model, depth_db: float = 20.0, zeta_pole: float = 0.5) -> ct.TransferFunction:
    """A notch at the rotor's 3P on the measurements, F(s) = (s² + 2ζ_z ω s + ω²)/(s² + 2ζ_p ω s + ω²).

    In OpenFAST the rotational sampling of the turbulence puts 3P into generator speed and
    tower-top motion, which the linear models lack; a controller with gain there turns it into
    pitch activity that buys nothing for the tower (docs/openfast.md: 53-82 % of QFT+ATD's
    pitch-rate variance is at 3P and above). ROSCO offers the same filter on its generator-speed
    measurement (``F_NotchFreqs``, ``F_GenSpdNotch_N``; its tower-top notch does not reach its
    tower damper). Unit gain at 0 and ∞.

    Parameters
    ----------
    model : specdesign.turbine.TurbineModel or specdesign.openfast.LinearTurbine
        The turbine: ω = 3·``rated_rotor_speed`` (rad/s), the rotor speed the pitch loop holds.
    depth_db : float, default 20.0
        Attenuation at ω, dB (> 0): ζ_z = ζ_p·10^(−depth/20).
    zeta_pole : float, default 0.5
        ζ_p, the notch's width (0 < ζ_p ≤ 1): 0.5 attenuates the 3P band 2.2-2.6 rad/s of the
        IEA 15 MW by ≥ 13 dB, at ≈ 27° of phase lag at its tower mode (1.1 rad/s).

    Returns
    -------
    control.TransferFunction
        F, named ``3P_notch``.

    Raises
    ------
    ValueError
        ``model`` has no finite ``rated_rotor_speed``, or ``depth_db``/``zeta_pole`` out of range.

    Examples
    --------
    >>> from specdesign.qft import three_p_notch
    >>> from specdesign.turbine import iea15mw
    >>> f = three_p_notch(iea15mw())
    >>> w3 = 3 * iea15mw().rated_rotor_speed
    >>> round(float(abs(f(1j * w3))), 6), round(float(abs(f(0))), 6)
    (0.1, 1.0)
    """
    w3 = 3.0 * float(getattr(model, "rated_rotor_speed", np.nan))
    if not (np.isfinite(w3) and w3 > 0):
        raise ValueError(f"model has no finite rated_rotor_speed ({w3 / 3!r} rad/s): pass a turbine that has one, "
                         "or a filter of your own as measurement_filter")
    if not (np.isfinite(depth_db) and depth_db > 0):
        raise ValueError(f"depth_db={depth_db!r} must be a finite attenuation > 0 dB")
    if not (0 < zeta_pole <= 1):
        raise ValueError(f"zeta_pole={zeta_pole!r} must be in (0, 1] (the notch's width)")
    zeta_zero = zeta_pole * 10 ** (-depth_db / 20)
    return ct.tf([1.0, 2 * zeta_zero * w3, w3 * w3], [1.0, 2 * zeta_pole * w3, w3 * w3], name="3P_notch")


def rolloff(omega: float, zeta: float = 2**-0.5) -> ct.TransferFunction:
    """A second-order low-pass on the measurements, ω²/(s² + 2ζω s + ω²) (unit gain at 0).

    The 3P notch leaves what lies above 3P: in OpenFAST the paper's structure with it still spends
    41 % of its pitch-rate variance at 5-20 rad/s (the lead-lag ATD's gain is flat there,
    docs/openfast.md). Multiply it in: ``qft.three_p_notch(model) * qft.rolloff(4.0)``.

    Parameters
    ----------
    omega : float
        Corner frequency, rad/s (> 0; above the tower mode and 3P, e.g. 4 rad/s on the IEA 15 MW:
        −16 dB at 10 rad/s, 23° of phase lag at the tower mode, 1.1 rad/s).
    zeta : float, default 1/√2
        Damping ratio (> 0; Butterworth by default).

    Returns
    -------
    control.TransferFunction
        The filter, named ``rolloff``.

    Raises
    ------
    ValueError
        ``omega`` or ``zeta`` not finite and positive.

    Examples
    --------
    >>> from specdesign.qft import rolloff
    >>> f = rolloff(4.0)
    >>> round(float(abs(f(0))), 6), round(float(20 * np.log10(abs(f(10j)))), 1)
    (1.0, -16.0)
    """
    for name, val in (("omega", omega), ("zeta", zeta)):
        if not (np.isfinite(val) and val > 0):
            raise ValueError(f"{name}={val!r} must be finite and > 0 ({'rad/s' if name == 'omega' else '-'})")
    return ct.tf([omega * omega], [1.0, 2 * zeta * omega, omega * omega], name="rolloff")


def filter_polys(measurement_filter, name: str = "measurement_filter") -> tuple[np.ndarray, np.ndarray] | None:
    """A fixed measurement filter as (numerator, denominator) polynomials, checked at the door.

    Parameters
    ----------
    measurement_filter : control.LTI or None
        SISO, continuous, proper, stable, with a finite nonzero gain at 0 (it multiplies the
        integral action).
    name : str
        The argument's name in the messages.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray) or None
        Descending powers of s, the denominator monic; None for None.

    Raises
    ------
    TypeError
        Not a python-control system.
    ValueError
        Not SISO, discrete, improper, unstable, or with a zero or infinite gain at 0.
    """
    if measurement_filter is None:
        return None
    if not isinstance(measurement_filter, ct.LTI):
        raise TypeError(f"{name} must be a control.TransferFunction or StateSpace (e.g. qft.three_p_notch(model)), "
                        f"got {type(measurement_filter).__name__}")
    if measurement_filter.ninputs != 1 or measurement_filter.noutputs != 1:
        raise ValueError(f"{name} must be SISO (one filter on each measurement), got "
                         f"{measurement_filter.noutputs}×{measurement_filter.ninputs}")
    if not measurement_filter.isctime(strict=True):
        raise ValueError(f"{name} must be continuous-time (dt=0): the tuner works in s")
    f = ct.tf(measurement_filter)
    num, den = np.trim_zeros(np.asarray(f.num[0][0], float), "f"), np.trim_zeros(np.asarray(f.den[0][0], float), "f")
    if num.size > den.size:
        raise ValueError(f"{name} is improper (numerator degree {num.size - 1} > denominator {den.size - 1}): "
                         "add poles above the band")
    poles = np.roots(den)
    if poles.size and poles.real.max() >= 0:
        raise ValueError(f"{name} has poles at or right of the imaginary axis ({poles[poles.real >= 0]}): "
                         "a measurement filter must be stable")
    dc = num[-1] / den[-1]  # den[-1] ≠ 0: no pole at 0 passed the stability check
    if dc == 0:
        raise ValueError(f"{name} has gain {float(dc)!r} at 0: it multiplies the integral action, so it must be finite and nonzero")
    return num / den[0], den / den[0]
