"""A SISO controller in modal parameters, with the analytic derivatives the multi-model H∞ step uses.

C(s) = Σ residue/(s − pole) + D, poles as an integrator (s = 0, kept), real poles and complex
pairs. A stable pole's real part is parametrised by its logarithm (−exp(·) stays stable), an
unstable one (an H∞ controller may have one) by its value, an imaginary part by its logarithm.
C(jω) is linear in the residues and the feedthrough and rational in the poles, so its
derivatives are closed-form (:func:`modal_response`); those of the block-diagonal state space
(:func:`modal_matrices_jacobian`) are exact by the complex step. Units: ω in rad/s, poles in
rad/s, the controller's gain as given (rad per rad/s for C_β).
"""
from __future__ import annotations

import control as ct
import numpy as np
from scipy.linalg import block_diag

__all__ = ["INTEGRATOR_TOL", "modal_bounds", "modal_matrices", "modal_matrices_jacobian", "modal_parameters",
           "modal_response"]

#: Below this |λ| (rad/s) a controller pole is its integrator, kept at s = 0 exactly.
INTEGRATOR_TOL = 1e-6
#: Step of the complex-step derivative of :func:`modal_matrices` (exact to round-off at any step).
_COMPLEX_STEP = 1e-30


def modal_parameters(k: ct.LTI) -> tuple[tuple[str, ...], np.ndarray] | None:
    """A SISO controller as (kinds, x), or None when its A is defective (eigenvectors ill-conditioned).

    Kinds: ``"i"`` an integrator (x: residue); ``"r"`` a stable real pole (log(−λ), residue);
    ``"c"`` a stable complex pair (log(−Re λ), log(Im λ), residue re, im); ``"ru"``/``"cu"``
    the same with Re λ ≥ 0, whose real part is a parameter as it is. Ordered by |λ|; x ends
    with the feedthrough D.

    Parameters
    ----------
    k : control.LTI
        A SISO controller.

    Returns
    -------
    tuple or None
        (kinds, x): tuple of str and numpy.ndarray of float.

    Examples
    --------
    >>> import control as ct
    >>> from specdesign.hinf.modal import modal_parameters
    >>> kinds, x = modal_parameters(ct.ss(ct.tf([1.0, 2.0], [1.0, 1.0, 0.0])))
    >>> kinds, round(float(x[-1]), 12)
    (('i', 'r'), 0.0)
    """
    k = ct.ss(k)
    lam, vec = np.linalg.eig(np.asarray(k.A, float))
    if np.linalg.cond(vec) > 1e8:
        return None
    res = (np.asarray(k.C, float) @ vec).ravel() * np.linalg.solve(vec, np.asarray(k.B, float)).ravel()
    idx = np.argsort(np.abs(lam) + 1e-12 * lam.imag, kind="stable")
    kinds, x, used = [], [], set()
    for i in idx:
        if i in used:
            continue
        used.add(i)
        lam_i, r = lam[i], res[i]
        if abs(lam_i) < INTEGRATOR_TOL:
            kinds.append("i")
            x.append(r.real)
        elif abs(lam_i.imag) <= 1e-9 * abs(lam_i):
            kinds.append("r" if lam_i.real < 0 else "ru")
            x += [np.log(-lam_i.real) if lam_i.real < 0 else lam_i.real, r.real]
        else:
            j = min((j for j in idx if j not in used), key=lambda j: abs(lam[j] - np.conj(lam_i)))
            used.add(j)
            if lam_i.imag < 0:
                lam_i, r = np.conj(lam_i), np.conj(r)
            kinds.append("c" if lam_i.real < 0 else "cu")
            x += [np.log(-lam_i.real) if lam_i.real < 0 else lam_i.real, np.log(lam_i.imag), r.real, r.imag]
    return tuple(kinds), np.array(x + [float(np.asarray(k.D).ravel()[0])])


