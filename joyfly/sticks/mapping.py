"""Raw js axes and buttons -> StickCommand: deadzone with rescale, expo, invert, scale; button hold timing.

Everything here is pure and deterministic: the time comes from JoyState.time_s, hold timers from the previous
StickCommand. `StickMapper` is the small stateful convenience that keeps the previous command for you, and
`open_sticks()` / `MappedSource` give the flight side a source of StickCommands in one call.

Per axis (AxisMap): x = raw / 32767, negated when `invert`; then the deadzone, rescaled so the output still reaches
+-1 (|x| <= dz -> 0, else sign(x) * (|x| - dz) / (1 - dz), as ROS joy does); then expo, x' = (1 - e) x + e x^3
(same end points, softer centre); then times `scale`, clamped to -1..1. A non-centring throttle (throttle_abs)
maps -32767..32767 to 0..1 (after invert), with the deadzone at the bottom end.

When the source is disconnected, or a deadman button is configured and released, the sticks read neutral
(0, and up 0.0 when the profile has an up axis) and no action is pressed.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from joyfly.sticks.js.events import AXIS_MAX, JoystickError
from joyfly.sticks.profiles.profile import AxisMap, Profile, rest_problems
from joyfly.sticks.sdl.mappings import SdlMappings
from joyfly.sticks.sources import check_profile_choice, open_source, pick_profile
from joyfly.sticks.virtual import record_to
from joyfly.types import Action, Clock, JoyState, JoystickSource, StickCommand
from px4common.clock import WallClock

HOLD_EPS_S = 1e-6  # held times are float sums of poll intervals: 10 x 0.1 s must count as 1 s


def normalise(raw: int) -> float:
    return max(-1.0, min(1.0, raw / AXIS_MAX))


def apply_deadzone(x: float, deadzone: float) -> float:
    """Zero inside +-deadzone, rescaled outside so that +-1 still maps to +-1."""
    if deadzone <= 0.0:
        return x
    if abs(x) <= deadzone:
        return 0.0
    return (abs(x) - deadzone) / (1.0 - deadzone) * (1.0 if x > 0 else -1.0)


def apply_expo(x: float, expo: float) -> float:
    """Blend of linear and cubic: same sign and end points, finer control near the centre."""
    return (1.0 - expo) * x + expo * x * x * x


def shape_axis(raw: int, axis: AxisMap) -> float:
    x = normalise(raw)
    if axis.invert:
        x = -x
    x = apply_expo(apply_deadzone(x, axis.deadzone), axis.expo) * axis.scale
    return max(-1.0, min(1.0, x))


def shape_throttle(raw: int, axis: AxisMap) -> float:
    x = normalise(raw)
    if axis.invert:
        x = -x
    level = (x + 1.0) / 2.0
    if axis.deadzone > 0.0:
        level = 0.0 if level <= axis.deadzone else (level - axis.deadzone) / (1.0 - axis.deadzone)
    return max(0.0, min(1.0, level * axis.scale))


def _raw(values: tuple[int, ...], index: int) -> int | None:
    return values[index] if 0 <= index < len(values) else None


def _stick(profile: Profile, state: JoyState, role: str) -> float | None:
    """The shaped value of a centred role; None when unmapped, 0.0 when the device lacks that axis."""
    axis = profile.axis(role)
    if axis is None:
        return None
    raw = _raw(state.axes, axis.index)
    return 0.0 if raw is None else shape_axis(raw, axis)


def _throttle_abs(profile: Profile, state: JoyState) -> float | None:
    axis = profile.axis("throttle_abs")
    raw = None if axis is None else _raw(state.axes, axis.index)
    return None if axis is None or raw is None else shape_throttle(raw, axis)


def pressed_actions(profile: Profile, state: JoyState) -> frozenset[Action]:
    return frozenset(a for a, idx in profile.buttons.items() if _raw(state.buttons, idx) == 1)


def _held(pressed: frozenset[Action], state: JoyState, prev: StickCommand | None) -> tuple[tuple[Action, float], ...]:
    before = dict(prev.held_s) if prev is not None else {}
    dt = max(0.0, state.time_s - prev.time_s) if prev is not None else 0.0
    return tuple(
        (a, before[a] + dt if prev is not None and a in prev.pressed and a in before else 0.0)
        for a in sorted(pressed, key=lambda a: a.value)
    )


def neutral(profile: Profile, state: JoyState) -> StickCommand:
    up = None if profile.axis("up") is None else 0.0
    return StickCommand(up=up, connected=state.connected, time_s=state.time_s,
                        deadman_ok=None if Action.DEADMAN not in profile.buttons else False)


def map_state(profile: Profile, state: JoyState, prev: StickCommand | None = None) -> StickCommand:
    """One raw JoyState -> StickCommand in the flying convention (see the module docstring)."""
    if not state.connected:
        return neutral(profile, state)
    pressed = pressed_actions(profile, state)
    deadman_ok = None if Action.DEADMAN not in profile.buttons else Action.DEADMAN in pressed
    held = _held(pressed, state, prev)
    if deadman_ok is False:
        cmd = neutral(profile, state)
        return StickCommand(up=cmd.up, throttle_abs=_throttle_abs(profile, state), pressed=pressed, held_s=held,
                            deadman_ok=False, time_s=state.time_s)
    return StickCommand(
        forward=_stick(profile, state, "forward") or 0.0,
        right=_stick(profile, state, "right") or 0.0,
        up=_stick(profile, state, "up"),
        yaw=_stick(profile, state, "yaw") or 0.0,
        throttle_abs=_throttle_abs(profile, state),
        pressed=pressed,
        held_s=held,
        deadman_ok=deadman_ok,
        connected=True,
        time_s=state.time_s,
    )


def held_for(cmd: StickCommand, action: Action) -> float | None:
    """Seconds the action's button has been held, or None when it is not pressed."""
    return dict(cmd.held_s).get(action)


