"""A headless Chromium driven over the DevTools protocol, for the report's browser tests.

Why not ``--dump-dom`` and a log scrape: the tests must know whether *anything* executed
(a JavaScript dialog, an exception, a console error) and whether elements are visible, which only
the DevTools protocol reports reliably. It runs over ``--remote-debugging-pipe`` (messages on
file descriptors 3 and 4, separated by NUL bytes), so it needs no websocket package and opens
no network port.
"""

from __future__ import annotations

import base64
import fcntl
import json
import os
import select
import shutil
import subprocess
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from tests.support.paths import ROOT

FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--hide-scrollbars",
    "--remote-debugging-pipe",
]
TIMEOUT = 60.0


def chromium_path() -> str | None:
    """Debian's ``chromium`` (``.ci/run`` installs it), or another Chrome found on PATH."""
    for name in ("chromium", "chromium-browser", "google-chrome", "chrome"):
        path = shutil.which(name)
        if path:
            return path
    return None


SCREENSHOTS = ROOT / "reports" / "screenshots"  # git ignores it


def require_chromium() -> None:
    """Skip the calling test, saying why and how to fix it, when no browser is installed."""
    if chromium_path() is None:
        import pytest

        pytest.skip(
            "headless Chromium not found: install Debian's chromium package "
            "(`apt-get install -y chromium`; .ci/run does it when apt is available)"
        )


class CdpError(RuntimeError):
    """The browser answered a command with an error, or stopped answering."""


@dataclass
class PageLog:
    """What the page did that a report must never do: dialogs, exceptions, console errors."""

    dialogs: list[str] = field(default_factory=list)
    exceptions: list[str] = field(default_factory=list)
    console_errors: list[str] = field(default_factory=list)

    @property
    def problems(self) -> list[str]:
        return (
            [f"dialog: {d}" for d in self.dialogs]
            + [f"exception: {e}" for e in self.exceptions]
            + [f"console: {c}" for c in self.console_errors]
        )


