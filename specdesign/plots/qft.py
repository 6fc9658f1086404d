"""QFT design figures: the paper's Fig. 7 analogue (Bode magnitudes ROSCO vs spec vs QFT)
and its Figs. 5-6 analogue (Nichols charts with the bounds).

Magnitudes in dB, phases in degrees, ω in rad/s.
"""
from __future__ import annotations

import warnings
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from loopshaping import nichols
from loopshaping import qft as lqft
from loopshaping.freqresp import is_zero

from .. import closedloop
from ..feasibility import HF_END, HF_OMEGA, hf_gain_bound
from ..turbine import iea15mw

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from ..qft import QFTDesign
    from ..turbine import TurbineModel

__all__ = ["plot_design_bode", "plot_design_nichols"]


def _verdict(design_db, spec_db, w, name):
    """Whether a nominal closed-loop magnitude stays below a specification on the grid ``w``."""
    excess = design_db - spec_db
    k = int(np.nanargmax(excess))
    if excess[k] <= 0:
        return f"meets {name} (closest {excess[k]:.2f} dB at {w[k]:.3g} rad/s)"
    return f"above {name} by up to {excess[k]:.2f} dB at {w[k]:.3g} rad/s"


def plot_design_bode(design: QFTDesign, model: TurbineModel | None = None, omega: ArrayLike | None = None,
                     axes: Sequence[Axes] | None = None) -> Figure:
    """|T_{Ω,w}| and |T_{MyT,w}| of ROSCO, the specifications and the QFT design (dB).

    The legend names each specification: the generator-speed spec W_Ω (ROSCO relaxed by the
    design's ``speed_relax_db``), the tower-load spec W_y as shaped (ROSCO × notches, the
    promise the paper's Table 3 lists) and W_y relaxed above ``tower_relax_omega`` (the spec
    the bounds and the dense check use, i.e. the one the design is checked against). The QFT
    curve's label says, on the drawn grid and for the nominal case, which spec it meets and by
    how much it exceeds the others (the relaxation puts the excess where ΔD% is negligible).

    Parameters
    ----------
    design : specdesign.qft.QFTDesign
        The QFT design (its controllers, specifications and closed loop).
    model : specdesign.turbine.TurbineModel, optional
        The turbine the design was made on (default the embedded IEA 15 MW), for ROSCO's loop.
    omega : array_like, optional
        Frequency grid, rad/s (default 800 log-spaced points, 0.01-10 rad/s).
    axes : sequence of matplotlib.axes.Axes, optional
        Two stacked axes (generator speed, tower-base moment), or three (and the pitch
        controller's gain); default a new figure with three for a design made under the
        high-frequency gain bound, two otherwise.

    Returns
    -------
    matplotlib.figure.Figure
        The figure (stacked axes, shared ω axis in rad/s): |T| in dB re 1 (rad/s)/(m/s) and
        re 1 N·m/(m/s); a third axes holds |C_β| and ROSCO's |C| in dB re 1 rad/(rad/s) with
        the bound κ·|C_ROSCO| on HF_OMEGA-HF_END (legend "high-frequency gain bound").

    Raises
    ------
    ValueError
        If ``axes`` holds neither two nor three axes.
    """
    w = np.logspace(-2, 1, 800) if omega is None else np.asarray(omega, dtype=float)
    kappa = design.options.get("max_hf_gain_ratio")
    if axes is None:
        import matplotlib.pyplot as plt

        n = 2 if kappa is None else 3
        fig, axes = plt.subplots(n, 1, figsize=(9, 3.75 * n), sharex=True)
    else:
        if len(axes) not in (2, 3):
            raise ValueError(f"axes holds {len(axes)} axes; give two (generator speed, tower-base moment) or three "
                             "(and the pitch controller's gain)")
        fig = axes[0].figure
    if model is None:
        model = iea15mw()
    cl_base = closedloop.closed_loop(model.linearize(design.wind_speed), design.baseline_controller, warn=False)
    opts = design.options

    def db(x):
        return 20 * np.log10(np.abs(x))

    # design_qft(spec=...) records a given pair this way: no notches of its own, no relaxation
    given = design.shaping.message in ("given specification", "target specification")
    target = opts.get("structure") == "certificate"  # the specification-driven design: pitch only
    checked = "the design is checked against it"
    name = "spec-driven $C_\\beta$ (pitch only)" if target else "QFT $C_\\beta$ + ATD"
    for ax, out, unit in ((axes[0], "gen_speed", "(rad/s)/(m/s)"), (axes[1], "tower_base_my", "N·m/(m/s)")):
        t_qft = db(closedloop.frequency_response(design.closed_loop, w, out))
        ax.semilogx(w, db(closedloop.frequency_response(cl_base, w, out)), "C0", label="ROSCO (ATD off)")
        verdicts = []
        if out == "gen_speed":
            relax = opts.get("speed_relax_db", float("nan"))
            how = (f"ROSCO + {relax:.2f} dB" if target else "given" if given else f"ROSCO + {relax:g} dB")
            w_db = db(design.speed_spec.response(w))
            ax.semilogx(w, w_db, "C3--", label=f"generator-speed spec W_Ω ({how}; {checked})")
            verdicts.append(_verdict(t_qft, w_db, w, "W_Ω"))
        else:
            r_db = db(design.tower_spec.response(w))
            notch = design.shaping.specification
            if target:
                ax.semilogx(w, r_db, "C3--", label=f"tower-load spec W_y for the target (promises "
                            f"{design.promise.exact_del:.1f} % DEL; {checked})")
                verdicts.append(_verdict(t_qft, r_db, w, "W_y"))
            elif given or notch is None:
                ax.semilogx(w, r_db, "C3--", label=f"tower-load spec W_y ({'given' if given else 'relaxed'}; {checked})")
                verdicts.append(_verdict(t_qft, r_db, w, "W_y"))
            else:
                n_db = db(notch.response(w))
                ax.semilogx(w, n_db, "C3:", lw=2, label="tower-load spec W_y as shaped: ROSCO × notches "
                            f"(promises {design.shaping.promise.exact_del:.1f} % DEL)")
                ax.semilogx(w, r_db, "C3--", label=f"W_y relaxed +{opts.get('tower_relax_db', float('nan')):g} dB above "
                            f"{opts.get('tower_relax_omega', float('nan')):g} rad/s (promises "
                            f"{design.promise.exact_del:.1f} % DEL; {checked})")
                verdicts += [_verdict(t_qft, r_db, w, "relaxed W_y"), _verdict(t_qft, n_db, w, "shaped W_y")]
        ax.semilogx(w, t_qft, "C1", lw=2, label=f"{name}, nominal: " + "; ".join(verdicts))
        wd = design.design_omega[(design.design_omega >= w[0]) & (design.design_omega <= w[-1])]
        ax.semilogx(wd, db(closedloop.frequency_response(design.closed_loop, wd, out)), "o", color="C4", ms=4,
                    label="QFT at the design frequencies")
        ax.set_ylabel(f"|T| (dB re 1 {unit})")
        ax.grid(True, which="both", lw=0.3)
        ax.legend(fontsize=7)
    axes[0].set_title(f"Wind → generator speed, {design.wind_speed:g} m/s (dense check, every plant case: "
                      f"{design.message})", fontsize=10)
    axes[1].set_title(f"Wind → tower-base fore-aft moment, {design.wind_speed:g} m/s")
    if len(axes) == 3:
        _draw_gain(axes[2], design, model, w, kappa)
    axes[-1].set_xlabel("frequency ω (rad/s)")
    fig.tight_layout()
    return fig


