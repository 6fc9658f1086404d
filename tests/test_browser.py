"""The interactive notebooks in a real browser: JupyterLab + headless Chromium (Python playwright).

The test starts its own JupyterLab on 127.0.0.1 (a free port, a random token, no browser) over a
temporary copy of notebooks 03 (the specification explorer) and 04 (the QFT Designer on the
19 m/s pitch loop), opens each in Debian's Chromium driven by playwright (``executable_path``:
playwright's own browser downloads are not used), runs all cells, checks that the controls show the state the figure draws, drags a
slider, and checks from pixels that the live (ipympl) figure changed, then saves the notebook
through JupyterLab and reads it back to check that every code cell ran and none errored. Each
drag's redraw time is reported (never asserted) as two numbers: the browser's, from the release
to the last draw of the figure's canvas, and the kernel's, the slider callback alone
(``update_ms`` of the explorer or the Designer, read from the notebook's kernel through its
connection file), beside the lines of text its blits took from the text cache and drew and a
timeline of the step (the values sent, the kernel's updates and widget messages, the images
and their bytes, ipympl's work on them in the page). Screenshots go to
``build/browser-screenshots/`` (kept by CI as artefacts). The server and its kernels are
stopped in every case (the process group it was started in).

Skipped, with the reason, only when Chromium is not installed (``apt-get install -y chromium``;
``.ci/run`` installs it).
"""
from __future__ import annotations

