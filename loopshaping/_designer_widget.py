"""The ipywidgets controls of :class:`loopshaping.interactive.Designer` (built by its ``widget``).

Kept apart so that the designer's numbers and figure import no widget library.
"""
from __future__ import annotations

import html
import math

from .controller import KINDS

__all__ = ["build_widget", "readout_html", "LOG_STEP", "LOG_SPAN"]

LOG_STEP = 0.005  # decades per slider step: 1.2 %, fine enough to place a corner frequency
LOG_SPAN = 1.0  # decades either side of the value the slider was built around (re-centred on a typed value)


def _log_range(value):
    c = math.log10(abs(value))
    return c - LOG_SPAN, c + LOG_SPAN


def readout_html(text: str, colour: str = "black") -> str:
    """Lines of text as the HTML of an ``ipywidgets.HTML`` readout beside a live figure.

    Parameters
    ----------
    text : str
        The lines (``\\n`` between them); shown as they are (escaped, white space kept).
    colour : str
        The text's colour, any matplotlib colour (``"tab:red"``), written as its hex value.

    Returns
    -------
    str
        HTML: one ``<div>``, the lines in a small font, wrapped where the widget is narrower
        than a line.

    Examples
    --------
    >>> from loopshaping.interactive import readout_html
    >>> readout_html("a < b\\nmet")
    '<div style="font-size:12px;line-height:1.35;white-space:pre-wrap;padding-left:3px;color:#000000">a &lt; b\\nmet</div>'
    """
    from matplotlib.colors import to_hex  # loopshaping loads matplotlib only to draw (here: a live figure's)

    return (f'<div style="font-size:12px;line-height:1.35;white-space:pre-wrap;padding-left:3px;color:{to_hex(colour)}">'
            f"{html.escape(text, quote=False)}</div>")


