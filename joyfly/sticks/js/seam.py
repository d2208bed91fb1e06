"""The one platform seam of joyfly's joystick side: the Linux js reader (joyfly/sticks/js/reader.py) needs `fcntl`
for the joystick ioctls, which Windows has not. Everything else that reads joysticks (SDL, `script:`, `replay:` and
recordings) is portable, so joyfly imports the js reader only through here: where it cannot be imported, SDL and the
virtual joysticks still work and a js path ends in one sentence.
"""

from __future__ import annotations

import importlib
from types import ModuleType

from joyfly.sticks.js.events import JoystickError
from joyfly.sticks.virtual import ReplaySource, ScriptSource, is_recording
from joyfly.types import Clock, JoystickSource

JS_MODULE = "joyfly.sticks.js.reader"


class JsUnavailable(JoystickError):
    """This system has no Linux js API."""


def js_reader(module: str = JS_MODULE) -> ModuleType:
    """The js reader module; JsUnavailable (one sentence) where it cannot be imported."""
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        raise JsUnavailable(f"This system has no Linux joystick (js) API ({exc.name or exc} is missing): use an SDL "
                            "controller (--joy sdl, see `joyfly joystick list`) or --joy script:FILE.") from None


def js_reader_or_none(module: str = JS_MODULE) -> ModuleType | None:
    try:
        return js_reader(module)
    except JsUnavailable:
        return None


def open_js(spec: str, clock: Clock, dev_dir: str, module: str = JS_MODULE) -> JoystickSource:
    """What the js reader opens (joystick.open_joystick); without it, the portable kinds (script:, replay:, a
    recording) still open and anything else is refused in one sentence."""
    try:
        reader = js_reader(module)
    except JsUnavailable:
        if spec.startswith("script:") and spec[len("script:"):]:
            return ScriptSource.from_file(spec[len("script:"):], clock)
        if spec.startswith("replay:") and spec[len("replay:"):]:
            return ReplaySource.from_file(spec[len("replay:"):], clock)
        if is_recording(spec):
            return ReplaySource.from_file(spec, clock)
        raise
    source: JoystickSource = reader.open_joystick(spec, clock, dev_dir=dev_dir)
    return source
