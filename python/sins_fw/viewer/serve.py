"""A recording in Rerun's web viewer, served on local ports: for machines without a display.

The viewer shipped with rerun-sdk serves the web viewer over HTTP and the recording over gRPC; a
browser that opens the printed address loads the viewer, which then fetches the recording from
the gRPC port. Both ports are bound to ``bind`` (127.0.0.1 unless asked otherwise: Rerun's
servers have no authentication).
"""

from __future__ import annotations

import contextlib
import ctypes
import signal
import socket
import subprocess
import sys
import time
import urllib.parse
from collections.abc import Callable
from pathlib import Path

from sins_fw.errors import InputError

#: The web viewer's default HTTP port and the recording's default gRPC port (Rerun's defaults).
WEB_PORT = 9090
GRPC_PORT = 9876
#: How long the viewer may take to open its ports.
START_TIMEOUT_S = 30.0


def viewer_binary() -> Path:
    """The viewer executable shipped with rerun-sdk."""
    try:
        import rerun_cli  # located only when the viewer is started (and may be missing)
    except ImportError:
        raise InputError("--serve: the Rerun viewer (package rerun-sdk) is not installed") from None
    exe = Path(rerun_cli.__file__).parent / "rerun"
    if not exe.is_file():
        raise InputError(f"--serve: the Rerun viewer is missing from its package ({exe})")
    return exe


def free_ports(bind: str, *wanted: tuple[int, str]) -> list[int]:
    """Each ``(port, option)`` if it can be bound on ``bind`` (a free one for 0), else an InputError
    naming ``option``. The ports are held together while they are chosen, so that two asked as 0
    never come out the same."""
    with contextlib.ExitStack() as held:
        ports = []
        for port, option in wanted:
            s = held.enter_context(socket.socket(socket.AF_INET, socket.SOCK_STREAM))
            try:
                s.bind((bind, port))
            except OSError as e:
                raise InputError(f"{option} {port}: cannot listen on {bind}:{port} ({e.strerror})") from None
            ports.append(int(s.getsockname()[1]))
        return ports


def free_port(bind: str, port: int, option: str) -> int:
    """``port`` if it can be bound on ``bind`` (a free one for 0), else an InputError naming ``option``."""
    return free_ports(bind, (port, option))[0]


def viewer_url(host: str, web_port: int, grpc_port: int) -> str:
    """The address that opens the web viewer on the served recording."""
    proxy = f"rerun+http://{host}:{grpc_port}/proxy"
    return f"http://{host}:{web_port}/?url={urllib.parse.quote(proxy, safe='')}"


def _listening(host: str, port: int) -> bool:
    with contextlib.suppress(OSError), socket.create_connection((host, port), timeout=0.5):
        return True
    return False


def _die_with_parent() -> None:
    """In the viewer's process, before it starts (Linux): be sent SIGTERM when sins-fw ends, even
    when it is killed outright, so that no server outlives the command that started it."""
    ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGTERM)  # 1 = PR_SET_PDEATHSIG


def serve(
    recording: Path,
    *,
    bind: str = "127.0.0.1",
    web_port: int = WEB_PORT,
    grpc_port: int = GRPC_PORT,
    on_ready: Callable[[str], None] = print,
) -> int:
    """Serve ``recording`` until the viewer process ends or Ctrl-C (then 130). ``on_ready`` gets the
    viewer's address once both ports answer."""
    exe = viewer_binary()
    if web_port == grpc_port != 0:
        raise InputError(f"--port and --grpc-port are both {web_port}: give two different ports")
    web_port, grpc_port = free_ports(bind, (web_port, "--port"), (grpc_port, "--grpc-port"))
    cmd = [
        str(exe),
        "--serve-web",
        "--bind",
        bind,
        "--web-viewer-port",
        str(web_port),
        "--port",
        str(grpc_port),
        str(recording),
    ]
    host = "127.0.0.1" if bind in ("127.0.0.1", "0.0.0.0", "::") else bind
    proc = subprocess.Popen(
        cmd,
        stdin=subprocess.DEVNULL,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        preexec_fn=_die_with_parent if sys.platform.startswith("linux") else None,
    )
    try:
        deadline = time.monotonic() + START_TIMEOUT_S
        while not (_listening(host, web_port) and _listening(host, grpc_port)):
            if proc.poll() is not None:
                err = proc.stderr.read().decode(errors="replace").strip() if proc.stderr else ""
                raise InputError(
                    f"--serve: the Rerun viewer stopped at start: {err[-500:] or proc.returncode}"
                )
            if time.monotonic() > deadline:
                raise InputError(
                    f"--serve: the Rerun viewer did not open its ports in {START_TIMEOUT_S:.0f} s"
                )
            time.sleep(0.1)
        on_ready(viewer_url(host, web_port, grpc_port))
        # The viewer writes its log to stderr as it serves: drain it so that it never blocks.
        if proc.stderr is not None:
            for _ in proc.stderr:
                pass
        return proc.wait()
    except KeyboardInterrupt:
        return 130
    finally:
        if proc.poll() is None:
            proc.terminate()
            try:
                proc.wait(timeout=5)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
