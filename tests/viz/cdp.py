"""A tiny Chrome DevTools Protocol client over ``--remote-debugging-pipe``.

No websocket library is needed: with ``--remote-debugging-pipe`` Chromium
reads NUL-terminated JSON commands from fd 3 and writes replies/events to
fd 4. Every wait is bounded by a deadline; the browser runs in its own
process group with a fresh profile and is always killed at the end.

Used by the report tests to open an HTML file, wait until plotly has drawn,
take a screenshot and collect JavaScript errors and network requests.
"""

from __future__ import annotations

import base64
import json
import os
import select
import shutil
import signal
import subprocess
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--no-default-browser-check",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--disable-extensions",
    "--disable-dev-shm-usage",
    "--mute-audio",
    "--hide-scrollbars",
    # WebGL (plotly's 3D scene) in software, since there is no GPU
    "--enable-unsafe-swiftshader",
    "--use-angle=swiftshader",
]


def find_chromium() -> str | None:
    """Path of a Chromium binary, or None when none is installed."""
    for name in ("chromium", "chromium-browser", "google-chrome", "chrome"):
        path = shutil.which(name)
        if path:
            return path
    return None


@dataclass
class PageResult:
    """What a page load produced."""

    screenshot: bytes
    errors: list[str] = field(default_factory=list)
    requests: list[str] = field(default_factory=list)
    probe: Any = None


class CDPError(RuntimeError):
    pass


