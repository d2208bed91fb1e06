"""A pilot answering `joyfly joystick calibrate`'s prompts on a virtual SDL device (tests/support/sdl_virtual.py):
each prompt moves the sticks or presses the buttons the way `layout` says, at once, before the wizard reads again.

layout: role ("up", "yaw", "forward", "right") -> (axis, value held, value at rest); buttons: action name ("arm",
"takeoff", ...) -> button; actions left out are skipped with Enter.
"""

from __future__ import annotations

from support.sdl_virtual import VirtualPad

PROMPT_ROLES = {"THROTTLE": "up", "YAW": "yaw", "PITCH": "forward", "ROLL": "right"}


class CalibrationUser:
    def __init__(self, pad: VirtualPad, layout: dict[str, tuple[int, float, float]], buttons: dict[str, int]) -> None:
        self.pad = pad
        self.layout = layout
        self.buttons = buttons
        self.said: list[str] = []
        self._enter = False
        self.rest()

    def rest(self) -> None:
        for axis, _, at_rest in self.layout.values():
            self.pad.axis(axis, at_rest)

    def say(self, text: str) -> None:
        self.said.append(text)
        self._enter = False
        if text.startswith("Centre"):
            self.rest()
            self._enter = True
        elif text.startswith("Move the stick you want for"):
            role = PROMPT_ROLES[text.split()[6]]
            axis, held, _ = self.layout[role]
            self.pad.axis(axis, held)
        elif "let the stick go back" in text:
            self.rest()
        elif text.startswith("Press the button for"):
            action = text.split()[4].lower()
            if action in self.buttons:
                self.pad.button(self.buttons[action], True)
            else:
                self._enter = True
        elif "let it go" in text:
            for button in self.buttons.values():
                self.pad.button(button, False)

    def entered(self) -> bool:
        return self._enter
