"""A ``brakesqueal explore`` subprocess for the explorer's tests: its tokenized URL and its output."""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import threading
import time
from urllib.parse import parse_qs, urlsplit

__all__ = ["Served", "TIMEOUT", "REBOUND"]

#: Seconds to wait for a view (cold numba caches compile on the first request).
TIMEOUT = float(os.environ.get("BRAKESQUEAL_EXPLORER_TIMEOUT", "240"))
#: Host name the browser resolves to 127.0.0.1 (a DNS-rebinding attacker's name, for the security tests).
REBOUND = "evil.example"


class Served:
    """A running ``brakesqueal explore`` subprocess: its tokenized URL and everything it printed.

    Attributes
    ----------
    url : str
        The URL it printed (``http://127.0.0.1:PORT/?token=...``).
    base : str
        ``http://127.0.0.1:PORT/``.
    port : int
    token : str
    output : list of str
        Its output lines so far (read by a thread, so the pipe never fills).
    """

    def __init__(self, args: list[str], script: str | None = None, timeout: float = 120.0) -> None:
        cmd = [sys.executable, script] if script else [sys.executable, "-m", "brakesqueal"]
        self.proc = subprocess.Popen([*cmd, "explore", "--no-browser", *args], stdout=subprocess.PIPE,
                                     stderr=subprocess.STDOUT, text=True)
        self.output: list[str] = []
        found = threading.Event()
        self.url = ""

        def read() -> None:
            assert self.proc.stdout is not None
            for line in self.proc.stdout:
                self.output.append(line)
                if not found.is_set() and "explorer at http://" in line:
                    self.url = line.split("explorer at ", 1)[1].split()[0]
                    found.set()
            found.set()

        threading.Thread(target=read, daemon=True).start()
        if not found.wait(timeout) or not self.url:
            self.stop()
            raise RuntimeError(f"the explorer printed no URL within {timeout} s: {''.join(self.output)}")
        parts = urlsplit(self.url)
        self.base = f"{parts.scheme}://{parts.netloc}/"
        self.port = int(parts.port or 80)
        self.token = parse_qs(parts.query).get("token", [""])[0]  # (an explorer before issue 30 had none)
        deadline = time.monotonic() + timeout
        while True:  # it prints the URL just before it listens
            try:
                socket.create_connection(("127.0.0.1", self.port), timeout=0.5).close()
                break
            except OSError:
                if self.proc.poll() is not None or time.monotonic() > deadline:
                    self.stop()
                    raise RuntimeError(f"the explorer does not listen: {''.join(self.output)}") from None
                time.sleep(0.1)

    def stop(self) -> None:
        """Terminate the server."""
        self.proc.terminate()
        try:
            self.proc.wait(10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait(10)
