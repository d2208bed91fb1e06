"""Stick mapping: deadzone with rescale, expo, invert, scale; every built-in profile flies the same way; hold timing."""

from __future__ import annotations

from dataclasses import dataclass

import pytest

from joyfly.sticks.js.reader import JoystickError
from joyfly.sticks.mapping import StickMapper, apply_deadzone, apply_expo, fired, map_state, open_sticks, shape_axis
from joyfly.sticks.profiles.profile import AxisMap, get_profile, load_profile
from joyfly.types import Action, JoyState, StickCommand

FULL = 32767


def test_deadzone_zeroes_small_values_and_still_reaches_full_scale():
    assert apply_deadzone(0.05, 0.1) == 0.0
    assert apply_deadzone(-0.1, 0.1) == 0.0
    assert apply_deadzone(1.0, 0.1) == pytest.approx(1.0)
    assert apply_deadzone(-1.0, 0.1) == pytest.approx(-1.0)
    assert apply_deadzone(0.55, 0.1) == pytest.approx(0.5)  # rescaled, no jump at the edge
    assert apply_deadzone(0.1001, 0.1) == pytest.approx(0.0, abs=1e-3)


def test_expo_keeps_end_points_and_softens_the_centre():
    assert apply_expo(1.0, 0.5) == pytest.approx(1.0)
    assert apply_expo(-1.0, 0.5) == pytest.approx(-1.0)
    assert 0.0 < apply_expo(0.3, 0.5) < 0.3
    assert apply_expo(0.3, 0.0) == pytest.approx(0.3)


def test_invert_and_scale():
    axis = AxisMap(0, invert=True, deadzone=0.0, scale=0.5)
    assert shape_axis(-FULL, axis) == pytest.approx(0.5)
    assert shape_axis(FULL, axis) == pytest.approx(-0.5)
    assert shape_axis(-32768, AxisMap(0, deadzone=0.0)) == -1.0  # clamped


@dataclass(frozen=True)
class Pad:
    """A controller's hardware layout as reference/joystick.md 1C-2 describes it (not read from profile.py)."""

    name: str  # the js name the kernel reports
    lx: int
    ly: int
    rx: int
    ry: int
    triggers: tuple[int, ...]  # axes that rest at -32767
    n_axes: int
    start: int  # Start / Options / Menu
    top: int  # Y / Triangle
    bottom: int  # A / Cross
    right_face: int  # B / Circle
    left_face: int  # X / Square
    back: int  # Back / Share / View
    n_buttons: int

    def rest(self) -> list[int]:
        axes = [0] * self.n_axes
        for t in self.triggers:
            axes[t] = -FULL
        return axes


XPAD = dict(lx=0, ly=1, rx=3, ry=4, triggers=(2, 5), n_axes=8, start=7, top=3, bottom=0, right_face=1, left_face=2,
            back=6, n_buttons=11)
PS = dict(lx=0, ly=1, rx=3, ry=4, triggers=(2, 5), n_axes=8, start=9, top=2, bottom=0, right_face=1, left_face=3,
          back=8, n_buttons=13)
PADS = [
    Pad("Microsoft X-Box 360 pad", **XPAD),
    Pad("Microsoft X-Box One S pad", **XPAD),
    Pad("Logitech Gamepad F310", **XPAD),
    Pad("Logitech Gamepad F710", **XPAD),
    Pad("Sony Interactive Entertainment Wireless Controller", **PS),
    Pad("DualSense Wireless Controller", **PS),
    Pad("Logitech Dual Action", lx=0, ly=1, rx=2, ry=3, triggers=(), n_axes=6, start=9, top=3, bottom=1,
        right_face=2, left_face=0, back=8, n_buttons=12),
    Pad("Logitech Cordless RumblePad 2", lx=0, ly=1, rx=2, ry=3, triggers=(), n_axes=6, start=9, top=3, bottom=1,
        right_face=2, left_face=0, back=8, n_buttons=12),
]
OLD_DS4 = Pad("Sony Computer Entertainment Wireless Controller", lx=0, ly=1, rx=2, ry=5, triggers=(3, 4), n_axes=8,
              start=9, top=3, bottom=1, right_face=2, left_face=0, back=8, n_buttons=13)