def _real_part(kind, value):
    """Re λ and dRe λ/d(value)."""
    if kind.endswith("u"):
        return value, 1.0
    e = np.exp(value)
    return -e, -e


def modal_response(kinds: tuple[str, ...], x: np.ndarray, s: np.ndarray,
                   jacobian: bool = False) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """C(s) of the modal parameters, and optionally dC(s)/dx.

    Parameters
    ----------
    kinds, x
        The modal form, as :func:`modal_parameters` returns it.
    s : numpy.ndarray
        Complex frequencies, e.g. jω with ω in rad/s, shape (n,).
    jacobian : bool
        Also return the derivatives.

    Returns
    -------
    c : numpy.ndarray
        C(s), complex, shape (n,).
    jac : numpy.ndarray
        With ``jacobian``: dC(s)/dx, complex, shape (n, x.size).

    Examples
    --------
    >>> import numpy as np
    >>> from specdesign.hinf.modal import modal_response
    >>> c, jac = modal_response(("r",), np.array([0.0, 2.0, 0.5]), np.array([1j]), jacobian=True)
    >>> np.round(c, 6), np.round(jac[0, 1], 6)  # 2/(j + 1) + 0.5; d/d residue = 1/(j + 1)
    (array([1.5-1.j]), np.complex128(0.5-0.5j))
    """
    s = np.asarray(s)
    out = np.zeros(s.shape, complex)
    jac = np.zeros((s.size, x.size), complex) if jacobian else None
    p = 0
    for kind in kinds:
        if kind == "i":
            out += x[p] / s
            if jacobian:
                jac[:, p] = 1 / s
            p += 1
        elif kind in ("r", "ru"):
            re, dre = _real_part(kind, x[p])
            q = 1 / (s - re)
            out += x[p + 1] * q
            if jacobian:
                jac[:, p], jac[:, p + 1] = x[p + 1] * q * q * dre, q
            p += 2
        else:
            re, dre = _real_part(kind, x[p])
            im = np.exp(x[p + 1])
            r = x[p + 2] + 1j * x[p + 3]
            q, qc = 1 / (s - (re + 1j * im)), 1 / (s - (re - 1j * im))
            out += r * q + np.conj(r) * qc
            if jacobian:
                # d/dλ of r/(s − λ) is r/(s − λ)²; λ = Re λ + j·Im λ and its conjugate move together
                a, b = r * q * q, np.conj(r) * qc * qc
                jac[:, p] = (a + b) * dre
                jac[:, p + 1] = 1j * (a - b) * im
                jac[:, p + 2], jac[:, p + 3] = q + qc, 1j * (q - qc)
            p += 4
    out += x[p]
    if jacobian:
        jac[:, p] = 1.0
        return out, jac
    return out


def modal_matrices(kinds: tuple[str, ...], x: np.ndarray) -> tuple[np.ndarray, ...]:
    """Real block-diagonal (A, B, C, D) of the modal parameters (complex for a complex ``x``).

    Parameters
    ----------
    kinds : tuple of str
        From :func:`modal_parameters`.
    x : numpy.ndarray
        The parameters.

    Returns
    -------
    tuple of numpy.ndarray
        A (n, n), B (n, 1), C (1, n), D (1, 1).

    Examples
    --------
    >>> import numpy as np
    >>> from specdesign.hinf.modal import modal_matrices
    >>> [m.tolist() for m in modal_matrices(("i",), np.array([3.0, 0.5]))]
    [[[0.0]], [[1.0]], [[3.0]], [[0.5]]]
    """
    dtype = np.result_type(x, float)
    blocks, bs, cs, p = [], [], [], 0
    for kind in kinds:
        if kind == "i":
            blocks.append(np.zeros((1, 1), dtype)), bs.append([1.0]), cs.append([x[p]])
            p += 1
        elif kind in ("r", "ru"):
            blocks.append(np.array([[_real_part(kind, x[p])[0]]], dtype)), bs.append([1.0]), cs.append([x[p + 1]])
            p += 2
        else:
            sg, om, rr, ri = _real_part(kind, x[p])[0], np.exp(x[p + 1]), x[p + 2], x[p + 3]
            # r/(s − λ) + c.c. = (2·rr·s − 2(rr·σ + ri·ω))/((s − σ)² + ω²): the block [[σ, ω], [−ω, σ]]
            blocks.append(np.array([[sg, om], [-om, sg]], dtype)), bs.append([0.0, 1.0]), cs.append([-2 * ri, 2 * rr])
            p += 4
    a = block_diag(*blocks) if blocks else np.zeros((0, 0), dtype)
    b = np.concatenate(bs)[:, None].astype(dtype) if bs else np.zeros((0, 1), dtype)
    c = np.array(np.concatenate(cs)[None, :], dtype) if cs else np.zeros((1, 0), dtype)
    return a, b, c, np.array([[x[p]]], dtype)


