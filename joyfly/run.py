"""Running a flight session for `joyfly fly` and `joyfly demo`: Ctrl-C/SIGTERM handling, then the closing words
(what happened, the summary, or in what state the vehicle was left).

The first Ctrl-C or SIGTERM asks the session to perform --on-exit; a second one quits at once (exit status 130).
Exit status: 0 a flight (or none) that ended well, 1 a failure joyfly reports, 2 a joystick that sent something
other than js_event records before anything armed (a mistake, as px4common's UserError), 3 the vehicle breached the
fence, 4 a flight ended without a landing, 130 quit at once.
"""

from __future__ import annotations

import signal
from collections.abc import Iterator
from contextlib import contextmanager
from types import FrameType
from typing import Any

import click

from joyfly.dashboard import breach_words, summary_lines
from joyfly.session.core import Phase
from joyfly.session.loop import SessionLoop

EXIT_MISTAKE = 2  # a mistake the user can fix (px4common.cli_style.UserError): here, a joystick that is none
EXIT_FENCE_BREACHED = 3  # the flight went outside the fence (joyfly/session/fence_watch.py)
EXIT_NOT_LANDED = 4  # a flight ended in the air: the vehicle restarted, or was left flying (not --on-exit hold)


def fly_session(session: SessionLoop, view: Any, out: Any) -> int:
    """Run the session with Ctrl-C/SIGTERM handling, close everything, then say how it ended; returns the exit
    status (0 done, 1 failed, 2 the joystick sent no js_events before arming, 3 the fence was breached, 4 a flight
    ended in the air, 130 quit at once by a second Ctrl-C)."""
    interrupted = False
    try:
        with exit_signals(session):
            session.run(on_view=view.show)
    except KeyboardInterrupt:
        interrupted = True
    finally:
        view.close(keep=session.link.state.last_heartbeat_s is not None)  # an empty view says nothing
        session.link.close()
        session.sticks.close()
    if interrupted:
        click.echo(f"joyfly: interrupted twice, quitting at once: {left_behind(session)}", err=True)
        return 130
    unlanded = session.landing_missing()
    if session.armed_seen:
        extra = session.summary_extra() + ([f"landing               none: {unlanded}"] if unlanded else [])
        out.writelines(line + "\n" for line in summary_lines(session.stats, session.control_label(), extra))
    elif session.phase is not Phase.FAILED:
        out.write(f"joyfly: {nothing_flown(session)}\n")
    return closing_status(session, unlanded)


def closing_status(session: SessionLoop, unlanded: str | None) -> int:
    """Say on stderr what went wrong, if anything; the exit status of the worst (failed, not landed, breach)."""
    if session.phase is Phase.FAILED:
        click.echo(f"joyfly: {session.error}", err=True)
        return EXIT_MISTAKE if session.error_is_mistake else 1
    status = 0
    if session.stats.fence_breaches:
        click.echo(f"joyfly: the vehicle went outside the {session.fence.half_width_m:g} m fence "
                   f"({breach_words(session.stats)}).", err=True)
        status = EXIT_FENCE_BREACHED
    if unlanded:
        click.echo(f"joyfly: the flight ended without a landing: {unlanded}.", err=True)
        status = EXIT_NOT_LANDED
    return status


def nothing_flown(session: SessionLoop) -> str:
    """The closing sentence of a session that ended before the vehicle was ever armed."""
    st = session.link.state
    if st.last_heartbeat_s is None:
        return f"Stopped before a vehicle answered on {session.link.transport.description}; nothing was flown."
    return f"Stopped before arming; nothing was flown (the vehicle is disarmed in {st.mode})."


# What PX4 does next in the mode joyfly leaves it in (px4-behaviour.md 4.3 for OFFBOARD without setpoints)
_NEXT = {
    "AUTO.LAND": "it lands and disarms by itself.",
    "AUTO.RTL": "it returns to its home, lands and disarms by itself.",
    "AUTO.LOITER": "it holds position until a ground station takes over.",
    "OFFBOARD": "with no more setpoints, PX4's offboard-loss failsafe takes over within COM_OF_LOSS_T (1 s; "
                "Return in SITL without RC).",
}
_RC_LOSS = ("with no more MANUAL_CONTROL, PX4's manual-control-loss failsafe holds it for COM_FAIL_ACT_T (5 s), "
            "then returns it home (NAV_RCL_ACT).")
# The same once a manual session's MANUAL_CONTROL stream stops (failsafe.cpp: Land and Return go on; the rest fail)
_NEXT_MANUAL = {**_NEXT, "AUTO.LOITER": _RC_LOSS, "POSCTL": _RC_LOSS, "ALTCTL": _RC_LOSS}


def left_behind(session: SessionLoop) -> str:
    """In what state joyfly leaves the vehicle when it quits at once, and what the vehicle does next."""
    st = session.link.state
    if st.last_heartbeat_s is None:
        return "no vehicle had answered; nothing was flown."
    heard = "" if st.link_ok(session.clock.now()) else " (as last heard)"
    if not st.armed:
        return f"the vehicle was left disarmed in {st.mode}{heard}."
    # the HEARTBEAT trails the ACK
    mode = session.exit_mode if session.in_control(st) and session.exit_mode else st.mode
    nexts = _NEXT if session.control_label() == "OFFBOARD" else _NEXT_MANUAL
    return f"the vehicle was left armed in {mode}{heard}: {nexts.get(mode, 'take over with a ground station.')}"


@contextmanager
def exit_signals(session: SessionLoop) -> Iterator[None]:
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


