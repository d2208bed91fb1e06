"""Running a flight session for `joyfly fly` and `joyfly demo`: Ctrl-C/SIGTERM handling, then the closing words
(what happened, the summary, or in what state the vehicle was left).

The first Ctrl-C or SIGTERM asks the session to perform --on-exit; a second one quits at once (exit status 130).
"""

from __future__ import annotations

import signal
from collections.abc import Iterator
from contextlib import contextmanager
from types import FrameType
from typing import Any

import click

from joyfly.dashboard import summary_lines
from joyfly.flight import FlightSession, Phase
from joyfly.flight_session import FlightStats


def fly_session(session: FlightSession, view: Any, out: Any) -> int:
    """Run the session with Ctrl-C/SIGTERM handling, print the summary, close everything."""
    try:
        with exit_signals(session):
            session.run(on_view=view.show)
    except KeyboardInterrupt:
        out.write("\njoyfly: interrupted twice, quitting at once (the vehicle keeps its last mode).\n")
        return 130
    finally:
        view.close()
        session.link.close()
        session.sticks.close()
    flew = session.stats != FlightStats()  # a session that never flew (no vehicle, refused) has nothing to sum up
    if flew or session.phase is not Phase.FAILED:
        for line in summary_lines(session.stats):
            out.write(line + "\n")
    if session.phase is Phase.FAILED:
        click.echo(f"joyfly: {session.error}", err=True)
        return 1
    return 0


@contextmanager
def exit_signals(session: FlightSession) -> Iterator[None]:
    """First SIGINT/SIGTERM: ask the session to perform --on-exit; the second: KeyboardInterrupt, at once."""

    def handler(signum: int, frame: FrameType | None) -> None:
        if session.exit_requested:
            raise KeyboardInterrupt
        session.request_exit()

    previous = {sig: signal.signal(sig, handler) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for sig, old in previous.items():
            signal.signal(sig, old)


