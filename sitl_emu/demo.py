"""A scripted flight of the vehicle core, no MAVLink: `python -m sitl_emu.demo`.

Arm, take off (NAV_TAKEOFF), hold, fly an OFFBOARD position step, land (NAV_LAND) and wait for the auto-disarm,
printing the vehicle's log lines and a status line per phase, all stamped with simulated time.
"""

from __future__ import annotations

import math
import time

from sitl_emu.px4 import LandedState, MavCmd, MavResult, NavState, custom_mode, decode_custom_mode, mode_name
from sitl_emu.types import OffboardControlMode, TrajectorySetpoint, VehicleCommand
from sitl_emu.vehicle.vehicle import Vehicle

NAN = math.nan
POS = OffboardControlMode(position=True)


class Demo:
    def __init__(self) -> None:
        self.v = Vehicle()
        self._seq = 0
        self._stream: TrajectorySetpoint | None = None
        self._next_stream_us = 0

    def say(self, text: str) -> None:
        print(f"[{self.v.time_us / 1e6:7.3f} s] {text}")

    def status(self) -> None:
        s = self.v.snapshot()
        x, y, z = s.pos_ned_m
        self.say(f"  {mode_name(s.nav_state):<12} {'armed' if s.armed else 'disarmed':<8} "
                 f"{LandedState(s.landed_state).name:<9} pos N {x:6.2f} E {y:6.2f} alt {0.0 - z:5.2f} m")

    def command(self, name: str, command: int, *params: float) -> None:
        p = (*params, *(NAN,) * (7 - len(params)))
        ack = self.v.handle_command(VehicleCommand(command, p))  # type: ignore[arg-type]
        self.say(f"> {name}: {'no ACK' if ack is None else MavResult(ack.result).name}")
        self._print_events()

    def run(self, seconds: float) -> None:
        end = self.v.time_us + int(seconds * 1e6)
        while self.v.time_us < end:
            if self._stream is not None and self.v.time_us >= self._next_stream_us:
                self.v.offboard_input(POS, self._stream)
                self._next_stream_us = self.v.time_us + 50_000  # 20 Hz, as MAVSDK streams
            self.v.step()
            self._print_events()

    def _print_events(self) -> None:
        for e in self.v.events_after(self._seq):
            print(f"[{e.time_us / 1e6:7.3f} s] {e.console_line}")
            self._seq = e.seq

    def fly(self) -> None:
        self.say("boot: disarmed in Hold, waiting for the simulated estimator")
        self.run(2.5)
        self.status()
        self.command("arm", MavCmd.COMPONENT_ARM_DISARM, 1.0)
        self.command("takeoff", MavCmd.NAV_TAKEOFF)
        self.run(12.0)
        self.status()
        self.say("hold for 3 s")
        self.run(3.0)
        self.status()
        z = self.v.snapshot().pos_ned_m[2]
        self._stream = TrajectorySetpoint(position_ned_m=(0.0, 0.0, z))
        self.run(0.5)
        main, sub = decode_custom_mode(custom_mode(NavState.OFFBOARD))
        self.command("set mode OFFBOARD", MavCmd.DO_SET_MODE, 1 | 128, main, sub)
        self.say("offboard: position setpoint 10 m north")
        self._stream = TrajectorySetpoint(position_ned_m=(10.0, 0.0, z))
        for _ in range(4):
            self.run(2.0)
            self.status()
        main, sub = decode_custom_mode(custom_mode(NavState.AUTO_LOITER))
        self.command("set mode Hold", MavCmd.DO_SET_MODE, 1 | 128, main, sub)
        self._stream = None
        self.command("land", MavCmd.NAV_LAND)
        while self.v.snapshot().armed and self.v.time_us < 120_000_000:
            self.run(1.0)
            if self.v.time_us % 2_000_000 == 0:
                self.status()
        self.status()


def main() -> None:
    demo = Demo()
    cpu = time.process_time()
    demo.fly()
    cpu = time.process_time() - cpu
    sim_s = demo.v.time_us / 1e6
    print(f"simulated {sim_s:.1f} s in {cpu:.2f} s of CPU ({sim_s / cpu:.0f}x real time)")


if __name__ == "__main__":
    main()
