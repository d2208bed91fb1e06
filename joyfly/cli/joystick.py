"""`joyfly joystick list` and `joyfly joystick test`: find joysticks and watch what they send.

`test` is what `rostopic echo /joy` was for, plus the flying commands the matched profile makes of it (and the
MANUAL_CONTROL values `--control position/altitude` sends for them, before the fence): a live view on a terminal, one
plain line per change otherwise (a pipe, a log, a test). It ends on Ctrl-C, after --duration, or when a virtual
joystick reaches its end.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from typing import Any, TextIO

import click

from joyfly.cli.calibrate import calibrate
from joyfly.sticks.examples import virtual_joystick_hint
from joyfly.sticks.js.events import JoystickError
from joyfly.sticks.js.seam import js_reader_or_none
from joyfly.sticks.manual import to_manual
from joyfly.sticks.mapping import StickMapper
from joyfly.sticks.profiles.profile import BUILTIN, Profile, load_profile, profile_names, read_config, rest_problems
from joyfly.sticks.profiles.user import find_user_profile
from joyfly.sticks.sdl.listing import sdl_lines
from joyfly.sticks.sdl.mappings import SdlMappings
from joyfly.sticks.sdl.source import SdlSource
from joyfly.sticks.sources import check_profile_choice, open_source, pick_profile
from joyfly.sticks.virtual import TimedSource, record_to
from joyfly.term import LiveBlock
from joyfly.types import Clock, JoyState, JoystickSource, StickCommand
from px4common.cli_style import CONTEXT, FiniteRange, OneLineGroup
from px4common.clock import WallClock

DEV_DIR = "/dev/input"


@click.group("joystick", cls=OneLineGroup, tool="joyfly", context_settings=CONTEXT,
             short_help="List and test joysticks (no vehicle needed).")
def joystick() -> None:
    """Find joysticks and check what they send (no vehicle needed)."""


@joystick.command("list", short_help="List the joysticks and their profiles.")
@click.option("--dev-dir", default=DEV_DIR, show_default=True, hidden=True, help="Where the js* nodes live.")
@click.option("--sdl-mapping", default=None, help="Extra SDL game-controller mappings (a file or one line).")
def list_cmd(dev_dir: str, sdl_mapping: str | None) -> None:
    """Every SDL device (index for --joy sdl:N, name, GUID, game controller or joystick, axes/buttons/hats, rumble)
    and every /dev/input/js*, with the profile that matches it."""
    try:
        lines = sdl_lines(SdlMappings(sdl_mapping))
    except JoystickError as exc:
        raise click.ClickException(str(exc)) from None
    js = js_reader_or_none()
    found = js.list_devices(dev_dir) if js is not None else []
    if not found and not [ln for ln in lines if not ln.startswith("?")]:
        for line in lines:  # why SDL could not look
            click.echo(line)
        click.echo(f"No joystick found (SDL sees none, and no {dev_dir}/js*): plug one in, or fly a virtual one "
                   f"with {virtual_joystick_hint()}.")
        return
    for line in lines:
        click.echo(line)
    for item in found:
        click.echo(_device_line(item))


def _device_line(item: Any) -> str:
    """A js device (joystick.DeviceInfo) with its profile, or the JoystickError that stopped its probe."""
    if isinstance(item, JoystickError):
        return f"?  {item}"
    mine = find_user_profile(item.name)
    profile = mine.profile if mine is not None else load_profile("auto", item.name, {})
    counts = f"{item.axes} axes, {item.buttons} buttons" if item.kind == "device" else f"({item.kind})"
    return f"{item.path}  \"{item.name}\"  {counts}  profile: {profile.name}"


joystick.add_command(calibrate)


@joystick.command("profiles", short_help="The built-in controller profiles.")
def profiles_cmd() -> None:
    """The built-in controller profiles, the device names they match, and their layout."""
    for profile in BUILTIN:
        axes = ", ".join(f"{role}={ax.index}{' inverted' if ax.invert else ''}" for role, ax in profile.axes.items())
        buttons = ", ".join(f"{a.value}={i}" for a, i in profile.buttons.items())
        click.echo(f"{profile.name}: {profile.description}")
        click.echo(f"    matches {' | '.join(profile.match)}")
        click.echo(f"    axes {axes}; buttons {buttons}" + (f"; {profile.notes}" if profile.notes else ""))


@joystick.command("test", short_help="Watch a joystick's axes and buttons live.")
@click.option("--joy", "joy", default="auto", show_default=True, help="As `joyfly fly --joy`: auto, sdl, sdl:N, "
              "sdl:NAME, a /dev/input/js* device, a FIFO of js_event records, a --record recording, raw:FILE, "
              "script:FILE or replay:FILE.")
@click.option("--sdl-mapping", default=None, help="Extra SDL game-controller mappings (a file or one line).")
@click.option("--profile", "profile_name", default="auto", show_default=True,
              help=f"Controller profile: auto or one of {', '.join(profile_names())}.")
@click.option("--config", "config_path", default=None, help="TOML file whose [profile] table overrides the profile.")
@click.option("--duration", type=FiniteRange(0.1, 86400), default=None, help="Stop after this many seconds.")
@click.option("--record", "record_path", default=None, help="Also record the session to this file (JSON lines), to "
              "replay with --joy FILE.")
@click.option("--dev-dir", default=DEV_DIR, show_default=True, hidden=True)
def test_cmd(joy: str, sdl_mapping: str | None, profile_name: str, config_path: str | None, duration: float | None,
             record_path: str | None, dev_dir: str) -> None:
    """Show the axes and buttons live, and the flying commands the profile makes of them."""
    clock = WallClock()
    try:
        overrides: dict[str, Any] = read_config(config_path) if config_path else {}
        check_profile_choice(profile_name, overrides)
        opened = open_source(joy, clock, dev_dir=dev_dir, mappings=SdlMappings(sdl_mapping))
    except JoystickError as exc:
        raise click.ClickException(str(exc)) from None
    source = opened.source
    if opened.why:
        click.echo(f"--joy {joy} chose {opened.why}.")
    try:
        profile = pick_profile(source, profile_name, overrides)
        source = record_to(source, record_path) if record_path else source
    except JoystickError as exc:
        source.close()
        raise click.ClickException(str(exc)) from None
    view = LiveView(sys.stdout) if sys.stdout.isatty() else PlainView(click.echo)
    try:
        watch(source, profile, clock, view, duration)
    except KeyboardInterrupt:
        pass
    finally:
        source.close()
        view.close()


# ---------------------------------------------------------------------------------------------------------- watching


def watch(source: JoystickSource, profile: Profile, clock: Clock, view: PlainView | LiveView,
          duration_s: float | None = None, poll_s: float = 0.05) -> None:
    """Poll the source and show every change until the duration is over or a virtual source has ended."""
    view.header(source, profile)
    mapper = StickMapper(profile)
    start = clock.now()
    checked = isinstance(getattr(source, "source", source), TimedSource)  # virtual sticks: no rest check
    while duration_s is None or clock.now() - start < duration_s:
        timeout = poll_s if duration_s is None else max(0.0, min(poll_s, duration_s - (clock.now() - start)))
        state = source.poll(timeout)
        cmd, _ = mapper.update(state)
        if not checked and state.connected and state.axes:
            checked = True
            for problem in rest_problems(profile, state):
                view.note(f"warning: {problem}")
        view.show(state, cmd, start, _error_of(source))
        if _ended(source):
            break


def _ended(source: JoystickSource) -> bool:
    inner = getattr(source, "source", source)  # a RecordingSource wraps the real one
    return isinstance(inner, TimedSource) and inner.ended


def _error_of(source: JoystickSource) -> str:
    inner = getattr(source, "source", source)
    gone = getattr(inner, "gone", None)  # a stream that is no js_events, a raw capture that ended
    if isinstance(gone, str):
        return f"({gone})"
    if isinstance(inner, TimedSource) and inner.ended:
        return "(the virtual joystick reached its end)"
    if isinstance(inner, SdlSource):
        return str(inner.last_error or "")
    js = js_reader_or_none()
    if js is None or not isinstance(inner, js.JsDevice):
        return ""
    if inner.last_error is None and inner.kind == "fifo":
        return "(waiting for a writer on the FIFO)"
    return str(inner.last_error or "")


def _sticks(cmd: StickCommand) -> str:
    up = "  --" if cmd.up is None else f"{cmd.up:+.2f}"
    text = f"forward={cmd.forward:+.2f} right={cmd.right:+.2f} up={up} yaw={cmd.yaw:+.2f}"
    if cmd.throttle_abs is not None:
        text += f" throttle={cmd.throttle_abs:.2f}"
    return text


def _pressed(cmd: StickCommand) -> str:
    held = dict(cmd.held_s)
    names = [f"{a.value}({held.get(a, 0.0):.1f}s)" for a in sorted(cmd.pressed, key=lambda a: a.value)]
    if cmd.deadman_ok is not None:
        names.append("deadman-ok" if cmd.deadman_ok else "deadman-released")
    return ",".join(names) or "-"


class PlainView:
    """One line per change (buttons, connection, or an axis), for pipes, logs and tests."""

    def __init__(self, echo: Callable[[str], None]) -> None:
        self.echo = echo
        self._last: tuple[Any, ...] | None = None

    def header(self, source: JoystickSource, profile: Profile) -> None:
        self.echo(f"{source.name} ({source.path}), profile {profile.name}")

    def note(self, text: str) -> None:
        self.echo(text)

    def show(self, state: JoyState, cmd: StickCommand, start_s: float, error: str) -> None:
        key = (state.axes, state.buttons, state.connected)
        if key == self._last:
            return
        self._last = key
        if not state.connected:
            self.echo(f"t={state.time_s - start_s:.2f} disconnected {error}".rstrip())
            return
        self.echo(f"t={state.time_s - start_s:.2f} axes={list(state.axes)} buttons={list(state.buttons)} "
                  f"{_sticks(cmd)} manual=({to_manual(cmd).describe()}) pressed={_pressed(cmd)}")

    def close(self) -> None:
        pass


class LiveView:
    """A block of lines redrawn in place on a terminal, at most 20 times a second."""

    def __init__(self, out: TextIO) -> None:
        self.out = out
        self._block = LiveBlock(out)
        self._next_draw_s = 0.0
        self._connected = True

    def header(self, source: JoystickSource, profile: Profile) -> None:
        self.out.write(f"{source.name} ({source.path}), profile {profile.name}; Ctrl-C to quit\n")

    def note(self, text: str) -> None:
        self._block.erase()
        self.out.write(text + "\n")

    def show(self, state: JoyState, cmd: StickCommand, start_s: float, error: str) -> None:
        if state.time_s < self._next_draw_s and state.connected == self._connected:
            return
        self._connected = state.connected
        self._next_draw_s = state.time_s + 0.05
        axes = " ".join(f"{i}:{v / 32767:+.2f}" for i, v in enumerate(state.axes)) or "(none yet)"
        buttons = " ".join(f"{i}:{v}" for i, v in enumerate(state.buttons)) or "(none yet)"
        status = "connected" if state.connected else f"DISCONNECTED {error}".rstrip()
        self._block.draw([f"t={state.time_s - start_s:7.2f}  {status}", f"axes     {axes}", f"buttons  {buttons}",
                          f"flying   {_sticks(cmd)}", f"manual   MANUAL_CONTROL {to_manual(cmd).describe()} "
                          "(--control position/altitude)", f"pressed  {_pressed(cmd)}"])

    def close(self) -> None:
        self.out.write("\n")
        self.out.flush()