# (gesture, axis role in the pad, raw value, expected StickCommand field, expected value)
GESTURES = [
    ("right stick forward", "ry", -FULL, "forward", 1.0),
    ("right stick back", "ry", FULL, "forward", -1.0),
    ("right stick right", "rx", FULL, "right", 1.0),
    ("right stick left", "rx", -FULL, "right", -1.0),
    ("left stick up", "ly", -FULL, "up", 1.0),
    ("left stick down", "ly", FULL, "up", -1.0),
    ("left stick right", "lx", FULL, "yaw", 1.0),
    ("left stick left", "lx", -FULL, "yaw", -1.0),
]
BUTTONS = [("start", Action.ARM), ("top", Action.TAKEOFF), ("bottom", Action.LAND), ("right_face", Action.RETURN),
           ("left_face", Action.HOLD), ("back", Action.OFFBOARD)]


def profile_for(pad: Pad, kernel: str = "6.8.0"):
    return load_profile("auto", pad.name, {}, kernel_release=kernel)


def stick_values(cmd: StickCommand) -> dict[str, float | None]:
    return {"forward": cmd.forward, "right": cmd.right, "up": cmd.up, "yaw": cmd.yaw}


@pytest.mark.parametrize(("pad", "kernel"), [(p, "6.8.0") for p in PADS] + [(OLD_DS4, "4.4.0")], ids=lambda x: str(x))
def test_every_gamepad_profile_flies_the_same_way(pad, kernel):
    profile = profile_for(pad, kernel)
    at_rest = map_state(profile, JoyState(0.0, tuple(pad.rest()), (0,) * pad.n_buttons))
    assert stick_values(at_rest) == {"forward": 0.0, "right": 0.0, "up": 0.0, "yaw": 0.0}  # triggers never fly
    assert at_rest.throttle_abs is None and at_rest.pressed == frozenset()
    for gesture, where, raw, field, expected in GESTURES:
        axes = pad.rest()
        axes[getattr(pad, where)] = raw
        cmd = map_state(profile, JoyState(0.0, tuple(axes), (0,) * pad.n_buttons))
        want = {"forward": 0.0, "right": 0.0, "up": 0.0, "yaw": 0.0, field: expected}
        assert stick_values(cmd) == pytest.approx(want), f"{profile.name}: {gesture}"
    for where, action in BUTTONS:
        buttons = [0] * pad.n_buttons
        buttons[getattr(pad, where)] = 1
        cmd = map_state(profile, JoyState(0.0, tuple(pad.rest()), tuple(buttons)))
        assert cmd.pressed == {action}, f"{profile.name}: {where}"


def test_old_hid_sony_layout_is_only_picked_on_old_kernels():
    assert profile_for(OLD_DS4, "4.4.0").name == "dualshock-old"
    assert profile_for(OLD_DS4, "5.15.0").name == "dualshock"


def test_radio_profile_mode2_aetr_with_absolute_throttle():
    profile = load_profile("auto", "EdgeTX RadioMaster TX16S Joystick", {})
    assert profile.name == "radio"
    rest = [0, 0, -FULL, 0, 0, 0, 0, 0]  # throttle stick down, the others centred
    cmd = map_state(profile, JoyState(0.0, tuple(rest), (0,) * 24))
    assert (cmd.forward, cmd.right, cmd.yaw, cmd.up, cmd.throttle_abs) == (0.0, 0.0, 0.0, None, 0.0)
    for index, raw, field, expected in [(0, FULL, "right", 1.0), (1, FULL, "forward", 1.0), (3, FULL, "yaw", 1.0),
                                        (2, FULL, "throttle_abs", 1.0), (2, 0, "throttle_abs", 0.5)]:
        axes = list(rest)
        axes[index] = raw
        assert getattr(map_state(profile, JoyState(0.0, tuple(axes), ())), field) == pytest.approx(expected)


def test_generic_profile_uses_axes_0_and_1():
    profile = load_profile("auto", "Some Unknown Stick 3000", {})
    assert profile.name == "generic"
    cmd = map_state(profile, JoyState(0.0, (FULL, -FULL), ()))
    assert (cmd.forward, cmd.right, cmd.up, cmd.yaw) == (1.0, 1.0, None, 0.0)


def test_missing_axes_and_buttons_read_neutral_instead_of_crashing():
    profile = get_profile("xbox")
    cmd = map_state(profile, JoyState(0.0, (0, 0), ()))  # before the INIT events arrived
    assert stick_values(cmd) == {"forward": 0.0, "right": 0.0, "up": 0.0, "yaw": 0.0}


