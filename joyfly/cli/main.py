"""`joyfly fly`, `joyfly demo` and `joyfly joystick ...`: parse options, build the pieces, run, report.

Errors a user can hit (no joystick, port in use, no vehicle, arming refused) end in one sentence and a non-zero exit
status; Ctrl-C / SIGTERM perform --on-exit and exit 0 (3 if the vehicle went outside the fence, 4 if a flight ended
in the air: joyfly/run.py); a second Ctrl-C quits at once.
"""

from __future__ import annotations

import logging
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import click

from flightview.launch import ViewOptions
from flightview.options import view_options, view_settings
from joyfly.cli.joystick import joystick
from joyfly.config import BOUNDS, CONTROLS, ConfigError, FlyOptions, build_options, load_file
from joyfly.dashboard import make_view
from joyfly.link.speedwatch import SpeedWatch
from joyfly.link.transport import TransportError, open_transport
from joyfly.link.vehicle_link import VehicleLink
from joyfly.rumble import Haptics, HapticView, device_of, rumbler_of
from joyfly.run import fly_session
from joyfly.session.core import Level, Note
from joyfly.session.factory import make_session
from joyfly.session.fence_watch import FENCE_ACTIONS, FENCE_GRACE_S, FENCE_TOLERANCE_M, RETURN_M_S, RETURN_WINDOW_S
from joyfly.session.manual_session import MANUAL_CONTROLS, MANUAL_MODES
from joyfly.session.manual_session import RATE_HZ as MANUAL_RATE_HZ
from joyfly.sticks.js.events import JoystickError
from joyfly.sticks.mapping import open_sticks
from joyfly.sticks.sdl.mappings import SdlMappings
from joyfly.sticks.takeoff_check import takeoff_warning
from joyfly.view import add_browser_view, check_view_options
from px4common.cli_style import CONTEXT, VERSION_MESSAGE, FiniteRange, OneLineGroup, UserError, describe_range
from px4common.clock import SPEED_MAX, SPEED_MIN, ScaledClock, WallClock
from px4common.signing_key import SigningKeyError, read_signing_key

TOOL = "joyfly"
D = FlyOptions()


@click.group(name=TOOL, cls=OneLineGroup, version_message=VERSION_MESSAGE, context_settings=CONTEXT)
@click.version_option(package_name="joyfly", prog_name=TOOL, message=VERSION_MESSAGE)
@click.option("-v", "--verbose", count=True, help="More log output on stderr (-v info, -vv debug).")
def main(verbose: int) -> None:
    """Fly a PX4 quadrotor (PX4 SITL or `sitl-emu serve`) with a joystick over MAVLink."""
    level = logging.WARNING - 10 * min(verbose, 2)
    logging.basicConfig(level=level, format="%(levelname)s %(name)s: %(message)s")
    if verbose == 0:
        logging.getLogger("joyfly").setLevel(logging.ERROR + 10)  # the live view already says it all
        logging.getLogger("sitl_emu").setLevel(logging.ERROR)  # the demo's embedded emulator


main.add_command(joystick)


def _opt(name: str, kind: Any, help_text: str, show_range: bool = True, default_text: str | None = None,
         **kw: Any) -> Callable[[Any], Any]:
    """An option whose default lives in FlyOptions (a --config file may set it too): the help shows the default and
    the range, and the value stays None unless given, so the file's value is not overridden."""
    key = name.lstrip("-").replace("-", "_")
    default = getattr(D, key)
    shown = [] if default is None else [f"default: {default_text or default}"]
    if key in BOUNDS and show_range:
        shown.append(describe_range(BOUNDS[key].lo, BOUNDS[key].hi))
    return click.option(name, type=kind, default=None, help=f"{help_text} [{'; '.join(shown)}]" if shown
                        else help_text, **kw)


@main.command(short_help="Fly a vehicle with a joystick.")
@_opt("--joy", str, "Joystick: auto (the first SDL game controller, else SDL joystick, else /dev/input/js0), sdl "
                    "(the first SDL game controller), sdl:N (SDL device N), sdl:NAME (part of its name), a "
                    "/dev/input/js* device, a FIFO of js_event records, a --record recording, raw:FILE (a capture of "
                    "js_event records), script:FILE or replay:FILE; other files are refused.")
@_opt("--sdl-mapping", str, "Extra SDL game-controller mappings: a gamecontrollerdb.txt file or one mapping line.")
@click.option("--rumble/--no-rumble", default=None, help="Rumble pulses on a fence push, a failsafe, link loss and "
              "low battery, on a pad that has rumble. [default: rumble]")
