"""`sins-fw replay … --serve`: the recording in Rerun's web viewer, seen as a person would see it.

The server is started as a user starts it; its printed address is loaded over HTTP, its ports are
checked to listen on the loopback interface only, Ctrl-C stops it with exit 130 and no file left
behind. Where Debian's `chromium` is installed, headless Chromium opens the address and takes a
screenshot: the viewer draws on a canvas, so the page is judged from the picture: far more drawn than
its loading screen, and, where Debian's `tesseract` is installed, the recording's name, views and
entities read off the screenshot. CI without them runs the rest; `apt install chromium tesseract-ocr`
runs it all.
"""

from __future__ import annotations

import os
import re
import shutil
import signal
import subprocess
import sys
import time
import urllib.request
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
TRACE = ROOT / "traces" / "static_60s.h5"
URL = re.compile(r"at (http://\S+) \(Ctrl-C stops it\)")


def _loopback_only(port: int) -> bool:
    """Every listening socket on ``port`` is bound to 127.0.0.1 (from /proc/net/tcp)."""
    found = []
    for line in Path("/proc/net/tcp").read_text().splitlines()[1:]:
        local, state = line.split()[1], line.split()[3]
        addr, p = local.split(":")
        if int(p, 16) == port and state == "0A":  # LISTEN
            found.append(addr)
    return bool(found) and all(a == "0100007F" for a in found)


def _start_serving(tmp: Path) -> tuple[subprocess.Popen[str], str]:
    """`sins-fw replay TRACE --serve` on free ports, as a user starts it, and the address it prints."""
    proc = subprocess.Popen(
        [sys.executable, "-m", "sins_fw", "replay", str(TRACE), "--serve", "--port", "0", "--grpc-port", "0"],
        cwd=tmp,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, "TMPDIR": str(tmp)},
    )
    url = None
    assert proc.stdout is not None
    deadline = time.monotonic() + 180
    lines = []
    while url is None and time.monotonic() < deadline:
        line = proc.stdout.readline()
        if not line:
            break
        lines.append(line)
        if m := URL.search(line):
            url = m.group(1)
    if url is None:  # say why: the command's own error, once it has ended
        try:
            proc.wait(timeout=30)
        except subprocess.TimeoutExpired:
            proc.kill()
    assert url is not None, ("".join(lines), proc.stderr.read() if proc.poll() is not None else "")
    return proc, url


@pytest.fixture(scope="module")
def served(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, object]]:
    tmp = tmp_path_factory.mktemp("serve")
    proc, url = _start_serving(tmp)
    try:
        yield {"proc": proc, "url": url, "tmp": tmp}
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def test_the_served_page_is_the_web_viewer_on_loopback_only(served):
    url = str(served["url"])
    with urllib.request.urlopen(url, timeout=10) as r:
        page = r.read().decode()
    assert r.status == 200 and "Rerun" in page and "wasm" in page
    web_port = int(re.match(r"http://127\.0\.0\.1:(\d+)/", url).group(1))
    grpc_port = int(re.search(r"127\.0\.0\.1%3A(\d+)%2Fproxy", url).group(1))
    assert _loopback_only(web_port) and _loopback_only(grpc_port)
    # The temporary recording exists while it is served.
    (rrd,) = Path(served["tmp"]).glob("sins-fw-serve-*/static_60s.rrd")
    assert rrd.stat().st_size > 0


def _colours(png: bytes) -> int:
    import io

    import matplotlib.image

    img = np.asarray(matplotlib.image.imread(io.BytesIO(png), format="png"))[..., :3]
    return len(np.unique((img * 255).astype(np.uint8).reshape(-1, 3), axis=0))


#: The viewer's loading screen has 322 distinct colours (measured on a screenshot taken before its
#: wasm had loaded), the viewer showing this recording 4 270: a thousand separates the two.
LOADED_COLOURS = 1000


#: What a person looks for (case aside, as tesseract reads it): the project's layout (a tab container
#: whose first tab is the attitude; Rerun's own layout is a grid), its 3-D view and the series.
WORDS = (
    "viewport (tab container)",
    "attitude",
    "board (estimate) and truth",
    "roll estimate",
    "pitch estimate",
)


def _missing(png: bytes, tmp: Path) -> list[str]:
    """What the screenshot does not show yet: the viewer itself, then (where tesseract can read the
    screen) each of :data:`WORDS`."""
    if _colours(png) <= LOADED_COLOURS:
        return ["the viewer (only its loading screen)"]
    if shutil.which("tesseract") is None:
        return []
    shot = tmp / "look.png"
    shot.write_bytes(png)
    text = subprocess.run(["tesseract", str(shot), "-"], capture_output=True, text=True, timeout=120).stdout
    return [w for w in WORDS if w not in text.lower()]


