"""Open a page in headless Chromium over the DevTools protocol: console errors, images, text, requests, screenshot."""

from __future__ import annotations

import base64
import contextlib
import json
import os
import re
import shutil
import signal
import subprocess
import tempfile
import time
from dataclasses import dataclass, field
from html.parser import HTMLParser
from pathlib import Path
from typing import Any

from websockets.sync.client import connect


@dataclass
class PageLoad:
    """What the browser saw while loading one page."""

    text: str
    images: list[dict[str, Any]]
    errors: list[str] = field(default_factory=list)
    requests: list[str] = field(default_factory=list)
    screenshot: bytes = b""


def chromium() -> str | None:
    """The Chromium executable, or None."""
    return shutil.which("chromium") or shutil.which("chromium-browser")


class _Session:
    def __init__(self, socket: Any, session: str) -> None:
        self.socket, self.session, self.next_id, self.events = socket, session, 0, []

    def call(self, method: str, **params: Any) -> dict[str, Any]:
        self.next_id += 1
        self.socket.send(
            json.dumps({"id": self.next_id, "method": method, "params": params, "sessionId": self.session})
        )
        while True:
            message = json.loads(self.socket.recv(timeout=60))
            if message.get("id") == self.next_id:
                if "error" in message:
                    raise RuntimeError(f"{method}: {message['error']}")
                return dict(message.get("result", {}))
            self.events.append(message)

    def wait(self, method: str, timeout: float = 60.0) -> None:
        end = time.monotonic() + timeout
        while not any(e.get("method") == method for e in self.events):
            self.events.append(json.loads(self.socket.recv(timeout=max(0.1, end - time.monotonic()))))


def _browser_call(socket: Any, method: str, **params: Any) -> dict[str, Any]:
    socket.send(json.dumps({"id": 1, "method": method, "params": params}))
    while True:
        message = json.loads(socket.recv(timeout=60))
        if message.get("id") == 1:
            return dict(message["result"])


def load_page(url: str, width: int = 1100, height: int = 1400) -> PageLoad:
    """Load ``url`` in a fresh headless Chromium and report what it saw (see :class:`PageLoad`)."""
    exe = chromium()
    assert exe is not None, "chromium is not installed (apt-get install chromium)"
    profile = tempfile.mkdtemp(prefix="chromium-profile-")
    try:
        process = subprocess.Popen(
            [
                exe,
                "--headless",
                "--no-sandbox",
                "--disable-gpu",
                "--remote-debugging-port=0",
                f"--user-data-dir={profile}",
                f"--window-size={width},{height}",
                "about:blank",
            ],
            stderr=subprocess.PIPE,
            text=True,
            start_new_session=True,  # its helper processes share the group: all of them are stopped below
        )
        try:
            assert process.stderr is not None
            address = None
            for line in process.stderr:
                match = re.search(r"DevTools listening on (ws://\S+)", line)
                if match:
                    address = match.group(1)
                    break
            assert address is not None, "chromium printed no DevTools address"
            with connect(address, max_size=2**28) as socket:
                target = _browser_call(socket, "Target.createTarget", url="about:blank")["targetId"]
                session_id = _browser_call(socket, "Target.attachToTarget", targetId=target, flatten=True)["sessionId"]
                page = _Session(socket, session_id)
                for domain in ("Page", "Runtime", "Log", "Network"):
                    page.call(f"{domain}.enable")
                page.call("Page.navigate", url=url)
                page.wait("Page.loadEventFired")
                script = (
                    "JSON.stringify({text: document.body.innerText, images: Array.from(document.images).map("
                    "i => ({src: i.src.slice(0, 40), complete: i.complete, width: i.naturalWidth}))})"
                )
                value = json.loads(
                    page.call("Runtime.evaluate", expression=script, returnByValue=True)["result"]["value"]
                )
                shot = page.call("Page.captureScreenshot", format="png", captureBeyondViewport=True)["data"]
                load = PageLoad(value["text"], value["images"], screenshot=base64.b64decode(shot))
                for event in page.events:
                    method, params = event.get("method"), event.get("params", {})
                    if method == "Runtime.exceptionThrown":
                        load.errors.append(str(params["exceptionDetails"].get("text")))
                    elif method == "Runtime.consoleAPICalled" and params.get("type") == "error":
                        load.errors.append(" ".join(str(a.get("value")) for a in params.get("args", [])))
                    elif method == "Log.entryAdded" and params["entry"].get("level") == "error":
                        load.errors.append(str(params["entry"].get("text")))
                    elif method == "Network.requestWillBeSent":
                        load.requests.append(str(params["request"]["url"])[:80])
                return load
        finally:
            process.terminate()
            process.wait(timeout=30)
            with contextlib.suppress(ProcessLookupError):  # the group is gone already: nothing left to stop
                os.killpg(process.pid, signal.SIGKILL)
    finally:
        _remove_profile(profile)


def _remove_profile(profile: str) -> None:
    """Remove Chromium's profile folder; a helper process may still write into it for a moment, so retry."""
    for _ in range(20):
        try:
            shutil.rmtree(profile)
            return
        except OSError:
            time.sleep(0.25)
    shutil.rmtree(profile)  # the last try raises what stands in the way


def save_artifact(name: str, data: bytes) -> Path:
    """Store a test artefact under tests/artifacts/ (git-ignored)."""
    folder = Path(__file__).resolve().parent / "artifacts"
    folder.mkdir(exist_ok=True)
    path = folder / name
    path.write_bytes(data)
    return path


class References(HTMLParser):
    """Every attribute that can make a browser fetch something, and every tag that can run or pull content."""

    def __init__(self) -> None:
        super().__init__()
        self.urls: list[str] = []
        self.tags: list[str] = []
        self.styles: list[str] = []
        self._in_style = False

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        """Record a fetching tag, its URL attributes and inline styles."""
        if tag in ("script", "link", "iframe", "object", "embed", "base", "video", "audio", "source"):
            self.tags.append(tag)
        self._in_style = tag == "style"
        for name, value in attrs:
            if name in ("src", "href", "srcset", "action", "poster", "data", "formaction") and value is not None:
                self.urls.append(value)
            if name == "style" and value:
                self.styles.append(value)

    def handle_data(self, data: str) -> None:
        """Record the text of a style element."""
        if self._in_style:
            self.styles.append(data)