class Chromium:
    """One headless browser with one page; use as a context manager."""

    def __init__(self, width: int = 1280, height: int = 800) -> None:
        self.width, self.height = width, height
        self._profile = tempfile.mkdtemp(prefix="sdi12-chromium-")
        self._next_id = 0
        self._buffer = b""
        self._pending: list[dict[str, Any]] = []
        self.session: str | None = None
        self.log = PageLog()

    # -- process and transport -----------------------------------------------------------
    def __enter__(self) -> Chromium:
        binary = chromium_path()
        if binary is None:
            raise FileNotFoundError("no chromium on PATH")
        to_browser_r, self._to_browser = os.pipe()
        self._from_browser, from_browser_w = os.pipe()

        def wire_fds() -> None:  # in the child: the browser reads fd 3 and writes fd 4
            high_r = fcntl.fcntl(to_browser_r, fcntl.F_DUPFD, 10)
            high_w = fcntl.fcntl(from_browser_w, fcntl.F_DUPFD, 10)
            os.dup2(high_r, 3)
            os.dup2(high_w, 4)

        self.process = subprocess.Popen(
            [binary, *FLAGS, f"--user-data-dir={self._profile}", "about:blank"],
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            preexec_fn=wire_fds,  # noqa: PLW1509 (no threads are started before this)
            close_fds=False,
        )
        os.close(to_browser_r)
        os.close(from_browser_w)
        target = self.call("Target.createTarget", url="about:blank")["targetId"]
        self.session = self.call("Target.attachToTarget", targetId=target, flatten=True)[
            "sessionId"
        ]
        for domain in ("Page", "Runtime", "Log"):
            self.call(f"{domain}.enable")
        self.call(
            "Emulation.setDeviceMetricsOverride",
            width=self.width,
            height=self.height,
            deviceScaleFactor=1,
            mobile=False,
        )
        return self

    def __exit__(self, *exc: object) -> None:
        try:
            self.session = None
            self.call("Browser.close", timeout=5)
        except (CdpError, OSError):
            pass
        try:
            self.process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
        os.close(self._to_browser)
        os.close(self._from_browser)
        shutil.rmtree(self._profile, ignore_errors=True)

    def _send(self, method: str, params: dict[str, Any]) -> int:
        self._next_id += 1
        message: dict[str, Any] = {"id": self._next_id, "method": method, "params": params}
        if self.session and not method.startswith(("Target.", "Browser.")):
            message["sessionId"] = self.session
        os.write(self._to_browser, json.dumps(message).encode() + b"\0")
        return self._next_id

    def _receive(self, deadline: float) -> dict[str, Any]:
        while b"\0" not in self._buffer:
            left = deadline - time.monotonic()
            if left <= 0 or not select.select([self._from_browser], [], [], left)[0]:
                raise CdpError("the browser did not answer in time")
            chunk = os.read(self._from_browser, 1 << 16)
            if not chunk:
                raise CdpError("the browser closed its DevTools pipe")
            self._buffer += chunk
        raw, self._buffer = self._buffer.split(b"\0", 1)
        message = json.loads(raw)
        if "method" in message:
            self._on_event(message["method"], message.get("params", {}))
        return message

    def _on_event(self, method: str, params: dict[str, Any]) -> None:
        if method == "Page.javascriptDialogOpening":
            self.log.dialogs.append(f"{params.get('type')}: {params.get('message')}")
            self._send("Page.handleJavaScriptDialog", {"accept": True})
        elif method == "Runtime.exceptionThrown":
            details = params.get("exceptionDetails", {})
            text = details.get("exception", {}).get("description") or details.get("text", "")
            self.log.exceptions.append(text)
        elif method == "Runtime.consoleAPICalled" and params.get("type") in ("error", "assert"):
            args = params.get("args", [])
            self.log.console_errors.append(
                " ".join(str(a.get("value", a.get("description", ""))) for a in args)
            )
        elif method == "Log.entryAdded" and params.get("entry", {}).get("level") == "error":
            entry = params["entry"]
            self.log.console_errors.append(f"{entry.get('text')} ({entry.get('url', '')})")
        self._pending.append({"method": method, "params": params})

    def call(self, method: str, timeout: float = TIMEOUT, **params: Any) -> dict[str, Any]:
        """Send one command and return its result (events seen meanwhile are logged)."""
        wanted = self._send(method, params)
        deadline = time.monotonic() + timeout
        while True:
            message = self._receive(deadline)
            if message.get("id") == wanted:
                if "error" in message:
                    raise CdpError(f"{method}: {message['error']}")
                return message.get("result", {})

    def wait_for(self, method: str, timeout: float = TIMEOUT) -> dict[str, Any]:
        """The params of the first event ``method`` (already seen or still to come)."""
        deadline = time.monotonic() + timeout
        while True:
            for i, event in enumerate(self._pending):
                if event["method"] == method:
                    del self._pending[: i + 1]
                    return event["params"]
            self._pending.clear()
            self._receive(deadline)

    # -- what the tests use ----------------------------------------------------------------
    def open(self, path: Path) -> None:
        """Load a file and wait for its load event, then let its scripts settle."""
        self._pending.clear()
        self.log = PageLog()
        self.call("Page.navigate", url=path.resolve().as_uri())
        self.wait_for("Page.loadEventFired")
        self.evaluate("new Promise(r => setTimeout(r, 200))")

    def evaluate(self, expression: str) -> Any:
        """The value of a JavaScript expression in the page (promises are awaited)."""
        result = self.call(
            "Runtime.evaluate", expression=expression, returnByValue=True, awaitPromise=True
        )
        if "exceptionDetails" in result:
            raise CdpError(f"evaluate failed: {result['exceptionDetails'].get('text')}")
        return result["result"].get("value")

    def screenshot(self, path: Path, element: str | None = None) -> Path:
        """A PNG of the viewport, or of the element the JavaScript expression ``element``
        evaluates to (scrolled into view first; at most 2500 px tall)."""
        params: dict[str, Any] = {"format": "png"}
        if element is not None:
            box = self.evaluate(
                f"(function(){{var e=({element}); e.scrollIntoView();"
                " var r=e.getBoundingClientRect();"
                " return {x:r.x+scrollX, y:r.y+scrollY, w:r.width, h:r.height};})()"
            )
            params["captureBeyondViewport"] = True
            params["clip"] = {
                "x": max(0, box["x"]),
                "y": box["y"],
                "width": box["w"],
                "height": min(box["h"], 2500),
                "scale": 1,
            }
        data = self.call("Page.captureScreenshot", **params)["data"]
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(base64.b64decode(data))
        return path
