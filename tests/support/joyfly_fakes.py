"""Test doubles for joyfly's flight side: a small PX4-like vehicle speaking real MAVLink (pymavlink) over any
joyfly transport, and a timed stick source. Kinematic, not physical: enough to test the client's behaviour.

The fake follows PX4's rules that matter to a client (px4-behaviour.md 3.2-3.7, 4): OFFBOARD needs a setpoint
younger than 1 s to arm or to switch while armed; offboard loss -> AUTO.RTL + "Failsafe activated"; PX4 returns to
OFFBOARD when setpoints resume while the user intention is still OFFBOARD; STATUSTEXT only to a link that heard a
GCS heartbeat; SET_MODE/DO_SET_MODE acknowledged as command 176.
"""

from __future__ import annotations

import math
import threading
import time
from dataclasses import dataclass, field
from typing import Any

from pymavlink.dialects.v20 import common as mavlink2

from joyfly.types import StickCommand

OFFBOARD = 6 << 16
LOITER = (3 << 24) | (4 << 16)
RTL = (5 << 24) | (4 << 16)
LAND = (6 << 24) | (4 << 16)
POSCTL = 3 << 16


class _Out:
    def __init__(self, transport: Any) -> None:
        self.transport = transport

    def write(self, data: bytes) -> None:
        self.transport.write(bytes(data))