def _look_until_shown(url: str, tmp: Path, timeout_s: float = 300.0) -> tuple[bytes, list[str]]:
    """Open ``url`` in headless Chromium and, as a person would, look every few seconds until the
    viewer shows the recording (or ``timeout_s``): the last screenshot (PNG) and what it still
    lacks. Driven over the DevTools protocol (tornado's websocket client, installed with dask)."""
    import asyncio
    import base64
    import json

    tornado_websocket = pytest.importorskip("tornado.websocket")
    browser = subprocess.Popen(
        [
            "chromium",
            "--headless=new",
            "--no-sandbox",
            "--ignore-gpu-blocklist",
            "--use-angle=swiftshader",  # WebGL in software: no GPU here
            "--enable-unsafe-swiftshader",
            "--window-size=1600,1000",
            "--remote-debugging-port=0",
            f"--user-data-dir={tmp / 'chromium'}",
            url,
        ],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert browser.stderr is not None
        ws_url = None
        for line in browser.stderr:
            if m := re.search(r"DevTools listening on (ws://\S+)", line):
                ws_url = m.group(1)
                break
        assert ws_url is not None, "chromium did not start its DevTools endpoint"
        port = int(re.match(r"ws://[^:]+:(\d+)/", ws_url).group(1))
        with urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list", timeout=10) as r:
            (page,) = [t for t in json.load(r) if t["type"] == "page"]

        async def look() -> tuple[bytes, list[str]]:
            conn = await tornado_websocket.websocket_connect(
                page["webSocketDebuggerUrl"], max_message_size=2**28
            )
            deadline = time.monotonic() + timeout_s
            n = 0
            while True:
                await asyncio.sleep(5)
                n += 1
                conn.write_message(json.dumps({"id": n, "method": "Page.captureScreenshot"}))
                while (msg := json.loads(await conn.read_message())).get("id") != n:
                    pass
                png = base64.b64decode(msg["result"]["data"])
                missing = _missing(png, tmp)
                if not missing or time.monotonic() > deadline:
                    return png, missing

        return asyncio.run(look())
    finally:
        browser.kill()
        browser.wait()


@pytest.mark.skipif(shutil.which("chromium") is None, reason="Debian's chromium is not installed")
def test_headless_chromium_shows_the_recording(served, tmp_path):
    png, missing = _look_until_shown(f"{served['url']}&renderer=webgl", tmp_path)
    shot = tmp_path / "viewer.png"
    shot.write_bytes(png)
    assert not missing, (missing, shot)


def test_ctrl_c_stops_the_server_with_130_and_removes_the_recording(served):
    proc = served["proc"]
    assert isinstance(proc, subprocess.Popen)
    proc.send_signal(signal.SIGINT)
    assert proc.wait(timeout=30) == 130
    assert not list(Path(served["tmp"]).glob("sins-fw-serve-*"))


def test_a_port_in_use_is_refused_before_any_work(tmp_path):
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen()
        port = s.getsockname()[1]
        r = subprocess.run(
            [sys.executable, "-m", "sins_fw", "replay", str(TRACE), "--serve", "--port", str(port)],
            cwd=tmp_path,
            capture_output=True,
            text=True,
            check=False,
            timeout=60,
        )
    assert r.returncode == 2, r.stderr
    assert f"--port {port}: cannot listen on 127.0.0.1:{port}" in r.stderr
    assert "Traceback" not in r.stderr and r.stdout == ""


def test_the_viewer_does_not_outlive_a_killed_command(tmp_path):
    proc, _ = _start_serving(tmp_path)
    children = [
        int(p.name)
        for p in Path("/proc").iterdir()
        if p.name.isdigit()
        and (p / "stat").exists()
        and (p / "stat").read_text().split(") ")[-1].split()[1] == str(proc.pid)
    ]
    assert children, "the viewer process was not found"
    proc.kill()  # SIGKILL: sins-fw cannot clean up
    proc.wait()
    deadline = time.monotonic() + 10
    while any(Path(f"/proc/{c}").exists() for c in children) and time.monotonic() < deadline:
        time.sleep(0.1)
    alive = [
        c
        for c in children
        if Path(f"/proc/{c}/stat").exists() and " Z " not in Path(f"/proc/{c}/stat").read_text()
    ]
    assert not alive, alive
