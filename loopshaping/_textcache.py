"""A renderer that draws a line of text from a cache when it would draw the very same pixels.

Rendering text is most of a blitted redraw with matplotlib ≥ 3.11 on Agg: every glyph is
placed and rasterised in Python (about 0.1 ms a glyph), and a live figure's titles run to
hundreds of glyphs of which an edit changes a few. :class:`CachedTextRenderer` wraps the
canvas's Agg renderer for :class:`loopshaping.interactive.LiveArtists`: it forwards everything,
and for each line of text (``draw_text``, unrotated) it first reads the pixels of the line's box
(its metrics plus a margin). When the same text, font, position, colour and clip met the same
pixels before, it writes back the pixels that drawing gave then (the result is a function of
those inputs); otherwise it draws and keeps the box's pixels. So a redraw is pixel-identical
to drawing every line, and only the lines whose text or underlay changed are rasterised.
"""
from __future__ import annotations

import math
from collections import OrderedDict

import numpy as np

__all__ = ["CachedTextRenderer"]


class CachedTextRenderer:
    """The Agg ``renderer``, with each unrotated line of text drawn from a cache when it can.

    Parameters
    ----------
    renderer : matplotlib.backends.backend_agg.RendererAgg
        The canvas's renderer (``canvas.get_renderer()``); its ``buffer_rgba`` is read and written.
    size : int
        Lines kept (least recently used dropped first).

    Attributes
    ----------
    renderer : RendererAgg
        The wrapped renderer.
    hits, misses : int
        Lines written from the cache and lines drawn, since construction.
    """

    def __init__(self, renderer, size: int = 64):
        self.renderer = renderer
        self.size = int(size)
        self.hits = self.misses = 0
        self._lines = OrderedDict()  # key (inputs and the underlay's bytes) → the box's pixels after drawing
        self._metrics = OrderedDict()  # (text, font, math) → (width, height, descent), px

    _OWN = frozenset({"renderer", "size", "hits", "misses", "_lines", "_metrics"})

    def __getattr__(self, name):  # everything but draw_text: the canvas's renderer
        return getattr(self.renderer, name)

    def __setattr__(self, name, value):  # the renderer's state (e.g. its rasterisation depth) stays its own
        if name in self._OWN:
            object.__setattr__(self, name, value)
        else:
            setattr(self.renderer, name, value)

    def _extent(self, s, prop, ismath):
        key = (s, prop, ismath)
        m = self._metrics.get(key)
        if m is None:
            m = self._metrics[key] = self.renderer.get_text_width_height_descent(s, prop, ismath)
            if len(self._metrics) > 4 * self.size:
                self._metrics.popitem(last=False)
        return m

    def draw_text(self, gc, x, y, s, prop, angle, ismath=False, mtext=None):
        """Draw one line of text at (x, y) px (y down from the top: Agg flips y), from the cache if it can."""
        r = self.renderer
        clip_path, _ = gc.get_clip_path()
        if angle or ismath == "TeX" or clip_path is not None or not (math.isfinite(x) and math.isfinite(y)):
            return r.draw_text(gc, x, y, s, prop, angle, ismath=ismath, mtext=mtext)
        w, h, d = self._extent(s, prop, ismath)
        # the ink lies within the metrics box from the pen position (x, baseline y), rounded out
        # to whole pixels; a margin across for side bearings (a quarter of the font size), and up
        # and down only for mathtext, whose box can miss a pixel row of ink (a margin there would
        # take in the line above or below, and an unchanged line under a changed one would be
        # drawn again); tests/test_fast_redraw.py compares the pixels with drawing every line
        pad = math.ceil(0.25 * prop.get_size_in_points() * r.dpi / 72.0) + 1
        m = 1 if ismath else 0
        buf = np.asarray(r.buffer_rgba())
        rows = slice(max(math.floor(y - (h - d)) - m, 0), min(math.ceil(y + d) + 1 + m, buf.shape[0]))
        cols = slice(max(math.floor(x) - pad, 0), min(math.ceil(x + w) + pad, buf.shape[1]))
        box = buf[rows, cols]
        clip = gc.get_clip_rectangle()
        key = (s, prop, ismath, x, y, tuple(gc.get_rgb()), gc.get_alpha(), gc.get_forced_alpha(),
               gc.get_antialiased(), None if clip is None else tuple(clip.bounds), r.dpi,
               None if mtext is None else (mtext.get_fontfeatures(), mtext.get_language()), box.tobytes())
        done = self._lines.get(key)
        if done is not None:
            self._lines.move_to_end(key)
            box[...] = done
            self.hits += 1
            return None
        r.draw_text(gc, x, y, s, prop, angle, ismath=ismath, mtext=mtext)
        self._lines[key] = box.copy()
        if len(self._lines) > self.size:
            self._lines.popitem(last=False)
        self.misses += 1
        return None
