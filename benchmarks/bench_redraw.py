"""The live figures' slider callbacks, in the kernel, as JupyterLab runs them (ipympl's canvas).

Run: python benchmarks/bench_redraw.py
Target (issue 30): a slider step redraws in ≤ 150 ms in the browser on an idle machine; the
kernel's share, the callback (``update_ms``), ≤ 40 ms.

Notebook 03's notch explorer (with the pitch and QFT-bounds checkers, a sweep of the depth
slider) and notebook 04's Designer on the 19 m/s pitch loop of ``design_qft(spec="notch")``
(a sweep of the gain, ±0.15 decade) are built on ipympl's canvas as in JupyterLab, the
browser's end replaced by a no-op (``send``): the callback then computes, sets the artists'
data, blits them and encodes the changed pixels as PNG, as it does in a notebook. Printed: the
median callback (and as it was with matplotlib's PNG encoder), and its parts measured apart (compute alone, the blit of the artists, the PNG
of the changed pixels and its size), beside what the shortcuts replace (the explorer's exact
QFT bounds check, the blit with every line of text rasterised, the PNG as matplotlib encodes
it with Pillow). Each figure twice, back to back: on its own, its
changing text (the Designer's verdict, the explorer's title and legend label) drawn on the
canvas at each step; and as its ``widget()`` shows it, that text in an ipywidgets readout above
the figure. The browser's time on top is measured by tests/test_browser.py.
"""
from __future__ import annotations

import os
import time

import matplotlib

matplotlib.use("module://ipympl.backend_nbagg")

import numpy as np  # noqa: E402
from matplotlib.backends.backend_webagg_core import FigureCanvasWebAggCore

from loopshaping._diffpng import install_encoder
from loopshaping.controller import Controller  # noqa: E402
from loopshaping.interactive import Designer  # noqa: E402
from specdesign import feasibility, qft, spec  # noqa: E402
from specdesign.plots.spec import NotchExplorer  # noqa: E402
from specdesign.qft.boundscheck import bounds_checker  # noqa: E402
from specdesign.turbine import iea15mw  # noqa: E402


def _as_in_the_browser(fig):
    """ipympl's canvas as once the browser has drawn the figure (blits, not data URLs), sending nowhere."""
    canvas = fig.canvas
    canvas.syncing_data_url = False  # the browser's view said it is initialised
    canvas.send = lambda *args, **kwargs: None  # the comm to the browser
    canvas.draw()  # the first full render caches the background
    return canvas


def _median_ms(fn, args):
    times = []
    for a in args:
        t0 = time.perf_counter()
        fn(a)
        times.append(time.perf_counter() - t0)
    return 1e3 * float(np.median(times))


def _parts(canvas, redraw, update, args):
    """Median ms of: the callback, and with matplotlib's PNG encoder; compute alone; the blit of
    the artists with the text cache and without it (every line rasterised, as before the cache);
    the PNG of the changed pixels, and by matplotlib's encoder; then the PNGs' median kB.

    The callback with matplotlib's encoder and the parts are timed on values between those of
    ``args`` (a third and two thirds of the way: not seen yet, so the lines that change are drawn
    as in a drag, not found in the cache).
    """
    callback = _median_ms(update, args)
    del canvas.get_diff_image  # the callback as before loopshaping._diffpng: matplotlib's encoder
    pillow_callback = _median_ms(update, args[:-1] + (args[1:] - args[:-1]) / 3)  # values not seen yet
    install_encoder(canvas)
    mid = args[:-1] + 2 * (args[1:] - args[:-1]) / 3
    compute = _median_ms(lambda a: update(a, redraw=False), mid)
    blit, plain, diff, pillow, size, pillow_size = [], [], [], [], [], []
    for a in mid:
        update(a, redraw=False)
        t0 = time.perf_counter()
        canvas.restore_region(redraw._background)
        for artist in redraw.artists:
            artist.draw(redraw._text)
        t1 = time.perf_counter()
        last = canvas._last_buff
        canvas._png_is_old = True
        size.append(len(canvas.get_diff_image()))  # the live canvas's encoder (loopshaping._diffpng)
        t2 = time.perf_counter()
        canvas._last_buff, canvas._png_is_old = last, True  # the same image, as matplotlib encodes it
        pillow_size.append(len(FigureCanvasWebAggCore.get_diff_image(canvas)))
        t3 = time.perf_counter()
        canvas.restore_region(redraw._background)
        for artist in redraw.artists:
            redraw.figure.draw_artist(artist)
        t4 = time.perf_counter()
        blit.append(t1 - t0)
        diff.append(t2 - t1)
        pillow.append(t3 - t2)
        plain.append(t4 - t3)
    return (callback, pillow_callback, compute, *(1e3 * float(np.median(x)) for x in (blit, plain, diff, pillow)),
            *(float(np.median(x)) / 1e3 for x in (size, pillow_size)))