@dataclass
class FakeVehicle:
    """A PX4-like quadrotor on the far end of `transport`. Call `step(now_s)` as time advances."""

    transport: Any
    refuse_arm_reason: str | None = None  # e.g. "Arming denied: Resolve system health failures first"
    max_speed_m_s: float = 5.0
    speak: bool = True  # False: stop sending (and reading) anything, as if the link died
    pos: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    vel: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    yaw: float = 0.0
    armed: bool = False
    custom_mode: int = LOITER
    intention: int = LOITER
    landed: bool = True
    home: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])  # PX4 sets it where it arms (COM_HOME_EN)
    log: list[tuple[float, str, Any]] = field(default_factory=list)  # (time, kind, detail) of what it received
    texts: list[str] = field(default_factory=list)
    wind_m_s: tuple[float, float] = (0.0, 0.0)  # north, east: carries it along in the air beyond what it commands

    def __post_init__(self) -> None:
        self.mav = mavlink2.MAVLink(_Out(self.transport), srcSystem=1, srcComponent=1)
        self.mav.robust_parsing = True
        self.now = 0.0
        self.sp: Any = None
        self.sp_time = -math.inf
        self.gcs_heartbeat_time = -math.inf
        self.landed_since = 0.0
        self.sticky_failsafe = False
        self._text_id = 0
        self._next = {"hb": 0.0, "pos": 0.0, "ess": 0.0, "home": 0.0}
        self.boot_s = 0.0  # when it (re)booted: time_boot_ms counts from here

    # --- receive -------------------------------------------------------------------------------------------------
    def _read(self) -> None:
        data = self.transport.read(0.0)
        while data:
            for msg in self.mav.parse_buffer(data) or []:
                self._handle(msg)
            data = self.transport.read(0.0)

    def _handle(self, msg: Any) -> None:
        kind = msg.get_type()
        if kind == "HEARTBEAT":
            self.log.append((self.now, "HEARTBEAT", (msg.type, msg.autopilot, msg.get_srcSystem(),
                                                     msg.get_srcComponent())))
            if msg.type == 6:
                self.gcs_heartbeat_time = self.now
        elif kind == "SET_POSITION_TARGET_LOCAL_NED":
            self.log.append((self.now, "SETPOINT", msg))
            if msg.coordinate_frame == 1:
                self.sp, self.sp_time = msg, self.now
        elif kind == "COMMAND_LONG":
            self.log.append((self.now, f"CMD{msg.command}", msg))
            self._command(msg)

    def _fresh_setpoint(self) -> bool:
        return self.now - self.sp_time < 1.0

    def _ack(self, msg: Any, result: int) -> None:
        self.mav.command_ack_send(msg.command, result, 0, 0, msg.get_srcSystem(), msg.get_srcComponent())

    def _text(self, severity: int, text: str) -> None:
        self.texts.append(text)
        if self.now - self.gcs_heartbeat_time >= 2.5:
            return
        raw = (text + "\t").encode()  # PX4 appends a tab to texts also sent as events
        if len(raw) <= 50:
            self.mav.statustext_send(severity, raw)
            return
        self._text_id += 1  # longer texts go out in 50-byte chunks sharing an id (PX4 streams/STATUSTEXT.hpp)
        for seq, start in enumerate(range(0, len(raw), 50)):
            self.mav.statustext_send(severity, raw[start:start + 50], self._text_id, seq)

    def _command(self, msg: Any) -> None:
        cmd = msg.command
        if cmd == 400:
            self._arm_command(msg)
        elif cmd == 176:
            self._set_mode(msg, int(msg.param2) << 16 | int(msg.param3) << 24)
        elif cmd == 21:
            self.custom_mode = self.intention = LAND
            self._ack(msg, 0)
            self._text(6, "Landing at current position")
        elif cmd == 20:
            self.custom_mode = self.intention = RTL
            self._ack(msg, 0)
        elif cmd == 512:
            self._ack(msg, 0)
            self.mav.home_position_send(0, 0, 0, *self.home, [1, 0, 0, 0], 0, 0, 0)
        else:
            self._ack(msg, 3)

    def _arm_command(self, msg: Any) -> None:
        if round(msg.param1) == 0:
            self.armed = not self.landed and self.armed
            self._ack(msg, 0 if not self.armed else 1)
            return
        if self.custom_mode in (RTL, LAND):
            self._text(2, "Arming denied: mode not armable")
            self._ack(msg, 1)
            return
        if self.refuse_arm_reason or (self.custom_mode == OFFBOARD and not self._fresh_setpoint()):
            self._text(2, self.refuse_arm_reason or "Arming denied: no offboard signal")
            self._ack(msg, 1)
            return
        self.armed = True
        self.landed_since = self.now
        self.home = list(self.pos)
        self._ack(msg, 0)
        self._text(6, "Armed by external command")

    def _set_mode(self, msg: Any, mode: int) -> None:
        if mode == OFFBOARD and self.armed and not self._fresh_setpoint():
            self._ack(msg, 1)
            self._text(2, "Switching to Offboard is currently not available")
            return
        self.custom_mode = self.intention = mode
        self._ack(msg, 0)

    # --- simulate ------------------------------------------------------------------------------------------------
    def failsafe(self, mode: int = RTL, sticky: bool = True) -> None:
        """Leave OFFBOARD as a PX4 failsafe would (the intention stays OFFBOARD). A sticky failsafe (battery,
        geofence...) lasts until `clear_failsafe()`; an offboard-loss one clears when setpoints come back."""
        self.custom_mode = mode
        self.sticky_failsafe = sticky
        self._text(2, "Failsafe activated")

    def clear_failsafe(self) -> None:
        self.sticky_failsafe = False

    def reboot(self) -> None:
        """Restart as a PX4 process does: on the ground at the origin, disarmed in Hold, its boot time from 0."""
        self.pos, self.vel, self.yaw = [0.0, 0.0, 0.0], [0.0, 0.0, 0.0], 0.0
        self.armed, self.landed, self.custom_mode, self.intention = False, True, LOITER, LOITER
        self.sp, self.sp_time, self.sticky_failsafe = None, -math.inf, False
        self.home = [0.0, 0.0, 0.0]
        self.boot_s = self.now
        self._next = dict.fromkeys(self._next, self.now)

    def step(self, now_s: float) -> None:
        dt = now_s - self.now
        self.now = now_s
        if not self.speak:
            return
        self._read()
        self._modes()
        self._move(dt)
        self._telemetry()

    def _modes(self) -> None:
        if self.custom_mode == OFFBOARD and self.armed and not self._fresh_setpoint():
            self.failsafe(RTL, sticky=False)
        elif (self.intention == OFFBOARD and self.custom_mode != OFFBOARD and self._fresh_setpoint()
              and not self.sticky_failsafe):
            self.custom_mode = OFFBOARD  # PX4 clears the fallback once the offboard signal is back
        if self.armed and self.landed and self.custom_mode in (LAND, RTL) and self.now - self.landed_since > 1.0:
            self.armed = False
            self.custom_mode = self.intention = LOITER
            self._text(6, "Disarmed by landing")

    def _target_velocity(self) -> list[float]:
        if not self.armed:
            return [0.0, 0.0, 0.0]
        if self.custom_mode == OFFBOARD and self.sp is not None:
            sp, mask = self.sp, self.sp.type_mask
            ff = [0.0, 0.0, 0.0] if mask & 8 else [sp.vx, sp.vy, sp.vz]
            target = [sp.x, sp.y, sp.z]
            return [1.0 * (t - p) + f for t, p, f in zip(target, self.pos, ff, strict=True)]
        if self.custom_mode == LAND:
            return [0.0, 0.0, 0.7]
        if self.custom_mode == RTL:
            return [-self.pos[0], -self.pos[1], 0.7 if math.hypot(*self.pos[:2]) < 0.3 else 0.0]
        return [0.0, 0.0, 0.0]

    def _move(self, dt: float) -> None:
        target = self._target_velocity()
        norm = math.hypot(target[0], target[1])
        if norm > self.max_speed_m_s:
            target[0], target[1] = target[0] * self.max_speed_m_s / norm, target[1] * self.max_speed_m_s / norm
        target[2] = min(max(target[2], -3.0), 1.5)
        alpha = min(1.0, dt / 0.3)
        self.vel = [v + alpha * (t - v) for v, t in zip(self.vel, target, strict=True)]
        self.pos = [p + v * dt for p, v in zip(self.pos, self.vel, strict=True)]
        if not self.landed:
            self.pos[0] += self.wind_m_s[0] * dt
            self.pos[1] += self.wind_m_s[1] * dt
        if self.pos[2] >= 0.0:
            self.pos[2] = 0.0
            self.vel = [0.0, 0.0, 0.0] if self.vel[2] >= 0 else self.vel
            if not self.landed:
                self.landed, self.landed_since = True, self.now
        elif self.pos[2] < -0.2:
            self.landed = False
        if self.sp is not None and self.custom_mode == OFFBOARD and not self.sp.type_mask & 1024:
            self.yaw = self.sp.yaw

    def _telemetry(self) -> None:
        now = self.now
        if now >= self._next["hb"]:
            base = 1 | (128 if self.armed else 0)
            self.mav.heartbeat_send(2, 12, base, self.custom_mode, self._system_status())
            self._next["hb"] = now + 1.0
        if now >= self._next["pos"]:
            ms = int((now - self.boot_s) * 1000)
            self.mav.local_position_ned_send(ms, *self.pos, *self.vel)
            self.mav.attitude_send(ms, 0.0, 0.0, self.yaw, 0.0, 0.0, 0.0)
            self._next["pos"] = now + 1 / 30
        if now >= self._next["ess"]:
            self.mav.extended_sys_state_send(0, 1 if self.landed else 2)
            self._next["ess"] = now + 0.2
        if now >= self._next["home"]:
            self.mav.home_position_send(0, 0, 0, *self.home, [1, 0, 0, 0], 0, 0, 0)
            self._next["home"] = now + 2.0  # PX4 streams HOME_POSITION at 0.5 Hz (px4-behaviour.md 1.5)

    def _system_status(self) -> int:
        return 4 if self.armed else 3  # ACTIVE, STANDBY

    def received(self, kind: str) -> list[tuple[float, Any]]:
        return [(t, m) for t, k, m in self.log if k == kind]


class WallStepper:
    """Steps a FakeVehicle in a background thread on the wall clock (real-UDP tests)."""

    def __init__(self, vehicle: FakeVehicle, period_s: float = 0.005) -> None:
        self.vehicle = vehicle
        self.period_s = period_s
        self._stop = threading.Event()
        self._t0 = time.monotonic()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self.lock = threading.Lock()

    def __enter__(self) -> WallStepper:
        self._thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._stop.set()
        self._thread.join(2.0)

    def _run(self) -> None:
        while not self._stop.is_set():
            with self.lock:
                self.vehicle.step(time.monotonic() - self._t0)
            time.sleep(self.period_s)


class TimedSticks:
    """A stick source playing (start_time_s, StickCommand) steps on a clock; the last step holds."""

    def __init__(self, clock: Any, steps: list[tuple[float, StickCommand]]) -> None:
        self.clock = clock
        self.steps = sorted(steps, key=lambda s: s[0])
        self.t0 = clock.now()
        self.polls = 0

    def poll(self, timeout_s: float) -> StickCommand:
        self.polls += 1
        t = self.clock.now() - self.t0
        current = StickCommand()
        for start, cmd in self.steps:
            if start <= t:
                current = cmd
        return current

    def close(self) -> None:
        pass
