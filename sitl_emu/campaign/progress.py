"""The progress of `sitl-emu campaign` on stderr: click's bar on a terminal; elsewhere (a log file, a CI job, a pipe)
a plain line at least every 10 wall seconds while cases fly, and one when they end:

    cases: 12 of 200 done (11 passed, 1 failed), 0.52 cases/s, about 6 min left
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager
from typing import Any, TextIO

import click

__all__ = ["CampaignProgress", "ProgressLines", "duration_text"]

EVERY_S = 10.0


def duration_text(seconds: float) -> str:
    """A rough duration for a person: 40 s, 6 min, 2 h 05 min."""
    if seconds < 90:
        return f"{max(1, round(seconds))} s"
    if seconds < 5400:
        return f"{round(seconds / 60)} min"
    hours, minutes = divmod(round(seconds / 60), 60)
    return f"{hours} h {minutes:02d} min"


class ProgressLines:
    """A line on `stream` every `every_s` wall seconds (from a thread, so a long case does not silence it) and at
    the end; `update(n)` counts finished cases, `row(row)` their verdicts."""

    def __init__(self, stream: TextIO, total: int, every_s: float = EVERY_S,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.stream, self.total, self.every_s, self.clock = stream, total, every_s, clock
        self.done = self.passed = self.failed = 0
        self.started = clock()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._tick, name="campaign-progress", daemon=True)

    def __enter__(self) -> ProgressLines:
        self._thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._stop.set()
        self._thread.join()
        self._print()

    def update(self, n: int) -> None:
        self.done += n

    def row(self, row: Mapping[str, Any]) -> None:
        if row.get("passed") is True:
            self.passed += 1
        else:
            self.failed += 1

    def line(self) -> str:
        elapsed_s = self.clock() - self.started
        text = f"cases: {self.done} of {self.total} done ({self.passed} passed, {self.failed} failed)"
        if self.done == 0 or elapsed_s <= 0:
            return f"{text}, time left unknown" if self.done < self.total else text
        rate = self.done / elapsed_s
        left = "" if self.done >= self.total else f", about {duration_text((self.total - self.done) / rate)} left"
        return f"{text}, {rate:.2g} cases/s{left}"

    def _tick(self) -> None:
        while not self._stop.wait(self.every_s):
            self._print()

    def _print(self) -> None:
        click.echo(self.line(), file=self.stream)
        self.stream.flush()


class CampaignProgress:
    """What the command line hands run_campaign: `start(total)` as its `progress`, `row` as its `on_row`."""

    def __init__(self, stream: TextIO | None = None, every_s: float = EVERY_S) -> None:
        self.stream = stream if stream is not None else sys.stderr
        self.every_s = every_s
        self.lines: ProgressLines | None = None

    @contextmanager
    def start(self, total: int) -> Iterator[Any]:
        if total == 0:  # every case is in the results file already
            yield None
            return
        if self.stream.isatty():
            with click.progressbar(length=total, label="cases", file=self.stream, show_pos=True,
                                   show_eta=True) as bar:
                yield bar
            return
        self.lines = ProgressLines(self.stream, total, self.every_s)
        with self.lines:
            yield self.lines

    def row(self, row: Mapping[str, Any]) -> None:
        if self.lines is not None:
            self.lines.row(row)