def test_disconnected_source_reads_neutral_with_nothing_pressed():
    profile = get_profile("xbox")
    axes = [0] * 8
    axes[4] = -FULL
    cmd = map_state(profile, JoyState(0.0, tuple(axes), (1,) * 11, connected=False))
    assert cmd.connected is False and cmd.forward == 0.0 and cmd.pressed == frozenset()


def test_arm_fires_once_after_a_one_second_hold_and_other_buttons_on_press():
    mapper = StickMapper(get_profile("xbox"))
    rest = (0,) * 8
    start, y_button = [0] * 11, [0] * 11
    start[7] = 1
    y_button[3] = 1
    seen = []
    for i in range(30):  # 0.0 .. 2.9 s holding Start
        cmd, actions = mapper.update(JoyState(i * 0.1, rest, tuple(start)))
        seen.append((round(i * 0.1, 1), actions))
    assert [t for t, a in seen if a] == [1.0]
    assert dict(cmd.held_s)[Action.ARM] == pytest.approx(2.9)
    _, actions = mapper.update(JoyState(3.0, rest, (0,) * 11))
    assert actions == frozenset()
    _, actions = mapper.update(JoyState(3.1, rest, tuple(y_button)))
    assert actions == {Action.TAKEOFF}
    _, actions = mapper.update(JoyState(3.2, rest, tuple(y_button)))
    assert actions == frozenset()  # held: not repeated


def test_short_arm_press_does_not_arm():
    mapper = StickMapper(get_profile("xbox"))
    start = [0] * 11
    start[7] = 1
    for i in range(9):
        _, actions = mapper.update(JoyState(i * 0.1, (0,) * 8, tuple(start)))
        assert actions == frozenset()
    _, actions = mapper.update(JoyState(0.9, (0,) * 8, (0,) * 11))
    assert actions == frozenset()


def test_button_down_at_start_does_not_fire_until_pressed_again():
    prev = None
    profile = get_profile("xbox")
    land = [0] * 11
    land[0] = 1
    cmd = map_state(profile, JoyState(0.0, (0,) * 8, tuple(land)), prev)
    assert fired(prev, cmd) == frozenset()


def test_deadman_released_neutralises_the_sticks():
    profile = load_profile("xbox", "", {"buttons": {"deadman": 4}})
    axes = [0] * 8
    axes[4] = -FULL
    released = map_state(profile, JoyState(0.0, tuple(axes), (0,) * 11))
    assert released.deadman_ok is False and released.forward == 0.0
    lb = [0] * 11
    lb[4] = 1
    held = map_state(profile, JoyState(0.0, tuple(axes), tuple(lb)))
    assert held.deadman_ok is True and held.forward == 1.0
    assert map_state(get_profile("xbox"), JoyState(0.0, tuple(axes), (0,) * 11)).deadman_ok is None


class _Clock:
    def __init__(self) -> None:
        self.t_s = 0.0

    def now(self) -> float:
        return self.t_s

    def sleep(self, seconds: float) -> None:
        self.t_s += max(0.0, seconds)


def test_open_sticks_gives_stick_commands_with_fired_actions(tmp_path):
    script = tmp_path / "s.txt"
    script.write_text("0 forward=1 arm=1\n1.2 arm=0\n2 end\n")
    clock = _Clock()
    sticks = open_sticks(f"script:{script}", clock, overrides={"forward": {"scale": 0.5}}, record=str(tmp_path / "r"))
    assert sticks.profile.name == "script+config" and sticks.name == "joyfly script"
    fired_at = []
    for _ in range(25):
        cmd = sticks.poll(0.0)
        if sticks.last_actions:
            fired_at.append((round(clock.now(), 1), set(sticks.last_actions)))
        clock.sleep(0.1)
    assert cmd.connected is False
    assert fired_at == [(1.0, {Action.ARM})]
    sticks.close()
    assert (tmp_path / "r").read_text().count("\n") >= 4  # header, states, end


def test_open_sticks_bad_profile_is_one_sentence(tmp_path):
    script = tmp_path / "s.txt"
    script.write_text("0 end\n")
    with pytest.raises(JoystickError) as info:
        open_sticks(f"script:{script}", _Clock(), profile="nope")
    assert str(info.value).startswith("Unknown profile 'nope'")
