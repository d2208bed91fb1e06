"""What the motors get and report: SERVO_OUTPUT_RAW from the mixer's commands, ESC_INFO / ESC_STATUS from the motors.

SERVO_OUTPUT_RAW (streams/SERVO_OUTPUT_RAW.hpp) copies actuator_outputs, the values the SITL output driver
(pwm_out_sim, PWMSim.hpp) produced: its fixed PWM range for all 16 channels, disarmed 900, minimum 1000, maximum
2000, failsafe (termination) 600. Armed, a motor's command u (0..1) goes out as 1000 + 1000 u (mixer_module
output_limit_calc, truncated to an integer); channels without a function (5-16 on the quad) stay at the disarmed value.

ESC_INFO / ESC_STATUS (streams/ESC_INFO.hpp, ESC_STATUS.hpp, not in pymavlink: extra_messages.py) copy esc_status,
which PX4 SIH publishes for its four simulated motors. Its telemetry uses PX4's own simulated-ESC model (the one
streams/HIL_ACTUATOR_CONTROLS.hpp published for simulators): for a motor at u (the motor's state, behind the command
by SIH_T_TAU), 6000 u rpm, 11.1 + 3 u V, 1 + 15 u A while armed (0 disarmed) and 20 + 40 u degrees C; all four
online, no failures, no errors.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Final

from sitl_emu.control.qmath import isfinite
from sitl_emu.mavlink.wire.extra_messages import EXTRA
from sitl_emu.px4 import NavState
from sitl_emu.types import Vec4, VehicleSnapshot

if TYPE_CHECKING:
    from sitl_emu.mavlink.context import EndpointContext, OutMessage

PWM_DISARMED, PWM_MIN, PWM_MAX, PWM_FAILSAFE = 900, 1000, 2000, 600
SERVO_CHANNELS: Final = 16
ESC_COUNT: Final = 4
ESC_ONLINE: Final = (1 << ESC_COUNT) - 1
ESC_CONNECTION_TYPE_PPM: Final = 0
ESC_PUBLISH_PERIOD_US: Final = 100_000  # esc_status at 10 Hz: its counter counts publications
# tuples of any length: compiled, a fixed-length tuple of numbers would be unboxed and boxed again at every read
_DISARMED_OUTPUTS: Final[tuple[int, ...]] = (PWM_DISARMED,) * SERVO_CHANNELS
_FAILSAFE_OUTPUTS: Final[tuple[int, ...]] = (PWM_FAILSAFE,) * SERVO_CHANNELS
_UNUSED: Final[tuple[int, ...]] = (PWM_DISARMED,) * (SERVO_CHANNELS - ESC_COUNT)
_ZERO4: Final[tuple[int, ...]] = (0, 0, 0, 0)
_NO_CURRENT_A: tuple[float, ...] = (0.0,) * ESC_COUNT  # disarmed motors draw nothing


def servo_outputs(snap: VehicleSnapshot) -> tuple[int, ...]:
    """The 16 actuator_outputs values (PWM us)."""
    if not snap.armed:
        return _DISARMED_OUTPUTS
    if snap.nav_state is NavState.TERMINATION:
        return _FAILSAFE_OUTPUTS
    u0, u1, u2, u3 = snap.motor_commands
    # a concatenation: compiled, a starred element builds the tuple through the iterator protocol
    return (_pwm(u0), _pwm(u1), _pwm(u2), _pwm(u3)) + _UNUSED  # noqa: RUF005


def _pwm(u: float) -> int:
    if not isfinite(u):  # output_limit_calc: an invalid value gets the disarmed output
        return PWM_DISARMED
    return int(PWM_MIN + (PWM_MAX - PWM_MIN) * min(max(u, 0.0), 1.0))


def servo_output_raw(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage:
    return ctx.encoder.servo_output_raw_encode(snap.time_us & 0xFFFFFFFF, 0, *servo_outputs(snap))


def _levels(motors: Vec4) -> Vec4:
    """Each motor's level |u| (0 for a non-finite state)."""
    u0, u1, u2, u3 = motors
    return _level(u0), _level(u1), _level(u2), _level(u3)


def _level(u: float) -> float:
    return abs(u) if isfinite(u) else 0.0


def _per_motor(levels: Vec4, offset: float, slope: float) -> Vec4:
    """offset + slope * u for each motor's level u (the simulated-ESC model's telemetry)."""
    u0, u1, u2, u3 = levels
    return offset + slope * u0, offset + slope * u1, offset + slope * u2, offset + slope * u3


def _truncated(values: Vec4) -> tuple[int, int, int, int]:
    """Each value as C converts a float to an integer field (towards zero)."""
    a, b, c, d = values
    return int(a), int(b), int(c), int(d)


def esc_status(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage:
    u = _levels(snap.motors)
    rpm = _truncated(_per_motor(u, 0.0, 6000.0))
    voltage = _per_motor(u, 11.1, 3.0)
    current = _per_motor(u, 1.0, 15.0) if snap.armed else _NO_CURRENT_A
    return EXTRA.esc_status_encode(0, snap.time_us, rpm, voltage, current)


def esc_info(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage:
    temperature_cdeg = _truncated(_per_motor(_per_motor(_levels(snap.motors), 20.0, 40.0), 0.0, 100.0))
    counter = (snap.time_us // ESC_PUBLISH_PERIOD_US) & 0xFFFF
    return EXTRA.esc_info_encode(0, snap.time_us, counter, ESC_COUNT, ESC_CONNECTION_TYPE_PPM, ESC_ONLINE, _ZERO4,
                                 _ZERO4, temperature_cdeg)