import ast
import io
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
SHOTS = ROOT / "build" / "browser-screenshots"
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    if CHROMIUM is None:
        pytest.skip("Debian's chromium is not installed (apt-get update && apt-get install -y chromium; .ci/run does it)")
    tmp = tmp_path_factory.mktemp("lab")
    root = tmp / "notebooks"
    root.mkdir()
    for name in ("03_specification.ipynb", "04_qft_design.ipynb"):
        shutil.copy(ROOT / "notebooks" / name, root / name)  # the browser saves outputs into the copies
    # every cell rendered in the DOM (no virtual scrolling), so the test can find the widget cells
    settings = tmp / "settings" / "@jupyterlab" / "notebook-extension"
    settings.mkdir(parents=True)
    (settings / "tracker.jupyterlab-settings").write_text(json.dumps({"windowingMode": "none"}))
    news = tmp / "settings" / "@jupyterlab" / "apputils-extension"
    news.mkdir(parents=True)
    (news / "notification.jupyterlab-settings").write_text(json.dumps({"fetchNews": "false"}))
    port, token = _free_port(), os.urandom(16).hex()
    env = {k: v for k, v in os.environ.items() if k != "MPLBACKEND"}  # the notebooks turn ipympl on
    env.update(SPECDESIGN_FAST="1", JUPYTER_RUNTIME_DIR=str(tmp / "runtime"), PYTHONPATH=os.pathsep.join(filter(None, [str(ROOT), env.get("PYTHONPATH")])))
    log = open(tmp / "jupyterlab.log", "w")
    proc = subprocess.Popen(
        [sys.executable, "-m", "jupyter", "lab", "--no-browser", "--ip=127.0.0.1", f"--port={port}",
         f"--IdentityProvider.token={token}", f"--ServerApp.root_dir={root}", f"--LabApp.user_settings_dir={tmp / 'settings'}",
         f"--LabApp.workspaces_dir={tmp / 'workspaces'}", "--LabApp.news_url=", "--ServerApp.port_retries=0", "--allow-root"],
        cwd=root, env=env, stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
    try:
        url = f"http://127.0.0.1:{port}"
        deadline = time.monotonic() + 90
        while True:
            try:
                with urllib.request.urlopen(f"{url}/api/status?token={token}", timeout=2) as r:
                    if r.status == 200:
                        break
            except OSError:
                pass
            if proc.poll() is not None or time.monotonic() > deadline:
                raise RuntimeError(f"JupyterLab did not start: {(tmp / 'jupyterlab.log').read_text()[-2000:]}")
            time.sleep(0.5)
        yield url, token, root, tmp / "runtime"
    finally:
        # the server and the kernels it started share its process group
        try:
            os.killpg(proc.pid, signal.SIGTERM)
            proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait(timeout=10)
        except ProcessLookupError:
            pass
        log.close()


@pytest.fixture(scope="module")
def browser(lab):
    from playwright.sync_api import sync_playwright

    with sync_playwright() as pw:
        b = pw.chromium.launch(executable_path=CHROMIUM, headless=True,
                               args=["--no-sandbox", "--disable-dev-shm-usage", "--disable-gpu"])
        try:
            yield b
        finally:
            b.close()


def _pixels(png: bytes) -> np.ndarray:
    import matplotlib.image

    return matplotlib.image.imread(io.BytesIO(png), format="png")


def _run_all(page, url, token, name, timeout_s):
    """Open ``name``, wait for its kernel, run all cells, wait until every code cell has run."""
    from playwright.sync_api import TimeoutError as PlaywrightTimeout

    page.goto(f"{url}/lab/tree/{name}?token={token}")
    page.wait_for_selector(".jp-Notebook .jp-CodeCell", timeout=60_000)
    panel = ".jp-NotebookPanel:not(.lm-mod-hidden)"  # the notebook just opened, not an earlier tab
    idle = "() => /\\| Idle/.test(document.querySelector('.jp-StatusBar-Widget')?.innerText || '')"
    prompts = f"() => [...document.querySelectorAll('{panel} .jp-CodeCell .jp-InputPrompt')].map(e => e.textContent)"
    dialog = page.locator(".jp-Dialog", has_text="Select Kernel")
    for attempt in range(3):
        time.sleep(2)
        if dialog.count():  # JupyterLab sometimes asks even though the notebook names python3
            dialog.locator(".jp-mod-accept").click()
        page.wait_for_function(idle, timeout=90_000)  # the kernel started and connected
        if dialog.count():  # ... also after the kernel said it is idle: it covered the menu once
            dialog.locator(".jp-mod-accept").click()
        try:  # a run-all sent while the kernel was still connecting is lost: send it again
            page.locator(f"{panel} .jp-Notebook").first.click(position={"x": 5, "y": 5}, timeout=10_000)
            page.locator(".lm-MenuBar-itemLabel", has_text="Run").first.click(timeout=10_000)
            page.locator(".lm-Menu-itemLabel").get_by_text("Run All Cells", exact=True).click(timeout=10_000)
            page.wait_for_function(f"() => ({prompts})().some(t => /\\[(\\*|\\d+)\\]/.test(t))", timeout=15_000)
            break
        except PlaywrightTimeout:
            if attempt == 2:
                raise
    page.wait_for_function(f"() => ({prompts})().every(t => /\\[\\d+\\]/.test(t))",
                           timeout=timeout_s * 1000, polling=500)
    return page.locator(panel)


def _saved_errors(page, root, name):
    """Save through JupyterLab, read the file: (cells not run, error outputs)."""
    path = root / name
    before = path.stat().st_mtime_ns
    # the toolbar's save button: a key press would go to a focused widget's text box
    page.locator(".jp-NotebookPanel:not(.lm-mod-hidden) [data-command='docmanager:save']").first.click()
    deadline = time.monotonic() + 30
    while path.stat().st_mtime_ns == before and time.monotonic() < deadline:
        time.sleep(0.3)
    assert path.stat().st_mtime_ns != before, f"JupyterLab did not save {name}"
    # the file's time moves when JupyterLab starts writing it: read it once the write is complete
    while True:
        try:
            nb = json.loads(path.read_text())
            break
        except json.JSONDecodeError:
            if time.monotonic() > deadline:
                raise
            time.sleep(0.3)
    code = [c for c in nb["cells"] if c["cell_type"] == "code"]
    not_run = [i for i, c in enumerate(code) if c.get("execution_count") is None]
    errors = [(o.get("ename"), o.get("evalue")) for c in code for o in c.get("outputs", []) if o.get("output_type") == "error"]
    return not_run, errors


def _drag(page, handle, dx):
    box = handle.bounding_box()
    x, y = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
    page.mouse.move(x, y)
    page.mouse.down()
    page.mouse.move(x + dx / 2, y, steps=5)
    page.mouse.move(x + dx, y, steps=5)
    page.mouse.up()


def _kernel_value(lab, name, expression):
    """``expression`` evaluated in the kernel of notebook ``name`` (its repr), beside the browser's session."""
    from jupyter_client import BlockingKernelClient

    url, token, _, runtime = lab
    with urllib.request.urlopen(f"{url}/api/sessions?token={token}", timeout=10) as r:
        kernel = next(s["kernel"]["id"] for s in json.load(r) if s["path"].endswith(name))
    client = BlockingKernelClient(connection_file=str(runtime / f"kernel-{kernel}.json"))
    client.load_connection_file()
    client.start_channels()
    try:
        # silent: nothing in the notebook's outputs or its execution count
        reply = client.execute_interactive("", silent=True, store_history=False,
                                           user_expressions={"value": expression}, timeout=30)
    finally:
        client.stop_channels()
    value = reply["content"]["user_expressions"]["value"]
    assert value["status"] == "ok", value
    return value["data"]["text/plain"]


#: In the page: true once JupyterLab's status bar has said the kernel is idle for 2 s on end.
_IDLE_FOR_2S = """() => {
  const idle = /\\| Idle/.test(document.querySelector('.jp-StatusBar-Widget')?.innerText || '');
  if (!idle) { window.__idle_since = null; return false; }
  window.__idle_since = window.__idle_since ?? performance.now();
  return performance.now() - window.__idle_since > 2000;
}"""


#: In the page: from the release of a slider handle (pointerup) to the last draw of the visible
#: canvas of the figure it drives: the time a user waits for the figure to settle. Measured by
#: hooks, not by polling the canvas (an earlier version compared ``toDataURL`` snapshots every
#: 5 ms: each snapshot is a PNG encode of the canvas on the page's one thread, which delayed the
#: very messages it timed). The hooks also record where the time goes: each value the slider
#: sends to the kernel (the page's websocket), each PNG image the figure receives from ipympl
#: (``URL.createObjectURL`` of its blob: arrival time, bytes), ipympl's own ``toDataURL`` of its
#: off-screen canvas at each image, and each ``drawImage`` (the decoded PNG onto the off-screen
#: canvas, that canvas onto the visible one). Reported (build/browser-screenshots/redraw_ms.json),
#: never asserted: speed belongs to benchmarks.
_WATCH_REDRAW = """([fig]) => {
  const rec = window.__rec = {up: null, sent: [], received: [], long: [], pngs: [], todata: [], decoded: [], shown: [], done: null};
  window.__fig_canvases = [...fig.querySelectorAll('canvas')];
  if (!window.__hooked) {  // once per page; the prototypes' methods, wrapped
    window.__hooked = true;
    const now = () => performance.now();
    // the page's tasks over 50 ms (the main thread busy: no message handled, nothing drawn)
    new PerformanceObserver(list => { for (const e of list.getEntries()) window.__rec?.long.push([e.startTime, e.duration]); })
      .observe({type: 'longtask'});
    const send = WebSocket.prototype.send, seen = new WeakSet();
    WebSocket.prototype.send = function (data) {
      if (!seen.has(this)) {  // the kernel's socket: each message it brings
        seen.add(this);
        this.addEventListener('message', () => window.__rec?.received.push(now()));
      }
      if (window.__rec) {  // a widget's state sent to the kernel with a value: the slider's
        const text = typeof data === 'string' ? data : new TextDecoder().decode(data);
        if (text.includes('comm_msg') && text.includes('"value"')) window.__rec.sent.push(now());
      }
      return send.apply(this, arguments);
    };
    const url = URL.createObjectURL;
    URL.createObjectURL = function (blob) {
      if (window.__rec && blob && blob.type === 'image/png') window.__rec.pngs.push([now(), blob.size]);
      return url.apply(this, arguments);
    };
    const toData = HTMLCanvasElement.prototype.toDataURL;
    HTMLCanvasElement.prototype.toDataURL = function () {
      const t = now(), out = toData.apply(this, arguments);
      if (window.__rec && !this.isConnected) window.__rec.todata.push([t, now() - t]);  // ipympl's, off screen
      return out;
    };
    const draw = CanvasRenderingContext2D.prototype.drawImage;
    CanvasRenderingContext2D.prototype.drawImage = function (src) {
      const t = now(), out = draw.apply(this, arguments), r = window.__rec;
      if (r && src instanceof HTMLImageElement && !this.canvas.isConnected) r.decoded.push([t, now() - t]);
      if (r && (window.__fig_canvases || []).includes(this.canvas)) r.shown.push(now());
      return out;
    };
  }
  document.addEventListener('pointerup', () => { rec.up = performance.now(); }, {capture: true, once: true});
  const tick = () => {
    const last = rec.shown.length ? rec.shown[rec.shown.length - 1] : null;
    if (rec.up !== null && performance.now() - Math.max(last ?? 0, rec.up) > 2000) {
      rec.done = last === null ? -1 : Math.max(0, last - rec.up); return;
    }
    setTimeout(tick, 50);
  };
  tick();
}"""


#: In the kernel (``exec``, ``{obj}`` the explorer or the Designer): its ``update`` wrapped to
#: record the wall-clock start and end of each call, ms (the page's clock is the same machine's).
_STAMP_UPDATES = """
def _stamped(*args, _update={obj}.update, _stamps=[], **kwargs):
    import time
    t0 = 1e3 * time.time()
    out = _update(*args, **kwargs)
    _stamps.append((t0, 1e3 * time.time()))
    return out
_stamped.stamps = _stamped.__kwdefaults__["_stamps"]
{obj}.update = _stamped
def _sent(self, msg, buffers=None, *, _send=__import__("ipywidgets").Widget._send, _log=[]):
    import time
    _log.append((1e3 * time.time(), type(self).__name__))
    return _send(self, msg, buffers)
__import__("ipywidgets").Widget._send = _sent
del _stamped, _sent
"""

#: In the kernel, after the drag: the messages its widgets sent, (wall-clock ms, widget class),
#: and ipywidgets as it was.
_SENT_MESSAGES = """(lambda w, wrapper: (setattr(w, "_send", wrapper.__kwdefaults__["_send"]), wrapper.__kwdefaults__["_log"])[1])(
    __import__("ipywidgets").Widget, __import__("ipywidgets").Widget._send)"""


def _timeline(rec):
    """The page's record of a drag (``_WATCH_REDRAW``) as ms after the release, per stage."""
    up = rec["up"]
    def after(ts):
        return [round(t - up, 1) for t in ts if t >= up]

    pngs = [(round(t - up, 1), n) for t, n in rec["pngs"] if t >= up]
    shown = [t for t in rec["shown"] if rec["sent"] and t >= rec["sent"][-1]]
    return {
        # from the last value the slider sent (during the drag or after the release) to the
        # last draw of the figure: the kernel's and the browser's share of the settle time
        "last_value_to_settled_ms": round(shown[-1] - rec["sent"][-1], 1) if shown else None,
        # the slider's values sent after the release (ipywidgets holds a value back while the
        # kernel handles the one before: the last is sent once the kernel is idle)
        "values_sent_ms": after(rec["sent"]),
        "values_sent_before_release": sum(t < up for t in rec["sent"]),
        # ipympl's images after the release: arrival (ms) and size (bytes)
        "images_ms_bytes": pngs,
        "images_during_drag": sum(t < up for t, _ in rec["pngs"]),
        # ipympl re-encodes its whole off-screen canvas as a data URL at every image
        "ipympl_todataurl_ms": [round(d, 1) for t, d in rec["todata"] if t >= up],
        "png_drawn_ms": after([t for t, _ in rec["decoded"]]),
        "canvas_shown_ms": after(rec["shown"]),
        # every message the page's sockets brought after the release (the kernel's: images,
        # widget states, status), and the page's tasks over 50 ms (start, duration)
        "messages_received_ms": after(rec["received"]),
        "long_tasks_ms": [(round(t - up, 1), round(d, 1)) for t, d in rec["long"] if t + d >= up],
        # the kernel's updates (start, end) after the release, on the page's clock
        "kernel_updates_ms": [(round(a - rec["origin"] - up, 1), round(b - rec["origin"] - up, 1))
                              for a, b in rec["kernel"] if b - rec["origin"] >= up],
        # the messages the kernel's widgets sent after the release: (ms, the widget's class)
        "kernel_messages_ms": [(round(t - rec["origin"] - up, 1), w) for t, w in rec["kernel_sent"] if t - rec["origin"] >= up],
    }


def _timed_drag(page, lab, name, obj, figure, handle, dx, what):
    """Drag ``handle`` by ``dx`` px; record how long after the release the figure settled and
    how long the kernel's last slider callback took (``obj.update_ms`` in the kernel), ms, and
    whether the callback blitted (``obj._redraw.ready``) or asked for a full redraw.

    The acceptance (issue 30) is ≤ 150 ms on an idle machine; this machine may not be idle, so
    both numbers are written with the load average beside them
    (build/browser-screenshots/redraw_ms.json) and not asserted (speed belongs to benchmarks).
    """
    # the kernel idle for 2 s first: after Run All the browser asks the kernel to render each
    # live figure of the notebook once, and a drag queued behind those renders would time them
    page.evaluate("window.__idle_since = null")
    page.wait_for_function(_IDLE_FOR_2S, timeout=120_000, polling=100)
    page.evaluate(_WATCH_REDRAW, [figure.element_handle()])
    # the kernel's side of the same timeline: the wall-clock start and end (ms) of each update
    # the drag causes, by a wrapper on the object's own update, removed after
    _kernel_value(lab, name, f"exec({_STAMP_UPDATES.format(obj=obj)!r})")
    _drag(page, handle, dx)
    page.wait_for_function("window.__rec.done !== null", timeout=60_000)
    rec = page.evaluate("window.__rec")
    rec["kernel"] = ast.literal_eval(_kernel_value(lab, name, f"{obj}.__dict__.pop('update').stamps"))
    rec["kernel_sent"] = ast.literal_eval(_kernel_value(lab, name, _SENT_MESSAGES))
    rec["origin"] = page.evaluate("performance.timeOrigin")
    ms = float(rec["done"])
    assert ms >= 0, f"{what}: the figure's canvas was never drawn after the drag"
    callback_ms = float(_kernel_value(lab, name, f"{obj}.update_ms"))
    blitted = _kernel_value(lab, name, f"{obj}._redraw.ready") == "True"
    # lines of text the blits wrote from the cache / rasterised (CachedTextRenderer)
    text = ast.literal_eval(_kernel_value(lab, name, f"(lambda t: (t.hits, t.misses) if t else (0, 0))({obj}._redraw._text)"))
    load = os.getloadavg()[0]
    SHOTS.mkdir(parents=True, exist_ok=True)
    out = SHOTS / "redraw_ms.json"
    times = json.loads(out.read_text()) if out.is_file() else {}
    times[what] = {"ms": round(ms, 1), "callback_ms": round(callback_ms, 1), "blitted": blitted,
                   "text_lines_cached": text[0], "text_lines_drawn": text[1], "load_1min": load,
                   "timeline": _timeline(rec)}
    out.write_text(json.dumps(times, indent=1))
    print(f"{what}: the figure settled {ms:.0f} ms after the release, the kernel's callback took "
          f"{callback_ms:.0f} ms, {'blitted' if blitted else 'full redraw'}, {text[0]} lines of text from the cache "
          f"and {text[1]} drawn (load {load:.1f}; acceptance on an idle machine: ≤ 150 ms); ms after the release: "
          f"{json.dumps(times[what]['timeline'])}")
    # on ipympl's canvas, once the browser showed the figure, a move blits (a full redraw of the
    # Designer's bounds took 0.5 s of the kernel alone). The text cache's hits are recorded, not
    # asserted: a short drag off the design changes the Designer's verdict lines at every step,
    # and their new heights move the lines below, so it may find none
    assert blitted, f"{what}: the slider's redraw was a full redraw, not a blit"
    return ms


def _wait_changed(figure, before, timeout_s=40.0):
    """The canvas once it differs from ``before`` and has stopped changing: (pixels, changed fraction)."""
    deadline = time.monotonic() + timeout_s
    last = before
    while True:
        time.sleep(1.0)
        after = _pixels(figure.screenshot())
        changed = float(np.mean(np.any(after != before, axis=-1))) if after.shape == before.shape else 1.0
        settled = after.shape == last.shape and np.array_equal(after, last)
        if (changed > 0.001 and settled) or time.monotonic() > deadline:
            return after, changed
        last = after


@pytest.mark.slow
def test_notebook_03_explorer_slider_redraws_the_figure(lab, browser):
    url, token, root, _ = lab
    SHOTS.mkdir(parents=True, exist_ok=True)
    page = browser.new_page(viewport={"width": 1400, "height": 1000})
    try:
        nb = _run_all(page, url, token, "03_specification.ipynb", timeout_s=150)
        cell = nb.locator(".jp-CodeCell", has_text="explorer.widget()").first
        cell.scroll_into_view_if_needed()
        figures = cell.locator(".jupyter-matplotlib-figure")
        figures.first.wait_for(timeout=30_000)
        assert figures.count() == 1  # one figure, no copy beside the widget
        sliders = cell.locator(".widget-slider")
        assert sliders.count() == 3 and cell.locator(".widget-checkbox").count() == 0  # no "redraw" box
        canvas = figures.first.locator("canvas").first
        page.screenshot(path=str(SHOTS / "03_explorer_before.png"), full_page=False)
        before = _pixels(canvas.screenshot())
        title_before = cell.locator(".widget-readout").nth(1).inner_text()
        readout_before = cell.locator(".widget-html").last.inner_text().strip()
        assert readout_before.startswith("notch at "), readout_before
        # after Run All the depth slider shows the notch the figure draws: a later cell set it
        # to 12 dB (explorer.update(1.05, 12.0, 0.2)); it showed 2.80 dB once
        assert float(title_before) == pytest.approx(12.0), title_before
        notch = _kernel_value(lab, "03_specification.ipynb", "(explorer.notch.omega_n, explorer.notch.depth_db, explorer.notch.width)")
        shown = [float(cell.locator(".widget-readout").nth(i).inner_text()) for i in range(3)]
        # within half a slider step (the browser rounds a value to its step) and the readout's digits
        omega_n, depth, width = ast.literal_eval(notch)
        assert shown[0] == pytest.approx(omega_n, rel=10**0.0025 - 1 + 5e-4), (shown, notch)
        assert shown[1] == pytest.approx(depth, abs=0.051) and shown[2] == pytest.approx(width, abs=0.0051), (shown, notch)
        # the QFT verdict of a move is a comparison with precomputed brackets, not a bound computation
        assert _kernel_value(lab, "03_specification.ipynb", "explorer.bounds_checker.precomputed") == "True"
        _timed_drag(page, lab, "03_specification.ipynb", "explorer", figures.first,
                    sliders.nth(1).locator(".noUi-handle"), 60, "notebook 03 depth slider")
        after, changed = _wait_changed(canvas, before)
        cell.screenshot(path=str(SHOTS / "03_explorer_after.png"))
        assert cell.locator(".widget-readout").nth(1).inner_text() != title_before
        # the notch and its verdicts in the readout above the figure, as the kernel has them
        readout = cell.locator(".widget-html").last.inner_text().strip()
        assert readout == ast.literal_eval(_kernel_value(lab, "03_specification.ipynb", "explorer.readout")), readout
        assert readout_before != readout
        assert changed > 0.001, f"the figure did not change after the depth slider moved ({changed:.4%} of pixels)"
        not_run, errors = _saved_errors(page, root, "03_specification.ipynb")
        assert not not_run and not errors, (not_run, errors)
    finally:
        page.screenshot(path=str(SHOTS / "03_final.png"), full_page=True)
        page.close()


@pytest.mark.slow
def test_notebook_04_designer_gain_edit_redraws_the_figure(lab, browser):
    url, token, root, _ = lab
    SHOTS.mkdir(parents=True, exist_ok=True)
    page = browser.new_page(viewport={"width": 1400, "height": 1100})
    try:
        nb = _run_all(page, url, token, "04_qft_design.ipynb", timeout_s=170)
        cell = nb.locator(".jp-CodeCell", has_text="designer.widget()").first
        cell.scroll_into_view_if_needed()
        figures = cell.locator(".jupyter-matplotlib-figure")
        figures.first.wait_for(timeout=30_000)
        assert figures.count() == 1  # the Designer shows its figure once
        canvas = figures.first.locator("canvas").first
        before = _pixels(canvas.screenshot())
        cell.screenshot(path=str(SHOTS / "04_designer_before.png"))
        gain = cell.locator(".widget-slider").first  # the selected element 0: the gain
        json_box = cell.locator("textarea").first
        k_before = json.loads(json_box.input_value())["elements"][0]["params"]["k"]
        # after Run All (a later cell set the gain 20 dB high and back, from code) the controls
        # show the controller the figure draws: the JSON exactly, the slider's readout to its
        # 4 digits, the exact box exactly
        assert k_before == float(_kernel_value(lab, "04_qft_design.ipynb", "designer.controller.elements[0].params['k']"))
        shown = float(gain.locator(".widget-readout").inner_text())  # within half a step (0.0025 decade) and 4 digits
        assert shown == pytest.approx(abs(k_before), rel=10**0.0025 - 1 + 5e-4), (shown, k_before)
        assert float(cell.locator(".widget-text input").first.input_value()) == k_before
        _timed_drag(page, lab, "04_qft_design.ipynb", "designer", figures.first,
                    gain.locator(".noUi-handle"), 40, "notebook 04 Designer gain")
        after, changed = _wait_changed(canvas, before)
        page.wait_for_function("([el, k]) => JSON.parse(el.value).elements[0].params.k !== k",
                               arg=[json_box.element_handle(), k_before], timeout=20_000)
        k_after = json.loads(json_box.input_value())["elements"][0]["params"]["k"]
        # the verdict in the readout above the figure, as the kernel has it (summary())
        readout = cell.locator(".widget-html").last.inner_text().strip()
        assert readout == ast.literal_eval(_kernel_value(lab, "04_qft_design.ipynb", "designer.readout")), readout
        assert f"G = gain(k={k_after:.6g})" in readout, (readout, k_after)  # the dragged gain
        # a 40-pixel drag is a fraction of a decade, in the gain's sign (not three decades)
        assert k_after * k_before > 0 and 0.02 < abs(np.log10(k_after / k_before)) < 0.6, (k_before, k_after)
        cell.screenshot(path=str(SHOTS / "04_designer_after_drag.png"))
        assert changed > 0.001, f"the Designer's figure did not change after the gain moved ({changed:.4%} of pixels)"
        # a typed gain is kept exactly (the controller's JSON shows it)
        exact = cell.locator(".widget-text input").first
        exact.fill("-0.0123456789")
        exact.press("Enter")
        page.wait_for_function("(el) => JSON.parse(el.value).elements[0].params.k === -0.0123456789",
                               arg=json_box.element_handle(), timeout=20_000)
        _, changed = _wait_changed(canvas, after)
        assert changed > 0.001, f"the Designer's figure did not change after a typed gain ({changed:.4%} of pixels)"
        cell.screenshot(path=str(SHOTS / "04_designer_typed_gain.png"))
        not_run, errors = _saved_errors(page, root, "04_qft_design.ipynb")
        assert not not_run and not errors, (not_run, errors)
    finally:
        page.screenshot(path=str(SHOTS / "04_final.png"), full_page=True)
        page.close()
