"""`joyfly joystick calibrate`: the calibration wizard (joyfly/sticks/profiles/calibrate.py) on a terminal; writes the
profile where joyfly looks profiles up (joyfly/sticks/profiles/user.py), shows it, and from then on `joyfly fly`
flies that device with it (with --profile auto)."""

from __future__ import annotations

import sys
import threading

import click

from joyfly.sticks.js.events import JoystickError
from joyfly.sticks.profiles.calibrate import Wizard
from joyfly.sticks.profiles.user import profile_dir, profile_toml, write_user_profile
from joyfly.sticks.sdl.mappings import SdlMappings
from joyfly.sticks.sources import open_source
from px4common.clock import WallClock


class TerminalConsole:
    """Prompts on stdout; Enter read by a helper thread, so the wizard keeps reading the sticks meanwhile. Each
    prompt forgets an earlier Enter; once stdin is closed, every prompt counts as answered with Enter."""

    def __init__(self) -> None:
        self._enter = threading.Event()
        self._closed = False
        threading.Thread(target=self._read, name="enter", daemon=True).start()

    def _read(self) -> None:
        for _ in sys.stdin:
            self._enter.set()
        self._closed = True
        self._enter.set()

    def say(self, text: str) -> None:
        if not self._closed:
            self._enter.clear()
        click.echo(text)

    def entered(self) -> bool:
        return self._enter.is_set()


@click.command("calibrate", short_help="Learn a joystick's layout and write its profile.")
@click.option("--joy", "joy", default="auto", show_default=True,
              help="The joystick, as `joyfly fly --joy`: auto, sdl, sdl:N, sdl:NAME, a /dev/input/js* device...")
@click.option("--sdl-mapping", default=None, help="Extra SDL game-controller mappings (a file or one line).")
@click.option("--dev-dir", default="/dev/input", show_default=True, hidden=True)
def calibrate(joy: str, sdl_mapping: str | None, dev_dir: str) -> None:
    """A wizard, as QGroundControl's: centre and deadzones, which stick is throttle, yaw, pitch and roll (and which
    are reversed; a radio's throttle that rests at one end), and the buttons; then writes the profile that
    `joyfly fly` uses for this device from then on."""
    try:
        source = open_source(joy, WallClock(), dev_dir=dev_dir, mappings=SdlMappings(sdl_mapping)).source
    except JoystickError as exc:
        raise click.ClickException(str(exc)) from None
    guid = str(getattr(source, "guid", ""))
    click.echo(f"Calibrating {source.name} ({source.path}); Ctrl-C stops without writing anything.")
    try:
        profile = Wizard(source, TerminalConsole()).run()
    except JoystickError as exc:
        raise click.ClickException(str(exc)) from None
    except KeyboardInterrupt:
        raise click.ClickException("Calibration stopped: nothing was written.") from None
    finally:
        source.close()
    text = profile_toml(source.name, guid, profile, f" for {source.name}")
    try:
        path = write_user_profile(text, source.name)
    except JoystickError as exc:
        raise click.ClickException(str(exc)) from None
    click.echo(f"\n{text}")
    click.echo(f"Wrote {path} (the profiles in {profile_dir()}): `joyfly fly` flies {source.name} with it from now "
               "on (with --profile auto).")
