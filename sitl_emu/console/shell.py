"""The pxh> shell: PX4's console commands, shared by the terminal console and the MAVLink shell.

What each command sends and prints follows PX4 (v1.15):
- `commander ...`: src/modules/commander/Commander.cpp custom_command(): every subcommand publishes an internal
  vehicle_command (from_external false, source = own sysid/compid); results appear later as log lines (events).
- `param ...`: sitl_emu/console/param.py (src/systemcmds/param/param.cpp).
- `mission`: sitl_emu/console/mission.py (our addition: the stored plans and the mission's progress).
- `listener ...`: src/systemcmds/topic_listener/listener_main.cpp (see listener.py). With -n N the messages
  come one by one as the topic is published, so the command keeps running after `execute` returns: the caller prints
  `poll()`'s output each loop and shows the next prompt once `busy` is False, as pxh does when the command returns.
- line handling and errors: platforms/posix/src/px4/common/px4_daemon/pxh.cpp process_line().
Log-style output uses PX4's console format "%-5s [%s] %s" (platforms/common/px4_log.cpp).
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from typing import Any

from sitl_emu.console import listener
from sitl_emu.console.failure import failure_command
from sitl_emu.console.mission import mission_command
from sitl_emu.console.param import log_line, param_command
from sitl_emu.px4 import SHELL_MODE_NAMES, UI_NAMES, MavCmd, MavResult, NavState, main_sub
from sitl_emu.types import VehicleCommand

log = logging.getLogger(__name__)

NAN = math.nan
FORCE_MAGIC = 21196.0  # ARM_DISARM param2: force (Commander.cpp)

# commander subcommands PX4 has and sitl_emu does not emulate (Commander.cpp custom_command, usage)
_PX4_ONLY_SUBCOMMANDS = frozenset({"start", "stop", "calibrate", "transition", "lockdown", "pair", "set_ekf_origin",
                                   "poweroff", "safety", "termination", "actuator_group_test", "set_heading"})

_COMMANDER_USAGE = """Usage: commander <command> [arguments...]
 Commands:
   status        Print status
   check         Run preflight checks
   arm           [-f] Force arming (do not run preflight checks)
   disarm        [-f] Force disarming (disarm in air)
   takeoff
   land
   mode          Change flight mode
     manual|altctl|posctl|position:slow|altitude_cruise|auto:mission|auto:loiter|auto:course|auto:rtl|acro|
     offboard|stabilized|auto:takeoff|auto:land|auto:precland Flight mode