def _draw_gain(ax, design, model, w, kappa):
    """|C_β| and ROSCO's |C| (dB re 1 rad per rad/s) and the high-frequency gain bound on ``ax``."""
    def db(x):
        return 20 * np.log10(np.abs(x))

    ax.semilogx(w, db(closedloop.siso_response(design.baseline_controller, w)), "C0", label="ROSCO $|C|$")
    ax.semilogx(w, db(closedloop.siso_response(design.pitch_controller, w)), "C1", lw=2, label="design $|C_\\beta|$")
    if kappa is not None:
        band = w[(w >= HF_OMEGA) & (w <= HF_END)]
        ax.semilogx(band, db(hf_gain_bound(model, design.wind_speed, band, kappa)), "k--", lw=1.5,
                    label=f"high-frequency gain bound $|C_\\beta| \\leq {kappa:g}\\,|C_{{ROSCO}}|$ "
                          f"({HF_OMEGA:g}-{HF_END:g} rad/s)")
    ax.set_ylabel("|C| (dB re 1 rad/(rad/s))")
    ax.set_title(f"Pitch controller gain, {design.wind_speed:g} m/s", fontsize=10)
    ax.grid(True, which="both", lw=0.3)
    ax.legend(fontsize=7)


def _bounds_at(bounds, template, picks):
    """The same specs' bounds at the template frequencies nearest to ``picks`` (rad/s):
    a readable chart shows a handful of frequencies, not every design frequency."""
    w = template.omega
    sub = np.unique([w[np.argmin(np.abs(w - p))] for p in picks])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", lqft.BoundsWarning)
        return lqft.intersect(*[lqft.bounds(template.at(sub), s) for s in bounds.specs])


