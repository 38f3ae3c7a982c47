"""A headless Chromium driven over the DevTools protocol on a pipe (--remote-debugging-pipe: JSON
messages ended by NUL on file descriptors 3 and 4), standard library only: load a page from
disk, evaluate script, click with real mouse events, press keys, take screenshots."""

import base64
import fcntl
import json
import os
import shutil
import subprocess
import tempfile
import time

NAMES = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")


def find_chromium():
    """The browser binary: UMBRA_CHROMIUM, else the first of NAMES on PATH; None if none."""
    override = os.environ.get("UMBRA_CHROMIUM")
    if override:
        return override
    for n in NAMES:
        p = shutil.which(n)
        if p:
            return p
    return None


class Browser:
    def __init__(self, binary, width=1400, height=1000, timeout=60.0):
        self.timeout = timeout
        self.profile = tempfile.mkdtemp(prefix="umbra-chromium-")
        to_browser_r, to_browser_w = os.pipe()
        from_browser_r, from_browser_w = os.pipe()

        args = [binary, "--headless", "--no-sandbox", "--disable-gpu", "--remote-debugging-pipe",
                "--no-first-run", "--no-default-browser-check", "--disable-extensions",
                f"--user-data-dir={self.profile}", f"--window-size={width},{height}",
                "about:blank"]
        # The protocol's pipe is descriptors 3 (to the browser) and 4 (from it): the shell puts
        # the pipe's ends there and closes the originals, then becomes the browser (bash: dash
        # redirects single-digit descriptors only).
        # (Above 9 first, so that neither end already sits on 3 or 4.)
        r = fcntl.fcntl(to_browser_r, fcntl.F_DUPFD, 10)
        w = fcntl.fcntl(from_browser_w, fcntl.F_DUPFD, 10)
        self.proc = subprocess.Popen(
            ["bash", "-c", f'exec "$0" "$@" 3<&{r} 4>&{w} {r}<&- {w}>&-', *args],
            pass_fds=(r, w), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        for fd in (r, w, to_browser_r, from_browser_w):
            os.close(fd)
        self.out = os.fdopen(to_browser_w, "wb")
        self.inp = os.fdopen(from_browser_r, "rb")
        self.next_id = 0
        self.buf = b""
        self.session = None
        self.size = (width, height)

    def call(self, method, params=None, session=True):
        self.next_id += 1
        msg = {"id": self.next_id, "method": method, "params": params or {}}
        if session and self.session:
            msg["sessionId"] = self.session
        self.out.write(json.dumps(msg).encode() + b"\0")
        self.out.flush()
        deadline = time.monotonic() + self.timeout
        while True:
            while b"\0" not in self.buf:
                if time.monotonic() > deadline:
                    raise TimeoutError(f"{method}: no answer in {self.timeout} s")
                chunk = self.inp.read1(1 << 16)
                if not chunk:
                    raise RuntimeError(f"{method}: the browser closed the pipe")
                self.buf += chunk
            raw, self.buf = self.buf.split(b"\0", 1)
            m = json.loads(raw)
            if m.get("id") == self.next_id:
                if "error" in m:
                    raise RuntimeError(f"{method}: {m['error']}")
                return m["result"]

    def open(self, path):
        """Loads the file at `path` in a new tab and waits for it to finish loading."""
        target = self.call("Target.createTarget", {"url": "about:blank"}, session=False)
        self.session = self.call("Target.attachToTarget",
                                 {"targetId": target["targetId"], "flatten": True},
                                 session=False)["sessionId"]
        w, h = self.size
        self.call("Emulation.setDeviceMetricsOverride",
                  {"width": w, "height": h, "deviceScaleFactor": 1, "mobile": False})
        self.call("Page.navigate", {"url": "file://" + os.path.abspath(path)})
        self.wait_for("document.readyState === 'complete'")

    def eval(self, expression):
        r = self.call("Runtime.evaluate", {"expression": expression, "returnByValue": True,
                                           "awaitPromise": True})
        if "exceptionDetails" in r:
            raise RuntimeError(f"{expression}: {r['exceptionDetails']}")
        return r["result"].get("value")

    def wait_for(self, expression, timeout=None):
        deadline = time.monotonic() + (timeout or self.timeout)
        while not self.eval(expression):
            if time.monotonic() > deadline:
                raise TimeoutError(f"waited for {expression}")
            time.sleep(0.05)

    def click(self, selector, fraction=(0.5, 0.5)):
        """A real mouse click (pressed, released) at `fraction` of the element's box, after
        scrolling it into view."""
        box = self.eval(
            f"(function(){{var e=document.querySelector({json.dumps(selector)});"
            "e.scrollIntoView({block:'center'});var r=e.getBoundingClientRect();"
            "return [r.left,r.top,r.width,r.height];})()")
        x, y = box[0] + box[2] * fraction[0], box[1] + box[3] * fraction[1]
        for kind in ("mouseMoved", "mousePressed", "mouseReleased"):
            self.call("Input.dispatchMouseEvent", {"type": kind, "x": x, "y": y, "button": "left",
                                                   "clickCount": 1})

    def key(self, selector, key, code):
        """Focuses the element and presses one key (keyDown, keyUp)."""
        self.eval(f"document.querySelector({json.dumps(selector)}).focus()")
        for kind in ("keyDown", "keyUp"):
            self.call("Input.dispatchKeyEvent", {"type": kind, "key": key, "code": code,
                                                 "windowsVirtualKeyCode": {"ArrowDown": 40}.get(key, 0)})

    def screenshot(self, path, clip_selector=None):
        params = {"format": "png"}
        if clip_selector:
            r = self.eval(
                f"(function(){{var e=document.querySelector({json.dumps(clip_selector)});"
                "var r=e.getBoundingClientRect();"
                "return [r.left+scrollX,r.top+scrollY,r.width,r.height];})()")
            # Whole pixels: a fractional clip resamples the capture.
            x, y = round(r[0]), round(r[1])
            params["clip"] = {"x": x, "y": y, "width": round(r[0] + r[2]) - x,
                              "height": min(round(r[1] + r[3]) - y, 2000), "scale": 1}
            params["captureBeyondViewport"] = True
        data = base64.b64decode(self.call("Page.captureScreenshot", params)["data"])
        with open(path, "wb") as f:
            f.write(data)
        return data

    def close(self):
        try:
            self.call("Browser.close", session=False)
            self.proc.wait(10)
        except Exception:
            self.proc.kill()
            self.proc.wait(10)
        shutil.rmtree(self.profile, ignore_errors=True)
