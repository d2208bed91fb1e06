"""`joyfly demo`: a whole joystick flight with no hardware and no second terminal.

It starts the bundled emulator in-process (sitl_emu's vehicle node on free loopback ports, run by its real-time
runner in a background thread), or uses a vehicle already listening at `--url`; flies a scripted joystick (take off,
a square inside the fence, a push against the fence, land) through the same session `joyfly fly` uses, with the
live view; and ends with a summary: distance flown, closest approach to the fence, time in OFFBOARD.
"""

from __future__ import annotations

import importlib.util
import socket
import sys
import threading
import time
from dataclasses import replace
from typing import Any, TextIO

from flightview.launch import ViewOptions
from joyfly.config import FlyOptions
from joyfly.dashboard import make_view
from joyfly.link.transport import UdpTransport, open_transport
from joyfly.link.vehicle_link import VehicleLink
from joyfly.session.factory import make_session
from joyfly.session.manual_session import MANUAL_CONTROLS
from joyfly.session.manual_session import RATE_HZ as MANUAL_RATE_HZ
from joyfly.sticks.mapping import MappedSource
from joyfly.sticks.profiles.profile import load_profile
from joyfly.sticks.virtual import ScriptSource
from px4common.clock import ScaledClock

# The demo flight (joyfly takes off by itself at the start; the sticks then fly a square and push the fence).
# Format: joyfly/sticks/virtual.py. With the default options full stick = 5 m/s, the fence is 5 m around home.
DEMO_SCRIPT = """\
8      forward=0.5               # north, 2.5 m/s
+1.6   forward=0
+1.5   right=0.5                 # east
+1.6   right=0
+1.5   forward=-0.5              # south
+1.6   forward=0
+1.5   right=-0.5                # west, back over home
+1.6   right=0
+1.5   up=0.5 yaw=0.5            # climb a little, turn clockwise
+2     up=0 yaw=0
+1     forward=1                 # full stick north for 4 s: 20 m of demand, the fence stops it at 5 m
+4     forward=0
+1     forward=-0.5              # back towards home
+2     forward=0
+2     land=1
+0.3   land=0
+30    end
"""
# --control position/altitude: PX4 takes off with the throttle (joyfly arms with it centred in about 3 s); in POSCTL
# half a stick is about 2.3 m/s (PX4's deadzone and expo, MPC_VEL_MANUAL 10 m/s at full stick), the nose points north.
MANUAL_DEMO_SCRIPT = """\
6      up=1                      # throttle up: PX4 lifts off after its spool-up and takeoff ramp, climbs 1.5 m/s
+5     up=0                      # centred: holds its altitude, about 4 m
+3     forward=0.6               # forward, north
+3     forward=0
+3     right=0.6                 # right, east
+3     right=0
+3     forward=-0.6              # south
+3     forward=0
+3     right=-0.6                # west, back over home
+3     right=0
+3     forward=1                 # full stick north: joyfly limits the stick as the fence nears
+6     forward=0
+3     land=1
+0.3   land=0
+40    end
"""
DEMO_TIMEOUT_S = 120.0  # simulated seconds; the scripted flight needs about 50


class DemoError(Exception):
    """The demo cannot start; the message says why and what to do."""


class VehicleTimeClock:
    """joyfly's clock = the embedded vehicle's simulated time, so joyfly's rates and timeouts stay in step with the
    vehicle even when the emulator cannot keep up with its speed factor (a busy machine)."""

    def __init__(self, vehicle: Any, speed: float) -> None:
        self.vehicle = vehicle
        self.speed = speed

    def now(self) -> float:
        return int(self.vehicle.time_us) / 1e6

    def sleep(self, seconds: float) -> None:
        end = self.now() + seconds
        give_up = time.monotonic() + 10 * seconds / self.speed + 0.5  # the emulator stopped: do not hang
        while self.now() < end and time.monotonic() < give_up:
            time.sleep(min(max((end - self.now()) / self.speed, 0.0002), 0.01))


class EmbeddedVehicle:
    """sitl_emu's vehicle node on free loopback ports, run in real time (x speed) in a daemon thread."""

    def __init__(self, joyfly_port: int, speed: float, wind: str | None = None, gcs_remote: str | None = None) -> None:
        """`wind` is `sitl-emu serve --wind`'s SPEED@FROM_DEG[,TURBULENCE] text (None: calm air); `gcs_remote` a
        HOST:PORT where the ground-station link sends its telemetry until a ground station talks to it (None: to a
        socket of the demo's own that drops it, so that a QGroundControl on this machine sees nothing unasked)."""
        try:
            from sitl_emu.cli.main import build_params, build_vehicle
            from sitl_emu.cli.options import UsageProblem, parse_address
            from sitl_emu.disturbance.wind import parse_wind
            from sitl_emu.runtime.node import LinkSettings, VehicleNode
            from sitl_emu.runtime.runner import RealTimeRunner
        except ImportError as exc:
            raise DemoError(f"The bundled emulator cannot be imported ({exc}): reinstall with `make demo`.") from None
        try:
            wind_settings = parse_wind(wind) if wind is not None else None
        except ValueError as err:
            raise DemoError(f"--wind: {err}") from None
        try:
            gcs_address = parse_address(gcs_remote, "--gcs-remote") if gcs_remote is not None else None
        except UsageProblem as err:
            raise DemoError(str(err)) from None
        self._sink: socket.socket | None = None
        if gcs_address is None:
            self._sink = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
            self._sink.bind(("127.0.0.1", 0))
            gcs_address = self._sink.getsockname()
        self.gcs_remote: tuple[str, int] | None = None if self._sink else gcs_address
        settings = LinkSettings(bind_host="127.0.0.1", api_port=0, api_remote=("127.0.0.1", joyfly_port),
                                gcs_port=0, gcs_remote=gcs_address)
        self.node: Any = VehicleNode(build_vehicle(build_params(None, ()), None, 0, 1, wind_settings), settings)
        self.runner = RealTimeRunner([self.node], speed=speed)
        self._thread = threading.Thread(target=self.runner.run, name="sitl-emu", daemon=True)

    @property
    def gcs_port(self) -> int:
        """The ground-station link's own port: a ground station that sends there first gets the telemetry."""
        return int(self.node.gcs.link.port)

    def describe_gcs(self) -> str:
        sending = f"sending to {self.gcs_remote[0]}:{self.gcs_remote[1]}" if self.gcs_remote else \
            "sending nowhere until a ground station talks to it (--gcs-remote HOST:PORT sends)"
        return f"ground-station link on UDP {self.gcs_port}, {sending}"

    @property
    def api_address(self) -> tuple[str, int]:
        host, port = self.node.api.link.local_address
        return ("127.0.0.1" if host in ("0.0.0.0", "") else host, port)

    def start(self) -> None:
        self._thread.start()

    def clock(self) -> VehicleTimeClock:
        """A clock reading this vehicle's simulated time, for joyfly's session and script in the same process."""
        return VehicleTimeClock(self.node.vehicle, self.runner.speed)

    def stop(self) -> None:
        self.runner.stop()
        self._thread.join(2.0)
        self.close()

    def close(self) -> None:
        self.node.close()
        if self._sink is not None:
            self._sink.close()


