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

import math
from typing import TYPE_CHECKING, Final

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
_DISARMED_OUTPUTS: Final = (PWM_DISARMED,) * SERVO_CHANNELS
_FAILSAFE_OUTPUTS: Final = (PWM_FAILSAFE,) * SERVO_CHANNELS
_UNUSED: Final = (PWM_DISARMED,) * (SERVO_CHANNELS - ESC_COUNT)
_ZERO4: Final = (0, 0, 0, 0)


def servo_outputs(snap: VehicleSnapshot) -> tuple[int, ...]:
    """The 16 actuator_outputs values (PWM us)."""
    if not snap.armed:
        return _DISARMED_OUTPUTS
    if snap.nav_state is NavState.TERMINATION:
        return _FAILSAFE_OUTPUTS
    return (*(_pwm(u) for u in snap.motor_commands), *_UNUSED)


def _pwm(u: float) -> int:
    if not math.isfinite(u):  # output_limit_calc: an invalid value gets the disarmed output
        return PWM_DISARMED
    return int(PWM_MIN + (PWM_MAX - PWM_MIN) * min(max(u, 0.0), 1.0))


def servo_output_raw(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage:
    return ctx.encoder.servo_output_raw_encode(snap.time_us & 0xFFFFFFFF, 0, *servo_outputs(snap))


def _levels(motors: Vec4) -> tuple[float, float, float, float]:
    return tuple(abs(u) if math.isfinite(u) else 0.0 for u in motors)  # type: ignore[return-value]


def esc_status(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage:
    u = _levels(snap.motors)
    rpm = [int(6000.0 * x) for x in u]
    voltage = [11.1 + 3.0 * x for x in u]
    current = [1.0 + 15.0 * x for x in u] if snap.armed else [0.0] * ESC_COUNT
    return EXTRA.esc_status_encode(0, snap.time_us, rpm, voltage, current)


def esc_info(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage:
    temperature_cdeg = [int((20.0 + 40.0 * x) * 100.0) for x in _levels(snap.motors)]
    counter = (snap.time_us // ESC_PUBLISH_PERIOD_US) & 0xFFFF
    return EXTRA.esc_info_encode(0, snap.time_us, counter, ESC_COUNT, ESC_CONNECTION_TYPE_PPM, ESC_ONLINE, _ZERO4,
                                 _ZERO4, temperature_cdeg)