@_opt("--url", str, "Vehicle connection: MAVROS-style udp://[bind]:port@host:port, or udpin:/udpout:/tcp:/serial.")
@_opt("--profile", str, "Controller profile: auto or a name from `joyfly joystick profiles`.")
@_opt("--control", click.Choice(list(CONTROLS)), "How joyfly flies. OFFBOARD setpoints: velocity: the sticks set "
      "the vehicle's velocity and releasing them holds position; step: the setpoint is the vehicle's position plus "
      "--step metres x stick. PX4's manual modes with MANUAL_CONTROL, as QGroundControl's joystick: position: "
      "Position mode (POSCTL), the throttle stick takes off, climbs and descends, the right stick flies forward/right "
      "of the nose, releasing the sticks holds position; altitude: Altitude mode (ALTCTL), the same but the right "
      "stick tilts the vehicle and nothing holds it horizontally. In these two PX4's parameters set the speeds "
      "(MPC_VEL_MANUAL...) and --alt, --step, --max-speed, --max-climb, --max-yaw-rate do not apply.")
@_opt("--step", float, "Step control: metres per full stick.")
@_opt("--alt", float, "Take-off altitude (OFFBOARD), metres above home, from --min-alt to --max-alt.",
      show_range=False)
@_opt("--max-climb", float, "Climb/descent rate at full throttle stick (OFFBOARD), m/s.")
@_opt("--max-speed", float, "Horizontal speed at full stick (OFFBOARD), m/s.")
@_opt("--max-yaw-rate", float, "Yaw rate at full yaw stick (OFFBOARD), deg/s.")
@_opt("--fence", float, "Half-width of the square fence around this flight's home (where joyfly arms the vehicle), "
      "metres; 0 disables. In position/altitude control joyfly limits the sticks near it.")
@_opt("--fence-action", click.Choice(list(FENCE_ACTIONS)), "What joyfly does when the vehicle is more than "
      f"{FENCE_TOLERANCE_M:g} m outside the fence (wind joyfly's setpoints cannot beat): it warns at once, and once "
      f"the vehicle has been outside {FENCE_GRACE_S:g} s and is not coming back (closing in at under {RETURN_M_S:g} "
      f"m/s over the last {RETURN_WINDOW_S:g} s) it acts: land lands where it is, hold is PX4's Hold, rtl PX4's "
      "Return, warn does nothing more. A breach makes the exit status 3.")
@_opt("--min-alt", float, "Lowest altitude, metres above home.")
@_opt("--max-alt", float, "Highest altitude, metres above home.")
@_opt("--rate", float, "Stream rate, Hz: setpoints (OFFBOARD), or MANUAL_CONTROL (position, altitude).",
      default_text=f"{D.rate:g} (OFFBOARD), {MANUAL_RATE_HZ:g} (position, altitude: QGroundControl's)")
@_opt("--on-exit", click.Choice(["land", "hold", "rtl"]), "What the vehicle does when joyfly exits.")
@_opt("--record", str, "Record the joystick's states with timestamps to this file (replay with --joy FILE).")
@_opt("--joy-timeout", float, "Seconds without the joystick before landing.")
@_opt("--connect-timeout", float, "Seconds to wait for the vehicle's first HEARTBEAT and position.")
@_opt("--speed", float, "How many times faster than real time the vehicle runs: the N of its sitl-emu serve "
      "--speed N (1 for PX4 SITL or a real vehicle). joyfly's rates and timeouts run as fast; it warns when the "
      "vehicle's clock says otherwise.")
@_opt("--signing-key", str, "MAVLink 2 signing: sign everything with the 32-byte key in this file (64 hex digits or "
      "raw bytes, as `sitl-emu serve --signing-key`) and take only what the vehicle signs with it.")
@click.option("--setup-signing", is_flag=True, default=None,
              help="Give the vehicle the --signing-key key first (SETUP_SIGNING, as QGroundControl does; PX4 accepts "
                   "it while it has no key, or signed with its current key, and never while armed).")
@click.option("--config", "config_path", default=None, help="TOML file with any of these options and a [profile].")
@view_options
def fly(config_path: str | None, view: bool, view_port: int | None, view_grpc_port: int | None,
        record_view: Path | None, **cli_options: Any) -> None:
    """Connect, take off to --alt in OFFBOARD (or arm in PX4's Position/Altitude mode with --control position/altitude)
    and fly with the joystick; Ctrl-C lands (see --on-exit)."""
    try:
        file_options, profile_table = load_file(config_path) if config_path else ({}, {})
        opts = build_options(file_options, cli_options, source=config_path)
    except (ConfigError, JoystickError) as err:
        raise UserError(str(err)) from None
    view_opts = view_settings(view, view_port, record_view, view_grpc_port)
    check_view_options(view_opts)
    sys.exit(run_fly(opts, profile_table, view_options=view_opts))


