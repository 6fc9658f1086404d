"""QFT design figures: the paper's Fig. 7 analogue (Bode magnitudes ROSCO vs spec vs QFT)."""
from __future__ import annotations

import numpy as np

__all__ = ["plot_design_bode"]


def plot_design_bode(design, model=None, omega=None, axes=None):
    """|T_{Ω,w}| and |T_{MyT,w}| of ROSCO, the specifications and the QFT design (dB).

    ``design`` is a :class:`specdesign.qft.QFTDesign` made on ``model`` (default the embedded
    IEA 15 MW); ``omega`` the grid in rad/s (default 0.01-10 rad/s). Returns the figure (two
    stacked axes, shared ω axis).
    """
    import matplotlib.pyplot as plt

    from .. import closedloop

    w = np.logspace(-2, 1, 800) if omega is None else np.asarray(omega, dtype=float)
    if axes is None:
        fig, axes = plt.subplots(2, 1, figsize=(9, 7.5), sharex=True)
    else:
        fig = axes[0].figure
    if model is None:
        from ..turbine import iea15mw

        model = iea15mw()
    cl_base = closedloop.closed_loop(model.linearize(design.wind_speed), design.baseline_controller, warn=False)

    def db(x):
        return 20 * np.log10(np.abs(x))

    for ax, out, unit in ((axes[0], "gen_speed", "(rad/s)/(m/s)"), (axes[1], "tower_base_my", "N·m/(m/s)")):
        ax.semilogx(w, db(closedloop.frequency_response(cl_base, w, out)), "C0", label="ROSCO (ATD off)")
        if out == "gen_speed":
            ax.semilogx(w, db(design.speed_spec.response(w)), "C3", label="specification (relaxed ROSCO)")
        else:
            ax.semilogx(w, db(design.shaping.specification.response(w)), "C3", label="specification: ROSCO × notches")
            ax.semilogx(w, db(design.tower_spec.response(w)), "C3--", label="spec used for the bounds (relaxed at high ω)")
        ax.semilogx(w, db(closedloop.frequency_response(design.closed_loop, w, out)), "C1", lw=2, label="QFT: $C_\\beta$ + ATD")
        wd = design.design_omegas[(design.design_omegas >= w[0]) & (design.design_omegas <= w[-1])]
        ax.semilogx(wd, db(closedloop.frequency_response(design.closed_loop, wd, out)), "o", color="C4", ms=4,
                    label="design frequencies")
        ax.set_ylabel(f"|T| (dB re 1 {unit})")
        ax.grid(True, which="both", lw=0.3)
        ax.legend(fontsize=8)
    axes[0].set_title(f"Wind → generator speed, {design.wind_speed:g} m/s")
    axes[1].set_title(f"Wind → tower-base fore-aft moment, {design.wind_speed:g} m/s")
    axes[1].set_xlabel("frequency ω (rad/s)")
    fig.tight_layout()
    return fig


def _bounds_at(bounds, template, picks):
    """The same specs' bounds at the template frequencies nearest to ``picks`` (rad/s):
    a readable chart shows a handful of frequencies, not every design frequency."""
    import warnings

    from loopshaping import qft as lqft

    w = template.omega
    sub = np.unique([w[np.argmin(np.abs(w - p))] for p in picks])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", lqft.BoundsWarning)
        return lqft.intersect(*[lqft.bounds(template.at(sub), s) for s in bounds.specs])


def plot_design_nichols(design, picks=(0.01, 0.05, 0.1, 0.3, 0.6, 1.0, 1.5, 3.0), axes=None):
    """Nichols charts (dB vs degrees) of the pitch loop C_β·P'_{Ω,β} (ATD closed) and of the
    ATD loop C_atd·P''_{z,β} (pitch loop closed), with their bounds at the design frequencies
    nearest to ``picks`` (rad/s): the paper's Figs. 5-6 analogue. Returns the figure."""
    import matplotlib.pyplot as plt

    from loopshaping import nichols

    if axes is None:
        fig, axes = plt.subplots(1, 2, figsize=(14, 5.5))
    else:
        fig = axes[0].figure
    w = np.logspace(-3, 1.5, 3000)
    for ax, bounds, template, c, ylim, title in (
        (axes[0], design.pitch_bounds, design.pitch_template, design.pitch_controller, (-60, 60),
         "Pitch loop $C_\\beta P'_{\\Omega,\\beta}$ (ATD closed)"),
        (axes[1], design.atd_bounds, design.atd_template, design.atd_controller, (-60, 40),
         "ATD loop $C_{atd} P''_{z,\\beta}$ (pitch loop closed)"),
    ):
        plant = template.systems[template.nominal]
        nichols.draw(_bounds_at(bounds, template, picks), loop=c * plant, ax=ax, omega=w, ylim=ylim)
        ax.set_title(f"{title}, {design.wind_speed:g} m/s")
    fig.tight_layout()
    return fig