class Browser:
    """Headless Chromium driven over the DevTools pipe (use as a context manager)."""

    def __init__(self, binary: str, *, timeout: float = 60.0) -> None:
        self.binary = binary
        self.timeout = timeout
        self._id = 0
        self._buf = b""
        self._events: list[dict[str, Any]] = []
        self.proc: subprocess.Popen | None = None
        self.profile = tempfile.mkdtemp(prefix="fm2uav-chromium-")

    # ------------------------------------------------------------- process
    def __enter__(self) -> Browser:
        r_cmd, self._w_cmd = os.pipe()
        self._r_resp, w_resp = os.pipe()
        args = [self.binary, *FLAGS, f"--user-data-dir={self.profile}",
                "--remote-debugging-pipe", "about:blank"]
        self._stderr = open(Path(self.profile) / "stderr.log", "wb")  # noqa: SIM115
        # the child gets our pipe ends as fds 3 (commands in) and 4 (replies out)
        # (bash, not sh: dash only redirects single-digit descriptors)
        self.proc = subprocess.Popen(
            ["bash", "-c", f'exec "$@" 3<&{r_cmd} 4>&{w_resp}', "bash", *args],
            pass_fds=(r_cmd, w_resp), stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
            stderr=self._stderr, start_new_session=True,
        )
        os.close(r_cmd)
        os.close(w_resp)
        return self

    def __exit__(self, *exc: Any) -> None:
        try:
            if self.proc is not None and self.proc.poll() is None:
                try:
                    self.call("Browser.close", timeout=5)
                except Exception:
                    pass
                try:
                    self.proc.wait(timeout=5)
                except subprocess.TimeoutExpired:
                    pass
        finally:
            if self.proc is not None and self.proc.poll() is None:
                try:
                    os.killpg(self.proc.pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass
                self.proc.wait(timeout=10)
            for fd in (self._w_cmd, self._r_resp):
                try:
                    os.close(fd)
                except OSError:
                    pass
            self._stderr.close()
            shutil.rmtree(self.profile, ignore_errors=True)

    def stderr_tail(self, n: int = 2000) -> str:
        try:
            return (Path(self.profile) / "stderr.log").read_text(errors="replace")[-n:]
        except OSError:
            return ""

    # ------------------------------------------------------------- protocol
    def _send(self, method: str, params: dict | None, session: str | None) -> int:
        self._id += 1
        msg: dict[str, Any] = {"id": self._id, "method": method, "params": params or {}}
        if session:
            msg["sessionId"] = session
        os.write(self._w_cmd, json.dumps(msg).encode() + b"\0")
        return self._id

    def _pump(self, deadline: float) -> bool:
        """Read available messages until the deadline; False on timeout."""
        left = deadline - time.monotonic()
        if left <= 0:
            return False
        ready, _, _ = select.select([self._r_resp], [], [], min(left, 0.5))
        if not ready:
            if self.proc is not None and self.proc.poll() is not None:
                raise CDPError(f"chromium exited with code {self.proc.returncode}: "
                               f"{self.stderr_tail()}")
            return True
        chunk = os.read(self._r_resp, 1 << 20)
        if not chunk:
            raise CDPError(f"chromium closed the DevTools pipe: {self.stderr_tail()}")
        self._buf += chunk
        while b"\0" in self._buf:
            raw, self._buf = self._buf.split(b"\0", 1)
            self._events.append(json.loads(raw))
        return True

    def call(self, method: str, params: dict | None = None, *, session: str | None = None,
             timeout: float | None = None) -> dict[str, Any]:
        """Send a command and wait (bounded) for its reply."""
        mid = self._send(method, params, session)
        deadline = time.monotonic() + (timeout or self.timeout)
        while True:
            for i, m in enumerate(self._events):
                if m.get("id") == mid:
                    del self._events[i]
                    if "error" in m:
                        raise CDPError(f"{method}: {m['error']}")
                    return m.get("result", {})
            if not self._pump(deadline):
                raise CDPError(f"{method}: no reply within {timeout or self.timeout:g} s")

    def wait_event(self, method: str, *, session: str | None = None,
                   timeout: float | None = None) -> dict[str, Any]:
        deadline = time.monotonic() + (timeout or self.timeout)
        seen = 0
        while True:
            for m in self._events[seen:]:
                if m.get("method") == method and (session is None or m.get("sessionId") == session):
                    return m
            seen = len(self._events)
            if not self._pump(deadline):
                raise CDPError(f"no {method} event within {timeout or self.timeout:g} s")

    # ------------------------------------------------------------- high level
    def load(self, url: str, *, ready_js: str, probe_js: str = "null",
             width: int = 1280, height: int = 1000, settle: float = 1.0) -> PageResult:
        """Open ``url``, wait until ``ready_js`` is true, screenshot, collect errors."""
        target = self.call("Target.createTarget", {"url": "about:blank"})["targetId"]
        session = self.call("Target.attachToTarget",
                            {"targetId": target, "flatten": True})["sessionId"]
        for domain in ("Page", "Runtime", "Log", "Network"):
            self.call(f"{domain}.enable", session=session)
        self.call("Emulation.setDeviceMetricsOverride",
                  {"width": width, "height": height, "deviceScaleFactor": 1, "mobile": False},
                  session=session)
        self.call("Page.navigate", {"url": url}, session=session)
        self.wait_event("Page.loadEventFired", session=session)
        deadline = time.monotonic() + self.timeout
        while True:
            r = self.call("Runtime.evaluate", {"expression": ready_js, "returnByValue": True},
                          session=session)
            if r.get("result", {}).get("value") is True:
                break
            if time.monotonic() > deadline:
                raise CDPError(f"page not ready within {self.timeout:g} s: {ready_js}")
            self._pump(time.monotonic() + 0.2)
        end = time.monotonic() + settle  # let WebGL draw a few frames
        while time.monotonic() < end:
            self._pump(end)
        probe = self.call("Runtime.evaluate", {"expression": probe_js, "returnByValue": True},
                          session=session).get("result", {}).get("value")
        shot = self.call("Page.captureScreenshot", {"format": "png"}, session=session)
        errors, requests = [], []
        for m in self._events:
            if m.get("sessionId") != session:
                continue
            meth, p = m.get("method"), m.get("params", {})
            if meth == "Runtime.exceptionThrown":
                d = p.get("exceptionDetails", {})
                errors.append("exception: " + str(d.get("exception", {}).get("description")
                                                  or d.get("text")))
            elif meth == "Runtime.consoleAPICalled" and p.get("type") in ("error", "assert"):
                errors.append("console.error: " + " ".join(
                    str(a.get("value", a.get("description", ""))) for a in p.get("args", [])))
            elif meth == "Log.entryAdded" and p.get("entry", {}).get("level") == "error":
                errors.append("log: " + str(p["entry"].get("text")))
            elif meth == "Network.requestWillBeSent":
                requests.append(p.get("request", {}).get("url", ""))
        return PageResult(base64.b64decode(shot["data"]), errors, requests, probe)