def modal_matrices_jacobian(kinds: tuple[str, ...], x: np.ndarray) -> list[tuple[np.ndarray, ...]]:
    """d(A, B, C, D)/dx_k of :func:`modal_matrices` for every parameter k (complex step: exact).

    Parameters
    ----------
    kinds, x
        The modal form, as :func:`modal_parameters` returns it.

    Returns
    -------
    list of tuple of numpy.ndarray
        One (dA, dB, dC, dD) per parameter, real.

    Examples
    --------
    >>> import numpy as np
    >>> from specdesign.hinf.modal import modal_matrices_jacobian
    >>> float(modal_matrices_jacobian(("r",), np.array([0.0, 2.0, 0.5]))[0][0][0, 0])  # d(−exp(u))/du at 0
    -1.0
    """
    out = []
    for k in range(x.size):
        xc = x.astype(complex)
        xc[k] += 1j * _COMPLEX_STEP
        out.append(tuple(m.imag / _COMPLEX_STEP for m in modal_matrices(kinds, xc)))
    return out


def modal_bounds(kinds: tuple[str, ...], x: np.ndarray, max_rate: float) -> list[tuple[float | None, float | None]]:
    """Bounds for an optimiser: every pole's |Re λ| and Im λ at most ``max_rate`` (rad/s, raised
    to what ``x`` already has), residues and feedthrough free.

    Without them a real pole can run off to −∞ with its residue (r/(s − λ) → a constant, the
    same response on any finite grid): the optimiser once left one at −7·10¹⁴ rad/s, a controller
    no sampled implementation can run.

    Parameters
    ----------
    kinds, x
        The modal form, as :func:`modal_parameters` returns it.
    max_rate : float
        Largest |Re λ| and Im λ allowed, rad/s (> 0).

    Returns
    -------
    list of tuple
        (lower, upper) per parameter, None for unbounded (scipy.optimize.minimize's form).

    Examples
    --------
    >>> import numpy as np
    >>> from specdesign.hinf.modal import modal_bounds
    >>> b = modal_bounds(("r",), np.array([0.0, 2.0, 0.5]), 100.0)
    >>> round(b[0][1], 4), b[1], b[2]  # log(100) on log(−λ); residue and D free
    (4.6052, (None, None), (None, None))
    """
    if not (np.isfinite(max_rate) and max_rate > 0):
        raise ValueError(f"max_rate={max_rate!r} must be a positive rate in rad/s")
    log_max = float(np.log(max_rate))
    out, p = [], 0
    for kind in kinds:
        if kind == "i":
            out.append((None, None))
            p += 1
            continue
        if kind.endswith("u"):  # real part as is: bounded below
            re = (min(-max_rate, float(x[p])), None)
        else:  # log(−Re λ)
            re = (None, max(log_max, float(x[p])))
        out.append(re)
        if kind.startswith("c"):
            out += [(None, max(log_max, float(x[p + 1]))), (None, None), (None, None)]
            p += 4
        else:
            out.append((None, None))
            p += 2
    return out + [(None, None)]