"""

App = Callable[[list[str]], tuple[int, str]]  # arguments -> (status, output)


class Shell:
    """Runs one pxh> command line at a time; `execute` returns the text the command prints.

    `extra_apps` adds commands of one front end (the terminal console's `vehicle`); `help` lists them too.
    `vehicle` may be changed between commands (the console switches vehicles that way).
    """

    def __init__(self, vehicle: Any, on_shutdown: Callable[[], None] | None = None,
                 extra_apps: dict[str, App] | None = None) -> None:
        self.vehicle = vehicle
        self.on_shutdown = on_shutdown
        self._job: listener.ListenerJob | None = None
        self._apps: dict[str, App] = {
            "commander": self._commander,
            "failure": lambda args: failure_command(self.vehicle, args),
            "listener": self._listener,
            "mission": self._mission,
            "param": self._param,
            "shutdown": self._shutdown,
            "ver": self._ver,
            **(extra_apps or {}),
        }

    @property
    def commands(self) -> list[str]:
        """The command names `help` lists."""
        return sorted([*self._apps, "help"])

    @property
    def busy(self) -> bool:
        """A command is still printing (`listener -n N`): no prompt yet."""
        return self._job is not None

    def poll(self) -> str:
        """What the running command prints now (its next message, if one is due)."""
        job = self._job
        if job is None:
            return ""
        try:
            out = job.poll()
        except Exception as err:  # as in execute: end the command with one line, keep the shell
            log.exception("pxh> listener")
            job.printed, out = job.count, log_line("ERROR", "listener", f"internal error: {err}")
        if job.done:
            self._job = None
        return out

    def cancel(self) -> None:
        """Stop the running command (PX4's listener stops on a key press)."""
        self._job = None

    def execute(self, line: str) -> str:
        words = line.split()
        if not words or words[0].startswith("#"):
            return ""
        self.cancel()
        command = words[0]
        if command == "help":
            return "Builtin Commands:\n" + "".join(f"  {name}\n" for name in self.commands)
        app = self._apps.get(command)
        if app is None:
            return f"Invalid command: {command}\ntype 'help' for a list of commands\n"
        try:
            status, out = app(words[1:])
        except Exception as err:  # a failing command must never take the console or the link down
            log.exception("pxh> %s", line)
            status, out = 1, log_line("ERROR", command, f"internal error: {err}")
        if status != 0:
            out += f"Command '{command}' failed, returned {status}.\n"
        return out

    # --- commander ---------------------------------------------------------------------------------------------
    def _commander(self, args: list[str]) -> tuple[int, str]:
        sub = args[0] if args else ""
        force = len(args) > 1 and args[1] == "-f"
        if sub == "arm":
            self._send(MavCmd.COMPONENT_ARM_DISARM, 1.0, FORCE_MAGIC if force else 0.0)
            return 0, ""
        if sub == "disarm":
            self._send(MavCmd.COMPONENT_ARM_DISARM, 0.0, FORCE_MAGIC if force else 0.0)
            return 0, ""
        if sub == "takeoff":
            return self._takeoff()
        if sub == "land":
            self._send(MavCmd.NAV_LAND)
            return 0, ""
        if sub == "mode":
            return self._mode(args[1:])
        if sub == "status":
            return 0, self._status()
        if sub == "check":
            self._send(MavCmd.RUN_PREARM_CHECKS)
            ok = self.vehicle.snapshot().pre_flight_checks_pass
            return 0, log_line("INFO", "commander", f"Preflight check: {'OK' if ok else 'FAILED'}")
        reason = f"{sub}: not supported by sitl_emu" if sub in _PX4_ONLY_SUBCOMMANDS else "unknown command"
        return 1, log_line("WARN", "commander", reason) + _COMMANDER_USAGE

    def _takeoff(self) -> tuple[int, str]:
        """NAV_TAKEOFF with every param NaN (MIS_TAKEOFF_ALT above ground), then arm if it was accepted."""
        ack = self._send(MavCmd.NAV_TAKEOFF)
        if ack is not None and ack.result == MavResult.ACCEPTED:
            self._send(MavCmd.COMPONENT_ARM_DISARM, 1.0, 0.0)  # Commander.cpp: param2 0, checks run
        return 0, ""

    def _mode(self, args: list[str]) -> tuple[int, str]:
        if not args:
            return 1, log_line("ERROR", "commander", "missing argument") + _COMMANDER_USAGE
        nav_state = SHELL_MODE_NAMES.get(args[0])
        if nav_state is None:
            return 0, log_line("ERROR", "commander", f"argument {args[0]} unsupported.")
        main, sub = main_sub(nav_state)
        # base_mode 1 = custom; PX4 passes NaN as sub mode for non-AUTO modes, read as 0 by the (uint8) cast.
        ack = self._send(MavCmd.DO_SET_MODE, 1.0, float(main), float(sub))
        if ack is not None and ack.result == MavResult.TEMPORARILY_REJECTED:
            # PX4 says printRejectMode's text only to a ground station (source component 190, reference 3.3), so
            # its console stays silent; ours says it, so that a refusal is never silent here either.
            return 0, log_line("ERROR", "commander", f"Switching to {UI_NAMES[nav_state]} is currently not available")
        return 0, ""

    def _status(self) -> str:
        snap = self.vehicle.snapshot()
        lines = [
            "Armed" if snap.armed else "Disarmed",
            "prearm safety: Off",  # Commander::print_status: SITL has no safety switch, so the safety is off
            f"navigation mode: {_nav_name(snap.nav_state)}",
            f"user intended navigation mode: {_nav_name(snap.user_intended_nav_state)}",
            f"in failsafe: {'yes' if snap.failsafe else 'no'}",
        ]
        return "".join(log_line("INFO", "commander", text) for text in lines)

    def _send(self, command: int, *params: float) -> Any:
        values = tuple(params) + (NAN,) * (7 - len(params))
        cmd = VehicleCommand(command=command, params=values,  # type: ignore[arg-type]
                             source_system=self.vehicle.sysid, source_component=1, from_external=False)
        return self.vehicle.handle_command(cmd)

    # --- listener ----------------------------------------------------------------------------------------------
    def _listener(self, args: list[str]) -> tuple[int, str]:
        if not args or args[0].startswith("-"):
            return 1, listener.usage()
        topic = listener.TOPICS.get(args[0])
        options = _listener_options(args[1:])
        if options is None:
            return 1, listener.usage()
        instance, count, rate_hz = options
        if topic is None:
            return -1, listener.unknown_topic(args[0])
        if instance not in (-1, 0):
            return 0, "never published\n"
        if instance == -1 and count == 1 and rate_hz == 0:  # listener_main.cpp: one message, no instance number
            return 0, listener.format_message(topic, self.vehicle, f"TOPIC: {topic.name}")
        count = count or 30 * rate_hz  # listener_main.cpp: -r without -n prints 30 s worth
        self._job = listener.ListenerJob(topic, self.vehicle, count, 1_000_000 // rate_hz if rate_hz else 0)
        return 0, self.poll()

    # --- param -------------------------------------------------------------------------------------------------
    def _param(self, args: list[str]) -> tuple[int, str]:
        return param_command(self.vehicle.params, args, int(self.vehicle.sysid))

    def _mission(self, args: list[str]) -> tuple[int, str]:
        return mission_command(self.vehicle.mission_store(), self.vehicle.snapshot().nav_state, args)

    # --- system ------------------------------------------------------------------------------------------------
    def _shutdown(self, args: list[str]) -> tuple[int, str]:
        if self.on_shutdown is None:
            return 1, log_line("ERROR", "shutdown", "not available from this shell")
        self.on_shutdown()
        return 0, "Exiting NOW.\n"

    def _ver(self, args: list[str]) -> tuple[int, str]:
        return 0, "HW arch: PX4_SITL\nPX4 version: emulated by sitl_emu (PX4 v1.15 behaviour)\nOS: Linux\n"


def _listener_options(args: list[str]) -> tuple[int, int, int] | None:
    """-i instance, -n messages, -r rate (listener_main.cpp getopt "i:r:n:"); None on anything else."""
    values = {"-i": -1, "-n": 0, "-r": 0}
    if len(args) % 2:
        return None
    for flag, text in zip(args[::2], args[1::2], strict=True):
        if flag not in values or not text.isdigit():
            return None
        values[flag] = int(text)
    if values["-n"] > listener.MAX_MESSAGES or values["-r"] > 1000:
        return None
    return values["-i"], values["-n"] or (0 if values["-r"] else 1), values["-r"]


def _nav_name(nav_state: NavState) -> str:
    return UI_NAMES.get(nav_state, str(int(nav_state)))