def _hold_reached(prev: StickCommand, cur: StickCommand, action: Action, hold_s: float) -> bool:
    """True on the one step where the action's hold time reaches hold_s (hold_s <= 0: on the press edge)."""
    if action not in prev.pressed:
        return hold_s <= 0.0 or (held_for(cur, action) or 0.0) >= hold_s - HOLD_EPS_S
    before_s = held_for(prev, action) or 0.0
    return before_s < hold_s - HOLD_EPS_S <= (held_for(cur, action) or 0.0)


def fired(prev: StickCommand | None, cur: StickCommand, arm_hold_s: float = 1.0) -> frozenset[Action]:
    """Actions to perform now: ARM once when its hold reaches arm_hold_s; the others on the press edge.

    DEADMAN never fires (read cur.deadman_ok). With prev None (the first state) nothing fires, so a button already
    down when the program starts does nothing at once (ARM still counts its hold from there).
    """
    if prev is None:
        return frozenset()
    out: set[Action] = set()
    for action in cur.pressed:
        if action is Action.ARM:
            if _hold_reached(prev, cur, action, arm_hold_s):
                out.add(action)
        elif action is not Action.DEADMAN and action not in prev.pressed:
            out.add(action)
    return frozenset(out)


class StickMapper:
    """Keeps the previous command so you can feed states one by one: `cmd, actions = mapper.update(state)`."""

    def __init__(self, profile: Profile) -> None:
        self.profile = profile
        self.prev: StickCommand | None = None

    def update(self, state: JoyState) -> tuple[StickCommand, frozenset[Action]]:
        cmd = map_state(self.profile, state, self.prev)
        actions = fired(self.prev, cmd, self.profile.arm_hold_s)
        self.prev = cmd
        return cmd, actions


class MappedSource:
    """A joystick source seen through a profile: poll() returns StickCommands (the flight side's stick source).

    `last_state` is the raw JoyState behind the last command and `last_actions` the actions that fired on it
    (ARM after its hold, the others on their press edge), for callers that do not track edges themselves.
    """

    def __init__(self, source: JoystickSource, profile: Profile) -> None:
        self.source = source
        self.profile = profile
        self.name = source.name
        self.path = source.path
        self._mapper = StickMapper(profile)
        self.last_state: JoyState | None = None
        self.last_actions: frozenset[Action] = frozenset()
        self.why = ""  # which device --joy auto / sdl chose, and why

    def poll(self, timeout_s: float) -> StickCommand:
        state = self.source.poll(timeout_s)
        cmd, self.last_actions = self._mapper.update(state)
        self.last_state = state
        return cmd

    def rest_problems(self) -> list[str]:
        """Stick roles off centre in the last state (see profiles.rest_problems); [] before any data."""
        state = self.last_state
        return [] if state is None or not state.axes else rest_problems(self.profile, state)

    def gone(self) -> str | None:
        """Why the joystick gives no sticks any more, for good (a stream of something other than js_events, a raw
        capture that ended: their `gone`), or None."""
        inner: Any = self.source
        while hasattr(inner, "source"):  # through a --record RecordingSource
            inner = inner.source
        why = getattr(inner, "gone", None)
        return why if isinstance(why, str) else None

    def close(self) -> None:
        self.source.close()


def open_sticks(spec: str, clock: Clock | None = None, profile: str = "auto",
                overrides: Mapping[str, Any] | None = None, record: str | None = None,
                dev_dir: str = "/dev/input", mappings: SdlMappings | None = None) -> MappedSource:
    """One call for `joyfly fly`: open `--joy` (auto, sdl[:N|:NAME], path, raw:, script:, replay:; see
    joyfly/sticks/sources.py), pick the profile (`--profile`, the config's `[profile]` table), optionally `--record`,
    and map. `why` on the result says which device `auto`/`sdl` chose. Raises JoystickError (one sentence)."""
    check_profile_choice(profile, overrides)
    opened = open_source(spec, clock or WallClock(), dev_dir=dev_dir, mappings=mappings)
    source = opened.source
    try:
        chosen = pick_profile(source, profile, overrides)
        source = record_to(source, record) if record else source
    except JoystickError:
        source.close()
        raise
    mapped = MappedSource(source, chosen)
    mapped.why = opened.why
    return mapped