def plot_design_nichols(design: QFTDesign, picks: Sequence[float] = (0.01, 0.05, 0.1, 0.3, 0.6, 1.0, 1.5, 3.0),
                        axes: Sequence[Axes] | None = None, model: TurbineModel | None = None) -> Figure:
    """Nichols charts of the QFT loops with their bounds: the paper's Figs. 5-6 analogue.

    The pitch loop C_β·P'_{Ω,β} (with the ATD loop closed, where the design has one) and, for
    a design with active tower damping, the ATD loop C_atd·P''_{z,β} (pitch loop closed) beside
    it; magnitude in dB vs phase in degrees, nominal plant case, the bounds at the design
    frequencies nearest to ``picks`` and the critical point (−180°, 0 dB). A pitch-only design
    gets one panel.

    Parameters
    ----------
    design : specdesign.qft.QFTDesign
        The QFT design (its templates, bounds and controllers).
    picks : sequence of float
        Frequencies, rad/s, whose nearest template frequencies get their bounds drawn.
    axes : sequence of matplotlib.axes.Axes, optional
        One axes per loop drawn (two with ATD, one without); default a new figure.
    model : specdesign.turbine.TurbineModel, optional
        The turbine the design was made on (default the embedded IEA 15 MW), for ROSCO's |C|
        in the high-frequency gain bound of a design made under it: drawn on the pitch loop's
        chart as |L| ≤ κ·|C_ROSCO|·|P| at the loop's phase (legend "high-frequency gain bound").

    Returns
    -------
    matplotlib.figure.Figure
        The figure.

    Raises
    ------
    ValueError
        If ``axes`` holds another number of axes than the design has loops.
    """
    import matplotlib.pyplot as plt

    with_atd = not is_zero(design.atd_controller)
    loops = [(design.pitch_bounds, design.pitch_template, design.pitch_controller, (-60, 60),
              "Pitch loop $C_\\beta P'_{\\Omega,\\beta}$" + (" (ATD closed)" if with_atd else ""))]
    if with_atd:
        loops.append((design.atd_bounds, design.atd_template, design.atd_controller, (-60, 40),
                      "ATD loop $C_{atd} P''_{z,\\beta}$ (pitch loop closed)"))
    if axes is None:
        fig, axes = plt.subplots(1, len(loops), figsize=(7 * len(loops), 5.5), squeeze=False)
        axes = axes[0]
    axes = np.atleast_1d(np.asarray(axes, dtype=object))
    if axes.size != len(loops):
        raise ValueError(f"axes holds {axes.size} axes; this design has {len(loops)} loop(s) to draw "
                         f"({'pitch and ATD' if with_atd else 'pitch only'}): give one axes per loop")
    fig = axes[0].figure
    w = np.logspace(-3, 1.5, 3000)
    kappa = design.options.get("max_hf_gain_ratio")
    for i, (ax, (bounds, template, c, ylim, title)) in enumerate(zip(axes, loops)):
        plant = template.systems[template.nominal]
        nichols.draw(_bounds_at(bounds, template, picks), loop=c * plant, ax=ax, omega=w, ylim=ylim)
        if i == 0 and kappa is not None:
            # |C_β| ≤ B(ω) is |L| ≤ B(ω)·|P| at the loop's own phase, frequency by frequency: the
            # highest the nominal loop may lie on its band
            band = w[(w >= HF_OMEGA) & (w <= HF_END)]
            p = closedloop.siso_response(plant, band, "plant")
            loop = closedloop.siso_response(c, band) * p
            phase, mag = nichols.wrap_phase(np.degrees(np.unwrap(np.angle(loop))),
                                            20 * np.log10(hf_gain_bound(iea15mw() if model is None else model,
                                                                        design.wind_speed, band, kappa) * np.abs(p)))
            ax.plot(phase, mag, "k--", lw=1.5, label=f"high-frequency gain bound $|C_\\beta| \\leq {kappa:g}\\,"
                    f"|C_{{ROSCO}}|$ ({HF_OMEGA:g}-{HF_END:g} rad/s), at the loop's phase")
            ax.legend(fontsize=7)
        ax.set_title(f"{title}, {design.wind_speed:g} m/s")
    fig.tight_layout()
    return fig
