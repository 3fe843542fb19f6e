"""Open a page in headless Chromium: a screenshot, the drawn figures' boxes and every JavaScript error.

For the tests of the HTML views and the docs' screenshots (the same helper
makes both).  Chromium is Debian's ``chromium`` package; it is driven over
the DevTools protocol on 127.0.0.1 (``websocket-client``, in the test
extra), which reports uncaught exceptions and console errors with their
level and tells when plotly.js has drawn every figure, so nothing waits a
fixed time.
"""

from __future__ import annotations

import base64
import contextlib
import json
import os
import shutil
import signal
import subprocess
import tempfile
import time
import urllib.request
from dataclasses import dataclass
from pathlib import Path

__all__ = ["CHROMIUM", "Capture", "capture", "chromium"]

#: Where Debian's package puts it.
CHROMIUM = "/usr/bin/chromium"
_FLAGS = (
    "--headless",
    "--no-sandbox",  # as root
    "--disable-gpu",
    "--enable-unsafe-swiftshader",  # WebGL on the CPU (plotly's 3D), without the deprecation warning
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--remote-debugging-address=127.0.0.1",
    "--remote-debugging-port=0",  # any free port: Chromium writes it into DevToolsActivePort
)
# Once every plotly figure on the page is drawn (its WebGL canvas there), their plot areas (the 3D
# scene, without title and legend) as boxes [x, y, width, height] in the window.
_DRAWN = """(() => {
  const divs = [...document.querySelectorAll(".js-plotly-plot")];
  if (!divs.length || !divs.every(d => d._fullLayout && d.querySelector(".gl-container canvas"))) return null;
  return divs.map(d => { const r = d.getBoundingClientRect(), s = d._fullLayout._size;
                         return [r.x + s.l, r.y + s.t, s.w, s.h]; });
})()"""
_FRAMES = "new Promise(r => requestAnimationFrame(() => requestAnimationFrame(() => setTimeout(r, 200))))"


@dataclass(frozen=True)
class Capture:
    """What :func:`capture` saw: the PNG written, each figure's plot area (its 3D scene, without
    title and legend) as ``[x, y, w, h]`` in the window's pixels, and the JavaScript errors
    (uncaught exceptions and console errors)."""

    png: Path
    scenes: list
    errors: list


def chromium() -> str | None:
    """The Chromium to use: :data:`CHROMIUM`, or ``chromium`` on the PATH, or None."""
    return CHROMIUM if os.access(CHROMIUM, os.X_OK) else shutil.which("chromium")


