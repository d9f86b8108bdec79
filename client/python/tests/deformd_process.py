"""The real deformd as a child process for the Python client's tests.

DeformdProcess(*flags, listen=): starts $DEFORM_TEST_DEFORMD (set by ctest to the deformd of the
same build; default <repository>/build/server/deformd/deformd) with --listen `listen` (default
127.0.0.1:0: a kernel-chosen port; free_port() gives one to start a second server on) and `flags`,
its output into a temporary file, and waits (up to 60 s) for its "listening on HOST:PORT" line.
RuntimeError with the log when the program is missing, exits or never listens: a missing server
fails the tests, it never skips them. stop() sends SIGTERM (SIGKILL after 10 s); also on leaving
a `with` block; kill() sends SIGKILL (a replica that dies). paused() stops the process (SIGSTOP) for a `with` block and then continues it
(SIGCONT): a server that answers nothing, for the deadline tests.
"""

import contextlib
import os
import pathlib
import re
import signal
import socket
import subprocess
import tempfile
import time

REPOSITORY = pathlib.Path(os.environ.get("DEFORM_SOURCE_DIR",
                                         pathlib.Path(__file__).resolve().parents[3]))


def deformd_program():
    program = pathlib.Path(os.environ.get("DEFORM_TEST_DEFORMD",
                                          REPOSITORY / "build" / "server" / "deformd" / "deformd"))
    if not program.is_file():
        raise RuntimeError(f"deformd not found at {program} (build it, or set DEFORM_TEST_DEFORMD)")
    return program


def free_port():
    """A loopback port nothing listens on now (the kernel's pick, released)."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


class DeformdProcess:
    def __init__(self, *flags, listen="127.0.0.1:0", timeout=60.0):
        self._log = tempfile.NamedTemporaryFile(prefix="deformd-pytest-", suffix=".log")
        self._process = subprocess.Popen(
            [str(deformd_program()), "--listen", listen, *map(str, flags)],
            stdout=self._log, stderr=subprocess.STDOUT)
        deadline = time.monotonic() + timeout
        while True:
            match = re.search(r"listening on [^ ]*:(\d+)", self.output())
            if match:
                self.port = int(match.group(1))
                break
            if self._process.poll() is not None or time.monotonic() > deadline:
                self.stop()
                raise RuntimeError(f"deformd did not start listening:\n{self.output()}")
            time.sleep(0.02)
        self.target = f"127.0.0.1:{self.port}"

    def output(self):
        return pathlib.Path(self._log.name).read_text(errors="replace")

    def stop(self):
        if self._process.poll() is None:
            self._process.send_signal(signal.SIGTERM)
            try:
                self._process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self._process.kill()
                self._process.wait()
        return self._process.returncode

    def kill(self):
        if self._process.poll() is None:
            self._process.kill()
        return self._process.wait()

    @contextlib.contextmanager
    def paused(self):
        self._process.send_signal(signal.SIGSTOP)
        stat = pathlib.Path(f"/proc/{self._process.pid}/stat")
        deadline = time.monotonic() + 10
        while stat.read_text().rsplit(")", 1)[1].split()[0] != "T":  # every thread stopped
            if time.monotonic() > deadline:
                raise RuntimeError("deformd did not stop on SIGSTOP")
            time.sleep(0.005)
        try:
            yield
        finally:
            self._process.send_signal(signal.SIGCONT)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.stop()
        self._log.close()
        return False
