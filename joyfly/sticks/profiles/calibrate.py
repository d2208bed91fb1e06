"""`joyfly joystick calibrate`: a wizard that learns a joystick's layout from the pilot's hands, as
QGroundControl's joystick calibration does, for any source (SDL game controllers and joysticks, js devices).

  1. centre: hands off, sticks centred (a radio's throttle down): each axis's rest value and noise give its deadzone;
  2. the axes, in QGroundControl's order: "move the stick you want for throttle up", then yaw right, forward
     (pitch), right (roll): the axis that moves furthest from rest is that role's, its direction says whether it is
     reversed, and a throttle that rested at one end of its travel is a radio's (non-centring) throttle;
  3. the buttons for arm, take-off, land, return, hold and OFFBOARD (press one, or Enter to leave it unbound).

The result is a Profile (joyfly/sticks/profiles/profile.py) that `user.profile_toml` writes. The wizard talks
through a `Console` (say a prompt; has Enter been pressed?), so a test drives it with a virtual joystick.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

from joyfly.sticks.js.events import AXIS_MAX, JoystickError
from joyfly.sticks.profiles.profile import AxisMap, Profile
from joyfly.types import Action, JoyState, JoystickSource

CENTRE_S = 1.0  # hands off for this long: rest values and noise
HOLD_S = 0.3  # a role's axis is taken once it has stayed past MOVED for this long
MOVED = 0.5  # fraction of full travel away from rest that counts as "moved"
RELEASED = 0.2
STEP_TIMEOUT_S = 60.0
POLL_S = 0.02
FULL_REACH = 0.9  # a held stick short of this fraction of full travel is reported
RADIO_REST = 0.8  # a throttle resting beyond this fraction of travel is a radio's, non-centring
MIN_DEADZONE, MAX_DEADZONE = 0.05, 0.3
# (role, what to do), QGroundControl's order
AXIS_STEPS = (
    ("up", "Move the stick you want for THROTTLE (climb) fully up, and hold it"),
    ("yaw", "Move the stick you want for YAW fully right (turn clockwise), and hold it"),
    ("forward", "Move the stick you want for PITCH fully forward (fly forward), and hold it"),
    ("right", "Move the stick you want for ROLL fully right (fly right), and hold it"),
)
BUTTON_STEPS = (Action.ARM, Action.TAKEOFF, Action.LAND, Action.RETURN, Action.HOLD, Action.OFFBOARD)


class Console(Protocol):
    def say(self, text: str) -> None: ...

    def entered(self) -> bool:
        """True once the user pressed Enter since the last prompt (never blocks)."""
        ...


class CalibrationError(JoystickError):
    """The wizard could not finish (no stick moved, the joystick went away)."""


@dataclass(frozen=True, slots=True)
class Rest:
    values: tuple[int, ...]
    noise: tuple[int, ...]


class Wizard:
    def __init__(self, source: JoystickSource, console: Console) -> None:
        self.source = source
        self.console = console
        self.state = source.poll(0.0)

    def run(self, arm_hold_s: float = 1.0) -> Profile:
        rest = self.centre()
        axes: dict[str, AxisMap] = {}
        for role, prompt in AXIS_STEPS:
            index, pushed = self.axis_step(prompt, rest, {a.index for a in axes.values()})
            axes.update(self.axis_map(role, index, pushed, rest))
        buttons: dict[Action, int] = {}
        for action in BUTTON_STEPS:
            button = self.button_step(action, set(buttons.values()))
            if button is not None:
                buttons[action] = button
        return Profile("calibrated", f"calibrated for \"{self.source.name}\"", (), axes, buttons, arm_hold_s)

    # -- steps ------------------------------------------------------------------------------------------------------

    def centre(self) -> Rest:
        self.console.say("Centre the sticks (a radio's throttle all the way down), hands off, then press Enter.")
        self._until(self.console.entered, "Enter pressed")
        samples: list[tuple[int, ...]] = []
        start = self.state.time_s
        while self.state.time_s - start < CENTRE_S or not samples:
            samples.append(self._poll().axes)
        count = min(len(s) for s in samples)
        if count == 0:
            raise CalibrationError(f"{self.source.name} reports no axes: move every stick once, then calibrate again.")
        mean = tuple(round(sum(s[i] for s in samples) / len(samples)) for i in range(count))
        noise = tuple(max(abs(s[i] - mean[i]) for s in samples) for i in range(count))
        return Rest(mean, noise)

    def axis_step(self, prompt: str, rest: Rest, taken: set[int]) -> tuple[int, int]:
        """The axis the user moves and holds (not one already taken) and the raw value it was held at."""
        self.console.say(prompt + ".")
        start = self.state.time_s
        held: tuple[int, float] | None = None  # (axis, since)
        while True:
            state = self._poll()
            index = self._moved(rest, taken)
            if index is None:
                held = None
            elif held is None or held[0] != index:
                held = (index, state.time_s)
            elif state.time_s - held[1] >= HOLD_S:
                pushed = state.axes[index]
                reach = abs(pushed) / AXIS_MAX
                short = "" if reach >= FULL_REACH else (f" (it reached only {100 * reach:.0f}% of its travel: full "
                                                         "stick will not give full speed)")
                self.console.say(f"Axis {index}: got it{short}; let the stick go back.")
                self._until(lambda: self._all_released(rest), "release of the sticks")
                return index, pushed
            self._check_time(start, "stick moved")

    def axis_map(self, role: str, index: int, pushed: int, rest: Rest) -> dict[str, AxisMap]:
        at_rest = rest.values[index]
        if role == "up" and abs(at_rest) > RADIO_REST * AXIS_MAX:
            return {"throttle_abs": AxisMap(index, invert=pushed < at_rest, deadzone=0.02)}
        deadzone = (abs(at_rest) + rest.noise[index]) / AXIS_MAX + 0.02
        return {role: AxisMap(index, invert=pushed < at_rest, deadzone=round(min(MAX_DEADZONE,
                                                                                  max(MIN_DEADZONE, deadzone)), 3))}

    def button_step(self, action: Action, taken: set[int]) -> int | None:
        """The button the user presses for `action` (not one already taken), or None when they press Enter."""
        self.console.say(f"Press the button for {action.value.upper()} (or Enter to leave it unbound).")
        start, before = self.state.time_s, self.state.buttons
        while not self.console.entered():
            state = self._poll()
            pressed = [i for i, v in enumerate(state.buttons)
                       if v and (i >= len(before) or not before[i]) and i not in taken]
            if pressed:
                self.console.say(f"Button {pressed[0]}: {action.value}; let it go.")
                self._until(lambda: not any(self.state.buttons), "release of the buttons")
                return pressed[0]
            before = state.buttons
            self._check_time(start, "button pressed")
        return None

    # -- helpers ----------------------------------------------------------------------------------------------------

    def _moved(self, rest: Rest, taken: set[int]) -> int | None:
        axes = self.state.axes
        best, best_dev = None, MOVED * AXIS_MAX
        for i in range(min(len(axes), len(rest.values))):
            dev = abs(axes[i] - rest.values[i])
            if i not in taken and dev > best_dev:
                best, best_dev = i, dev
        return best

    def _all_released(self, rest: Rest) -> bool:
        axes = self.state.axes
        return all(abs(axes[i] - rest.values[i]) < RELEASED * AXIS_MAX for i in range(min(len(axes), len(rest.values))))

    def _poll(self) -> JoyState:
        self.state = self.source.poll(POLL_S)
        if not self.state.connected:
            raise CalibrationError(f"{self.source.name} went away during the calibration: plug it in and calibrate "
                                   "again (nothing was written).")
        return self.state

    def _check_time(self, start_s: float, what: str) -> None:
        if self.state.time_s - start_s > STEP_TIMEOUT_S:
            raise CalibrationError(f"No {what} in {STEP_TIMEOUT_S:g} s: calibrate again when ready (nothing was "
                                   "written).")

    def _until(self, done: Callable[[], bool], what: str) -> JoyState:
        start = self.state.time_s
        while not done():
            self._poll()
            self._check_time(start, what)
        return self.state