def capture(page, png, *, size=(1200, 900), timeout=60.0, scroll_to=0, before=None) -> Capture:
    """Open ``page`` (a local file) in headless Chromium and screenshot it to ``png`` once drawn.

    Parameters
    ----------
    page, png : str or Path
    size : (int, int)
        The window, in CSS pixels (the PNG's size).
    timeout : float
        Seconds for the whole visit; a page not drawn by then raises TimeoutError.
    scroll_to : int
        The figure (0-based) scrolled to the top of the window before the screenshot.
    before : str, optional
        JavaScript run (and awaited, if a promise) once drawn, before the
        screenshot: ``figures`` holds the page's plotly divs, e.g.
        ``Plotly.animate(figures[1], ["10"], {mode: "immediate"})`` shows frame 10.
    """
    import websocket  # websocket-client, in the test extra

    exe = chromium()
    if exe is None:
        raise FileNotFoundError(f"no Chromium at {CHROMIUM} (apt-get install chromium)")
    profile = tempfile.mkdtemp(prefix="grasptwist-chromium-")
    # Chromium's own temporary files (org.chromium.Chromium.*) go inside the profile, and its
    # helper processes share a session with it, so that nothing of a visit outlives it.
    scratch = Path(profile) / "tmp"
    scratch.mkdir()
    proc = subprocess.Popen(
        [exe, *_FLAGS, f"--user-data-dir={profile}", f"--window-size={size[0]},{size[1]}", "about:blank"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        env={**os.environ, "TMPDIR": str(scratch)},
        start_new_session=True,
    )
    deadline = time.monotonic() + timeout
    try:
        port = _port(Path(profile) / "DevToolsActivePort", deadline, proc)
        with urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list", timeout=10) as answer:
            target = next(t for t in json.load(answer) if t["type"] == "page")
        ws = websocket.create_connection(target["webSocketDebuggerUrl"], timeout=timeout, suppress_origin=True)
        try:
            return _visit(_Session(ws, deadline), Path(page).resolve().as_uri(), Path(png), size, scroll_to, before)
        finally:
            ws.close()
    finally:
        _end(proc)
        shutil.rmtree(profile, ignore_errors=True)


def _end(proc):
    """Chromium and every helper process it started (its session), ended and reaped."""
    for sig, wait in ((signal.SIGTERM, 10), (signal.SIGKILL, None)):
        with contextlib.suppress(ProcessLookupError):  # the whole session is already gone
            os.killpg(proc.pid, sig)
        try:
            proc.wait(wait)
            return
        except subprocess.TimeoutExpired:
            continue


def _port(file, deadline, proc) -> int:
    while time.monotonic() < deadline:
        if file.is_file() and file.read_text().strip():
            return int(file.read_text().split()[0])
        if proc.poll() is not None:
            raise RuntimeError(f"Chromium exited with status {proc.returncode} before listening")
        time.sleep(0.05)
    raise TimeoutError("Chromium did not open its DevTools port")


class _Session:
    """Commands to one page over the DevTools protocol; the events in between are kept for errors."""

    def __init__(self, ws, deadline):
        self.ws, self.deadline, self.next_id, self.errors = ws, deadline, 0, []

    def call(self, method, **params):
        self.next_id += 1
        self.ws.send(json.dumps({"id": self.next_id, "method": method, "params": params}))
        while True:
            message = json.loads(self.ws.recv())
            if message.get("id") == self.next_id:
                if "error" in message:
                    raise RuntimeError(f"{method}: {message['error']}")
                return message["result"]
            self._event(message)

    def _event(self, message):
        params = message.get("params", {})
        if message.get("method") == "Runtime.exceptionThrown":
            details = params["exceptionDetails"]
            self.errors.append(details.get("exception", {}).get("description") or details.get("text"))
        elif message.get("method") == "Runtime.consoleAPICalled" and params.get("type") in ("error", "assert"):
            self.errors.append(" ".join(str(a.get("value", a.get("description"))) for a in params["args"]))
        elif message.get("method") == "Log.entryAdded" and params["entry"]["level"] == "error":
            self.errors.append(params["entry"]["text"])

    def evaluate(self, expression):
        result = self.call("Runtime.evaluate", expression=expression, awaitPromise=True, returnByValue=True)
        if "exceptionDetails" in result:
            raise RuntimeError(f"{expression[:40]}...: {result['exceptionDetails']}")
        return result["result"].get("value")


def _visit(session, url, png, size, scroll_to, before) -> Capture:
    for domain in ("Runtime", "Log", "Page"):
        session.call(f"{domain}.enable")
    session.call("Emulation.setDeviceMetricsOverride", width=size[0], height=size[1], deviceScaleFactor=1, mobile=False)
    session.call("Page.navigate", url=url)
    while (scenes := session.evaluate(_DRAWN)) is None:
        if time.monotonic() > session.deadline:
            raise TimeoutError(f"{url}: the figures were not drawn in time (errors: {session.errors})")
        time.sleep(0.1)
    figures = "const figures = document.querySelectorAll('.js-plotly-plot');"
    if before:
        session.evaluate(f"(async () => {{ {figures} await ({before}); }})()")
    if scroll_to:
        session.evaluate(f"{{ {figures} figures[{scroll_to}].scrollIntoView(); }}")
        scenes = session.evaluate(_DRAWN)
    session.evaluate(_FRAMES)  # the WebGL canvases painted
    shot = session.call("Page.captureScreenshot", format="png")
    png.write_bytes(base64.b64decode(shot["data"]))
    session.evaluate("0")  # collect the events that came with the screenshot
    return Capture(png, scenes, list(session.errors))
