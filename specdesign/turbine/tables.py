"""The shipped IEA 15 MW data and the rotor-table preparation for the compiled kernel.

Reads ``specdesign/data/iea15mw`` (package data, through :mod:`importlib.resources`, so it
resolves from an installed wheel) and turns the Cp/Ct tables into the per-cell bicubic
coefficients :func:`specdesign.turbine.kernel.bicubic` evaluates.
"""
from __future__ import annotations

from importlib import resources

import numpy as np

__all__ = ["DATA_DIR", "read_text", "read_rotor_table", "uniform_step", "HERMITE", "bicubic_coefficients"]

#: Folder of the model's data inside the ``specdesign`` package.
DATA_DIR = "data/iea15mw"


def read_text(name: str) -> str:
    """Text of a file of the shipped IEA 15 MW data (package data, also from an installed wheel).

    Parameters
    ----------
    name : str
        File name inside ``specdesign/data/iea15mw``.

    Returns
    -------
    str
        The file's text.

    Raises
    ------
    FileNotFoundError
        If there is no such file.

    Examples
    --------
    >>> "air_density_kg_m3" in read_text("parameters.json")
    True
    """
    return resources.files("specdesign").joinpath(f"{DATA_DIR}/{name}").read_text()


def read_rotor_table() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Parse the shipped ROSCO-format Cp/Ct/Cq text table (``Cp_Ct_Cq.IEA15MW.txt``).

    Returns
    -------
    tsr : numpy.ndarray
        (n_tsr,) tip-speed ratios (-).
    pitch : numpy.ndarray
        (n_pitch,) blade pitch (deg).
    cp : numpy.ndarray
        (n_tsr, n_pitch) power coefficients (-).
    ct : numpy.ndarray
        (n_tsr, n_pitch) thrust coefficients (-).
    """
    lines = read_text("Cp_Ct_Cq.IEA15MW.txt").splitlines()
    pitch = tsr = None
    blocks = {}
    i = 0
    while i < len(lines):
        line = lines[i].strip().lower()
        if line.startswith("# pitch angle vector"):
            pitch = np.array(lines[i + 1].split(), float)
        elif line.startswith("# tsr vector"):
            tsr = np.array(lines[i + 1].split(), float)
        elif line.startswith("#") and "coefficient" in line:
            key = line.split()[1][:2]  # "po", "th", "to"
            rows = []
            j = i + 1
            while len(rows) < len(tsr):
                if lines[j].strip():
                    rows.append(np.array(lines[j].split(), float))
                j += 1
            blocks[key] = np.array(rows)
            i = j
            continue
        i += 1
    return tsr, pitch, blocks["po"], blocks["th"]


def uniform_step(grid: np.ndarray, name: str) -> float:
    """The spacing of a uniform grid (the compiled interpolant needs uniform axes).

    Parameters
    ----------
    grid : numpy.ndarray
        1-D increasing grid.
    name : str
        Name of the axis, for the error message.

    Returns
    -------
    float
        The step, in the units of ``grid``.

    Raises
    ------
    ValueError
        If the grid is not uniform.
    """
    step = np.diff(grid)
    if not np.allclose(step, step[0], rtol=1e-9, atol=1e-12):
        raise ValueError(f"the {name} axis of the rotor table must be uniform for the compiled interpolant")
    return float(step[0])


#: Hermite basis: for a cubic on [0, 1] with values f0, f1 and slopes d0, d1, the monomial
#: coefficients are HERMITE @ [f0, f1, d0, d1].
HERMITE = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [-3.0, 3.0, -2.0, -1.0], [2.0, -2.0, 1.0, 1.0]])


def bicubic_coefficients(tsr: np.ndarray, pitch_rad: np.ndarray, table: np.ndarray) -> tuple[np.ndarray, object]:
    """Per-cell bicubic coefficients reproducing the interpolating cubic spline of ``table``.

    The coefficients a[i, j, k, l] (f = Σ a_kl u^k v^l in cell (i, j), u and v in [0, 1])
    reproduce the interpolating tensor-product cubic spline of ``table`` (scipy
    RectBivariateSpline, s=0). Within each cell that spline is one bicubic polynomial, fixed by
    f, f_u, f_v, f_uv at the four corners; Hermite patches built from those corner values
    reproduce it exactly, so the compiled kernel evaluates the same C2 surface scipy fits.

    Parameters
    ----------
    tsr : numpy.ndarray
        (n_tsr,) uniform tip-speed-ratio grid (-).
    pitch_rad : numpy.ndarray
        (n_pitch,) uniform pitch grid (rad).
    table : numpy.ndarray
        (n_tsr, n_pitch) coefficient table (Cp or Ct, -).

    Returns
    -------
    coefficients : numpy.ndarray
        (n_tsr − 1, n_pitch − 1, 4, 4) patch coefficients.
    spline : scipy.interpolate.RectBivariateSpline
        The spline they reproduce.
    """
    from scipy.interpolate import RectBivariateSpline

    spl = RectBivariateSpline(tsr, pitch_rad, table, kx=3, ky=3, s=0)
    du = tsr[1] - tsr[0]
    dv = pitch_rad[1] - pitch_rad[0]
    f = spl(tsr, pitch_rad)
    fu = spl(tsr, pitch_rad, dx=1) * du
    fv = spl(tsr, pitch_rad, dy=1) * dv
    fuv = spl(tsr, pitch_rad, dx=1, dy=1) * du * dv
    # Corner matrix G[i, j] = [[f00, f01, fv00, fv01], [f10, f11, fv10, fv11], [fu.., ..], [fuv..]]
    # in the ordering of HERMITE: rows (value at u=0, value at u=1, slope at u=0, slope at u=1).
    def corners(a):
        return np.stack([a[:-1, :-1], a[:-1, 1:], a[1:, :-1], a[1:, 1:]], -1)  # 00, 01, 10, 11

    c_f, c_fu, c_fv, c_fuv = corners(f), corners(fu), corners(fv), corners(fuv)
    g = np.empty(f[:-1, :-1].shape + (4, 4))
    # rows: f(u=0), f(u=1), f_u(u=0), f_u(u=1); columns: same for v.
    g[..., 0, 0], g[..., 0, 1], g[..., 0, 2], g[..., 0, 3] = c_f[..., 0], c_f[..., 1], c_fv[..., 0], c_fv[..., 1]
    g[..., 1, 0], g[..., 1, 1], g[..., 1, 2], g[..., 1, 3] = c_f[..., 2], c_f[..., 3], c_fv[..., 2], c_fv[..., 3]
    g[..., 2, 0], g[..., 2, 1], g[..., 2, 2], g[..., 2, 3] = c_fu[..., 0], c_fu[..., 1], c_fuv[..., 0], c_fuv[..., 1]
    g[..., 3, 0], g[..., 3, 1], g[..., 3, 2], g[..., 3, 3] = c_fu[..., 2], c_fu[..., 3], c_fuv[..., 2], c_fuv[..., 3]
    return HERMITE @ g @ HERMITE.T, spl