def build_widget(d):
    """The controls and the figure of a designer, wired to its editing methods.

    Parameters
    ----------
    d : loopshaping.interactive.Designer
        The designer (its figure already drawn).

    Returns
    -------
    ipywidgets.VBox
        ``VBox([controls, figure])``, on a live (ipympl) canvas ``VBox([controls, readout,
        figure])`` with the verdict lines in ``readout`` (an ``ipywidgets.HTML``, no longer
        drawn on the canvas); ``controls`` holds the element list, the add/remove
        row, the selected element's parameter rows (slider + exact text box each), the
        controller's JSON and a message line.

    Raises
    ------
    ImportError
        Without ipywidgets.
    """
    try:
        import ipywidgets as ipw
    except ImportError as e:
        raise ImportError("the interactive designer needs ipywidgets (and ipympl for a live figure)") from e
    from IPython.display import clear_output, display

    elements = ipw.Select(options=d.element_options(), rows=6, description="elements",
                          layout=ipw.Layout(width="60%"))
    if elements.options:
        elements.value = min(d.selected, len(elements.options) - 1)
    rows = ipw.VBox()
    kind = ipw.Dropdown(options=KINDS, value="real_pole", description="add")
    add_btn, rm_btn = ipw.Button(description="add element"), ipw.Button(description="remove selected")
    json_box = ipw.Textarea(value=d.controller.to_json(), layout=ipw.Layout(width="100%"), disabled=True)
    msg = ipw.HTML()
    canvas = d.figure.canvas
    live = isinstance(canvas, ipw.DOMWidget)
    fig_box = canvas if live else ipw.Output()
    if live and d._redraw.live:
        # the verdict lines leave the live canvas for a readout above it: drawn at every edit
        # they were most of a redraw (text costs about 0.1 ms a glyph, and its pixels go to the
        # browser); a saved figure still draws them
        d._readout_widget = ipw.HTML(readout_html(d.readout, d._readout_colour))
        d._redraw.print_only(d._artists["title"])
    shown = {"idx": None}
    busy = [False]
    editing = [False]  # an edit made through these controls (they already show it)

    def show_figure():
        if not live:  # a static backend: show the re-rendered figure in place of the old one
            with fig_box:
                clear_output(wait=True)
                display(d.figure)

    def after_edit(select=None):
        # Relabel the list without letting the selection (and the control being dragged) jump.
        keep = elements.value if select is None else select
        busy[0] = True
        try:
            with elements.hold_sync():  # the new labels and the selection in one message
                elements.options = d.element_options()
                if elements.options:
                    elements.value = min(keep or 0, len(elements.options) - 1)
        finally:
            busy[0] = False
        d.selected = elements.value or 0
        json_box.value = d.controller.to_json()
        show_figure()

    def apply(idx, name, value):
        editing[0] = True
        try:
            d.set_param(idx, **{name: value})
        except (TypeError, ValueError) as err:
            msg.value = f"<span style='color:#c00'>{name} = {value!r} rejected: {err}</span>"
            return False
        finally:
            editing[0] = False
        msg.value = ""
        after_edit()
        return True

    def param_row(idx, name, value):
        current = lambda: d.controller.elements[idx].params[name]  # noqa: E731
        if name == "order":
            sl = ipw.IntSlider(value=value, min=1, max=4, description=name)
            sl.observe(lambda ch: apply(idx, name, int(ch["new"])), names="value")
            return sl
        is_log = not name.startswith("zeta")
        if is_log:
            lo, hi = _log_range(value)
            # a wide track: about 1.5 % per pixel, so a small drag is a small change
            sl = ipw.FloatLogSlider(value=abs(value), base=10, min=lo, max=hi, step=LOG_STEP,
                                    description=name + (" (−)" if value < 0 else ""), readout_format=".4g",
                                    layout=ipw.Layout(width="36em"))
        else:
            sl = ipw.FloatSlider(value=value, min=0.0 if name == "zeta_zero" else 0.005, max=2.0, step=0.005,
                                 description=name, readout_format=".4g", layout=ipw.Layout(width="36em"))
        text = ipw.FloatText(value=value, description="exact", continuous_update=False, layout=ipw.Layout(width="14em"))
        quiet = [False]
        sent = [value]  # the values Python put on the slider since the last move (signed)

        def set_quietly(widget, v):
            quiet[0] = True
            try:
                if is_log and widget is sl:
                    lo, hi = _log_range(v)
                    if not 10 ** sl.min <= abs(v) <= 10 ** sl.max:  # re-centre on a typed value out of range
                        with sl.hold_sync():
                            sl.min, sl.max = min(lo, sl.min), max(hi, sl.max)
                    sl.description = name + (" (−)" if v < 0 else "")
                    v = abs(v)
                widget.value = v
                if widget is sl:
                    sent.append(math.copysign(sl.value, v) if is_log else sl.value)
            finally:
                quiet[0] = False

        def on_slider(ch):
            if quiet[0]:
                return
            new = math.copysign(ch["new"], current()) if is_log else ch["new"]
            # The front end rounds each value set from Python to its step and echoes it back
            # (maybe after later cells ran): within half a step of a value Python set since the
            # last move, it is such an echo, not a move.
            dist = [abs(math.log10(abs(new)) - math.log10(abs(v))) if is_log else abs(new - v) for v in sent]
            if min(dist) < 0.5 * sl.step:
                return
            sent[:] = [new]
            if apply(idx, name, new):
                set_quietly(text, new)

        def on_text(ch):
            if quiet[0]:
                return
            v = float(ch["new"])
            if is_log and not (math.isfinite(v) and v != 0):
                msg.value = f"<span style='color:#c00'>{name} = {v!r} rejected: a log-scale value must be finite and non-zero</span>"
                set_quietly(text, current())
            elif apply(idx, name, v):  # the typed value, exactly
                set_quietly(sl, v)
            else:
                set_quietly(text, current())

        sl.observe(on_slider, names="value")
        text.observe(on_text, names="value")
        return ipw.HBox([sl, text])

    def build_rows(change=None):
        if busy[0]:
            return
        idx = elements.value
        if idx is None or idx >= len(d.controller.elements):
            rows.children, shown["idx"] = (), None
            return
        if idx == shown["idx"] and change is not None:
            return  # the list was relabelled, the element is the same: keep the control being dragged
        shown["idx"] = idx
        d.selected = idx
        e = d.controller.elements[idx]
        rows.children = tuple(param_row(idx, name, value) for name, value in e.params.items())

    def on_add(_):
        editing[0] = True
        try:
            d.add(kind.value)
        finally:
            editing[0] = False
        shown["idx"] = None
        after_edit(select=len(d.controller.elements) - 1)
        build_rows()

    def on_remove(_):
        if elements.value is not None and d.controller.elements:
            editing[0] = True
            try:
                d.remove(elements.value)
            finally:
                editing[0] = False
            shown["idx"] = None
            after_edit(select=0)
            build_rows()

    def from_code():
        # an edit from code (d.set_param in a later cell): the list, the rows and the JSON
        # follow, so the controls show the controller the figure draws
        if editing[0]:
            return
        shown["idx"] = None
        after_edit()
        build_rows()

    d._on_update = from_code
    elements.observe(build_rows, names="value")
    add_btn.on_click(on_add)
    rm_btn.on_click(on_remove)
    build_rows()
    show_figure()
    controls = ipw.VBox([elements, ipw.HBox([kind, add_btn, rm_btn]), rows, json_box, msg])
    return ipw.VBox([controls, *([d._readout_widget] if d._readout_widget is not None else []), fig_box])