def run_fly(opts: FlyOptions, profile_table: dict[str, Any], out: Any = None,
            view_options: ViewOptions | None = None) -> int:
    """Open the joystick and the link, fly until done; returns the exit status."""
    out = out or sys.stdout
    clock: WallClock | ScaledClock = WallClock() if opts.speed == 1.0 else ScaledClock(opts.speed)
    key = _signing_key(opts)
    try:
        sticks = open_sticks(opts.joy, clock, opts.profile, profile_table, record=opts.record,
                             mappings=SdlMappings(opts.sdl_mapping, opts.mappings))
    except JoystickError as err:
        raise UserError(str(err)) from None
    problem = throttle_problem(opts.control, sticks.profile)
    if problem:
        sticks.close()
        raise UserError(problem)
    try:
        transport = open_transport(opts.url)
    except TransportError as err:
        sticks.close()
        raise UserError(str(err)) from None
    view = make_view(out)
    if sticks.why:
        out.write(f"joyfly: --joy {opts.joy} chose {sticks.why}.\n")
    out.write(f"joyfly: joystick {sticks.name} ({sticks.path}), profile {sticks.profile.name}; "
              f"vehicle on {transport.description}; Ctrl-C to land and quit\n")
    if opts.control in MANUAL_CONTROLS:
        warning = takeoff_warning(sticks.source, sticks.profile, MANUAL_MODES[opts.control][2])
        if warning is not None:
            view.note(Note(clock.now(), Level.WARN, warning))
    link = VehicleLink(transport, clock)
    if key is not None:
        link.use_signing(key, setup=opts.setup_signing)
    session = make_session(link, sticks, clock, opts.session_settings(), on_note=view.note)
    watch = SpeedWatch(opts.speed, lambda text: view.note(Note(clock.now(), Level.WARN, text)))
    session.link.on_message.append(watch.observe)
    shown = add_browser_view(view, session, view_options, out)
    rumbler = rumbler_of(sticks) if opts.rumble else None
    yaw_of = (lambda: session.link.state.yaw_rad) if opts.control in MANUAL_CONTROLS else None
    haptics = Haptics(rumbler, yaw_of) if rumbler is not None else None
    return fly_session(session, HapticView(shown, haptics, device_of(sticks)), out)


def _signing_key(opts: FlyOptions) -> bytes | None:
    if opts.setup_signing and opts.signing_key is None:
        raise UserError("--setup-signing gives the vehicle the --signing-key key: name its file with --signing-key.")
    try:
        return read_signing_key(opts.signing_key) if opts.signing_key is not None else None
    except SigningKeyError as err:
        raise UserError(str(err)) from None


def throttle_problem(control: str, profile: Any) -> str | None:
    """PX4's manual modes take off with the throttle: a profile without a throttle axis could never leave the ground."""
    if control in MANUAL_CONTROLS and profile.axis("up") is None and profile.axis("throttle_abs") is None:
        return (f"--control {control} takes off with the throttle stick, but the profile {profile.name} maps no "
                "throttle: pick a profile with --profile, or set [profile.up] index (a centring stick) or "
                "[profile.throttle] index (a radio's throttle) in a --config file.")
    return None


@main.command(short_help="A whole flight with no hardware.")
@click.option("--url", default=None, help="Fly a vehicle already listening there instead of the built-in emulator.")
@click.option("--speed", type=FiniteRange(SPEED_MIN, SPEED_MAX), default=1.0, show_default=True,
              help="Run the built-in emulator (and the script) this many times faster than real time; with --url, "
                   "the speed that vehicle runs at.")
@click.option("--script", "script_path", default=None, help="Joystick script (default: the built-in demo flight).")
@click.option("--live/--plain", default=None, help="Force the live terminal view or plain log lines.")
@click.option("--control", type=click.Choice(list(CONTROLS)), default=D.control, show_default=True,
              help="How to fly, as `joyfly fly --control`: OFFBOARD setpoints (velocity, step) or PX4's Position / "
                   "Altitude mode with MANUAL_CONTROL (position, altitude; the script then takes off with the "
                   "throttle).")
@click.option("--wind", default=None, metavar="SPEED@FROM[,TURBULENCE]",
              help="Wind on the built-in emulator, as `sitl-emu serve --wind`: e.g. 5@270 (5 m/s from the west), "
                   "5@270,light|moderate|severe or a W20 in m/s.")
@click.option("--gcs-remote", default=None, metavar="HOST:PORT",
              help="Send the built-in emulator's ground-station telemetry there (127.0.0.1:14550: a QGroundControl "
                   "on this machine) [default: nowhere until a ground station talks to its port, which the demo "
                   "prints].")
@view_options
def demo(url: str | None, speed: float, script_path: str | None, live: bool | None, control: str, wind: str | None,
         gcs_remote: str | None, view: bool, view_port: int | None, view_grpc_port: int | None,
         record_view: Path | None) -> None:
    """A whole flight with no hardware: the built-in emulator, a scripted joystick, the live view, a summary."""
    from joyfly.demo import DemoError, run_demo

    view_opts = view_settings(view, view_port, record_view, view_grpc_port)
    check_view_options(view_opts)
    try:
        sys.exit(run_demo(url=url, speed=speed, script_path=script_path, live=live, control=control,
                          view_options=view_opts, wind=wind, gcs_remote=gcs_remote))
    except (DemoError, TransportError, JoystickError) as err:
        raise UserError(str(err)) from None


if __name__ == "__main__":
    main()