def script_source(script_path: str | None, clock: Any, control: str = "velocity") -> MappedSource:
    """The scripted joystick, mapped through the built-in `script` profile."""
    text = MANUAL_DEMO_SCRIPT if control in MANUAL_CONTROLS else DEMO_SCRIPT
    source = ScriptSource.from_file(script_path, clock) if script_path else ScriptSource.from_text(
        text, clock, "<built-in demo script>")
    return MappedSource(source, load_profile("auto", source.name))


def run_demo(url: str | None = None, speed: float = 1.0, script_path: str | None = None, live: bool | None = None,
             out: TextIO | None = None, options: FlyOptions | None = None, control: str | None = None,
             view_options: ViewOptions | None = None, wind: str | None = None, gcs_remote: str | None = None) -> int:
    """Fly the demo; returns the exit status (0 when the flight ended landed and disarmed). `control` picks the way
    of flying (FlyOptions.control), position/altitude at QGroundControl's MANUAL_CONTROL rate; `wind` (SPEED@FROM_DEG
    [,TURBULENCE]) blows on the built-in emulator, whose ground-station link sends to `gcs_remote` (HOST:PORT)."""
    from joyfly.run import fly_session
    from joyfly.view import add_browser_view

    out = out or sys.stdout
    opts = options or FlyOptions()
    if control is not None:
        opts = replace(opts, control=control, rate=MANUAL_RATE_HZ if control in MANUAL_CONTROLS else opts.rate)
    _check_url_options(url, wind, gcs_remote)
    transport: Any = open_transport(url) if url else UdpTransport(("127.0.0.1", 0), None)
    emulator = None
    if url is None:
        try:
            emulator = EmbeddedVehicle(transport.local_port, speed, wind, gcs_remote)
        except DemoError:
            transport.close()
            raise
        transport.remote = emulator.api_address
        transport.description = f"the built-in emulator (UDP {emulator.api_address[1]})"
        emulator.start()
    # with --url, `speed` is the speed that vehicle runs at
    clock: ScaledClock | VehicleTimeClock = emulator.clock() if emulator is not None else ScaledClock(speed)
    sticks = script_source(script_path, clock, opts.control)
    view = make_view(out, live)
    out.write(f"joyfly demo: {transport.description}, scripted joystick "
              f"{sticks.path}{f', x{speed:g} speed' if emulator and speed != 1 else ''}"
              f"{f', wind {wind}' if wind else ''}\n")
    out.write(f"joyfly demo: {emulator.describe_gcs()}\n" if emulator else "")
    out.write(_view_hint(view_options))
    settings = opts.session_settings(exit_when_landed=True)
    session = make_session(VehicleLink(transport, clock), sticks, clock, settings, on_note=view.note)
    try:
        shown = add_browser_view(view, session, view_options, out)
    except BaseException:
        if emulator is not None:
            emulator.stop()
        raise
    watchdog = threading.Timer(DEMO_TIMEOUT_S / clock.speed, session.request_exit)
    watchdog.daemon = True
    watchdog.start()
    try:
        status = fly_session(session, shown, out)
    finally:
        watchdog.cancel()
        if emulator is not None:
            emulator.stop()
    return status


def _check_url_options(url: str | None, wind: str | None, gcs_remote: str | None) -> None:
    """--wind and --gcs-remote are the built-in emulator's: refused with --url, in one sentence."""
    if url is not None and wind is not None:
        raise DemoError("--wind blows on the built-in emulator only: give the vehicle at --url its own wind "
                        "(sitl-emu serve --wind).")
    if url is not None and gcs_remote is not None:
        raise DemoError("--gcs-remote sets the built-in emulator's ground-station link only: the vehicle at --url "
                        "has its own (sitl-emu serve --gcs-remote).")


def _view_hint(view_options: ViewOptions | None) -> str:
    """Without the view extra (the demo does not need it), one line saying how to see the flight in 3D."""
    if (view_options is not None and view_options.wanted) or importlib.util.find_spec("rerun") is not None:
        return ""
    from flightview.server import install_hint

    return f"joyfly demo: to see the flight in 3D in a browser, {install_hint()} and add --view\n"
