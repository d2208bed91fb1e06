"""Run `sitl-emu serve` on a pseudo-terminal as an interactive shell runs a job: in the foreground or with `&`.

`PtyJob` starts this file as a small "shell": the session leader of a new session whose controlling terminal is the
pty. It forks serve into its own process group and makes that group the terminal's foreground job or not, as an
interactive shell does for `serve` and `serve &`; later `fg()` and `bg()` move it, as the shell's fg and bg do.
Everything serve writes to the terminal is collected by a thread (`output`); `send` types into the terminal.
"""

from __future__ import annotations

import contextlib
import fcntl
import os
import select
import signal
import subprocess
import sys
import termios
import threading
import time
from collections.abc import Callable
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]  # this file also runs as a script: no `support` import


class PtyJob:
    def __init__(self, serve_args: list[str], foreground: bool, cwd: Path, readline: bool = True) -> None:
        """`cwd`: where serve keeps its logs and parameter file (a test's tmp_path, never the checkout)."""
        self._master, slave = os.openpty()
        control_r, self._control = os.pipe()
        pid_r, pid_w = os.pipe()
        self.helper = subprocess.Popen(
            [sys.executable, __file__, str(control_r), str(pid_w), "fg" if foreground else "bg",
             "readline" if readline else "no-readline", *serve_args],
            stdin=slave, stdout=slave, stderr=slave, pass_fds=(control_r, pid_w), cwd=cwd,
            env={**os.environ, "PYTHONPATH": str(REPO), "TERM": "xterm"})
        os.close(slave)
        os.close(control_r)
        os.close(pid_w)
        with os.fdopen(pid_r) as f:
            self.pid = int(f.readline())
        self._chunks: list[bytes] = []
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    @property
    def output(self) -> str:
        return b"".join(self._chunks).decode("utf-8", errors="replace")

    def send(self, text: str) -> None:
        os.write(self._master, text.encode())

    def wait_for(self, text: str, timeout: float = 10.0, count: int = 1) -> bool:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if self.output.count(text) >= count:
                return True
            time.sleep(0.05)
        return False

    def state(self) -> str:
        """The process state letter of serve ('T': stopped by job control, 'S'/'R': running)."""
        with open(f"/proc/{self.pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0]

    def kill(self, sig: int) -> None:
        os.kill(self.pid, sig)

    def fg(self) -> None:
        os.write(self._control, b"fg\n")
        self._until(lambda: os.tcgetpgrp(self._master) == self.pid)

    def bg(self) -> None:
        os.write(self._control, b"bg\n")
        self._until(lambda: os.tcgetpgrp(self._master) != self.pid)

    @staticmethod
    def _until(done: Callable[[], bool], timeout: float = 5.0) -> None:
        """Wait until the shell has moved the job (what is typed next goes to the right process)."""
        deadline = time.monotonic() + timeout
        while not done():
            if time.monotonic() > deadline:
                raise TimeoutError("the job did not move between foreground and background")
            time.sleep(0.01)

    def wait(self, timeout: float) -> int:
        """serve's exit status (the helper exits with it)."""
        return self.helper.wait(timeout=timeout)

    def close(self) -> None:
        if self.helper.poll() is None:
            with contextlib.suppress(ProcessLookupError):
                os.kill(self.pid, signal.SIGKILL)
            self.helper.wait(timeout=10)
        os.close(self._control)
        os.close(self._master)

    def _read(self) -> None:
        while True:
            try:
                data = os.read(self._master, 4096)
            except OSError:  # the terminal closed
                return
            if not data:
                return
            self._chunks.append(data)


# serve as `sitl-emu serve` runs it, in a Python where `import readline` fails (as where readline does not exist)
_WITHOUT_READLINE = "import sys; sys.modules['readline'] = None; from sitl_emu.cli.main import main; main()"


def _shell(control_fd: int, pid_fd: int, mode: str, readline: str, serve_args: list[str]) -> int:
    """The helper process: a session leader with the pty as its controlling terminal, serve as its job."""
    os.setsid()
    fcntl.ioctl(0, termios.TIOCSCTTY, 0)
    signal.signal(signal.SIGTTOU, signal.SIG_IGN)  # a shell moves the foreground job from the background
    signal.signal(signal.SIGTTIN, signal.SIG_IGN)  # and never stops on reading: a racing read fails with EIO
    pid = os.fork()
    if pid == 0:
        os.setpgid(0, 0)
        if mode == "fg":
            os.tcsetpgrp(0, os.getpgrp())
        signal.signal(signal.SIGTTOU, signal.SIG_DFL)
        signal.signal(signal.SIGTTIN, signal.SIG_DFL)
        start = ["-m", "sitl_emu"] if readline == "readline" else ["-c", _WITHOUT_READLINE]
        os.execv(sys.executable, [sys.executable, *start, "serve", *serve_args])
    with contextlib.suppress(PermissionError):  # EACCES: the job already exec'd (it set its own group first)
        os.setpgid(pid, pid)
    if mode == "fg":
        os.tcsetpgrp(0, pid)
    os.write(pid_fd, f"{pid}\n".encode())
    os.close(pid_fd)
    threading.Thread(target=_move_job, args=(control_fd, pid), daemon=True).start()
    threading.Thread(target=_read_as_the_shell, daemon=True).start()
    _, status = os.waitpid(pid, 0)
    return os.waitstatus_to_exitcode(status)


def _read_as_the_shell() -> None:
    """While the shell has the terminal, what is typed is the shell's: it reads it and says so ("shell read: ...")."""
    while True:
        if os.tcgetpgrp(0) != os.getpgrp() or not select.select([0], [], [], 0.05)[0]:
            time.sleep(0.05)
            continue
        try:
            data = os.read(0, 4096)
        except OSError:  # the job took the terminal meanwhile
            continue
        os.write(1, b"shell read: " + data)


def _move_job(control_fd: int, pid: int) -> None:
    with os.fdopen(control_fd) as commands:
        for command in commands:  # as a shell's fg and bg: who has the terminal; the job continues if stopped
            os.tcsetpgrp(0, pid if command.strip() == "fg" else os.getpgrp())
            os.killpg(pid, signal.SIGCONT)


if __name__ == "__main__":
    code = _shell(int(sys.argv[1]), int(sys.argv[2]), sys.argv[3], sys.argv[4], sys.argv[5:])
    sys.exit(code if code >= 0 else 128 - code)