def _report(what, canvas, parts, replaced):
    callback, pillow_callback, compute, blit, plain, diff, pillow, kb, pillow_kb = parts
    w, h = canvas.get_width_height(physical=True)
    print(f"{what} ({w}x{h} px)")
    print(f"  callback (update_ms)               {callback:7.1f} ms   target ≤ 40 ms "
          f"(with matplotlib's PNG encoder: {pillow_callback:.1f} ms)")
    print(f"    compute (verdicts, data)         {compute:7.1f} ms   {replaced}")
    print(f"    blit of the changed artists      {blit:7.1f} ms   (every line of text rasterised: {plain:.1f} ms)")
    print(f"    PNG of the changed pixels        {diff:7.1f} ms   {kb:.1f} kB (matplotlib's, by Pillow: {pillow:.1f} ms, {pillow_kb:.1f} kB)")


def _explorer(base, notch, checker, qc, readout):
    explorer = NotchExplorer(base, notch, checker=checker, bounds_checker=qc)
    if readout:
        explorer.widget()  # the changing lines leave the canvas for the widget's readout
    return explorer, _as_in_the_browser(explorer.fig)


def _designer(d, readout):
    designer = Designer(d.pitch_bounds, d.pitch_template, Controller.from_tf(d.pitch_controller))
    designer.draw()
    if readout:
        designer.widget()  # the verdict lines leave the canvas for the widget's readout
    return designer, _as_in_the_browser(designer.figure)


MODES = {False: "the changing text drawn on the canvas (no widget: a figure on its own)",
         True: "the changing text in the widget's readout (as widget() shows it)"}


def main():
    print(f"slider callbacks on ipympl's canvas (median over a sweep; load {os.getloadavg()[0]:.1f})")
    model = iea15mw()
    base = spec.baseline_analysis(model, 19.0, output="tower_base_my", m=4.0)
    notch = spec.shape_to_target(base, 15.0, keep_below=0.6).notches[0]
    checker = feasibility.pitch_checkers(model, 19.0, spec.speed_specification(model, 19.0, margin_db=3.0),
                                         max_sensitivity=None)[0]
    t0 = time.perf_counter()
    qc = bounds_checker(model, 19.0)
    t_build = time.perf_counter() - t0
    t0 = time.perf_counter()
    qc.precompute()
    t_pre = time.perf_counter() - t0
    depths = np.linspace(notch.depth_db - 3.0, notch.depth_db + 3.0, 31)
    exact = bounds_checker(model, 19.0)  # not precomputed: one exact bound computation per check
    t_exact = _median_ms(lambda dep: exact.check(exact.rosco_nominal * spec.Notch(notch.omega_n, dep, notch.width)
                                                 .response(exact.template.omega)), depths[::3])
    for readout, mode in MODES.items():
        explorer, canvas = _explorer(base, notch, checker, qc, readout)

        def move(depth, redraw=True):
            explorer.update(notch.omega_n, depth, notch.width, redraw=redraw)

        parts = _parts(canvas, explorer._redraw, move, depths)
        _report(f"notebook 03: the notch explorer's depth slider, {mode}", canvas, parts,
                f"(its QFT verdict computed exactly: +{t_exact:.1f} ms)")
    print(f"    (bounds checker: built in {t_build * 1e3:.0f} ms, precomputed in {t_pre * 1e3:.0f} ms, once)")

    d = qft.design_qft(model, 19.0, spec=qft.spec_notch(25.0))  # as notebook 04 builds it
    for readout, mode in MODES.items():
        designer, canvas = _designer(d, readout)
        k0 = designer.controller.elements[0].params["k"]
        gains = k0 * np.logspace(-0.15, 0.15, 31)

        def gain(k, redraw=True):
            designer.controller = designer.controller.set(0, k=k)
            designer.update(redraw=redraw)

        _report(f"notebook 04: the Designer's gain ({len(d.pitch_template.systems)} plant cases, "
                f"{designer.omega.size} frequencies), {mode}", canvas,
                _parts(canvas, designer._redraw, gain, gains), "")


if __name__ == "__main__":
    main()
