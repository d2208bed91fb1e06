"""px4.py holds PX4's and MAVLink's numbering once; these tests hold it to the MAVLink definitions (common.xml, as
pymavlink generates it)."""

from __future__ import annotations

from pymavlink.dialects.v20 import common

from sitl_emu.commander.commands import _HANDLERS
from sitl_emu.mavlink.link_commands import MAVLINK_MODULE_COMMANDS
from sitl_emu.px4 import ABSOLUTE_FRAMES, GLOBAL_FRAMES, RELATIVE_FRAMES, MavCmd, MavFrame, MavResult, Severity


def test_every_mav_cmd_has_the_number_and_name_of_common_xml():
    for cmd in MavCmd:
        assert common.enums["MAV_CMD"][cmd.value].name == f"MAV_CMD_{cmd.name}"


def test_mav_cmd_holds_every_command_the_emulator_answers():
    # commander (Commander.cpp handle_command: DO_ORBIT too), navigator (DO_SET_MISSION_CURRENT), the mavlink module
    answered = {20, 21, 22, 34, 176, 179, 185, 186, 192, 224, 241, 246, 300, 400, 401, 410, 420,
                510, 511, 512, 519, 520}
    assert answered <= {int(c) for c in MavCmd}
    # the handler tables: the commander's, the mavlink module's, and the failure injection manager's one command
    assert {int(c) for c in {*_HANDLERS, *MAVLINK_MODULE_COMMANDS, MavCmd.INJECT_FAILURE}} == answered


def test_every_mav_frame_has_the_number_and_name_of_common_xml():
    for frame in MavFrame:
        assert common.enums["MAV_FRAME"][frame.value].name == f"MAV_FRAME_{frame.name}"
    assert ABSOLUTE_FRAMES.isdisjoint(RELATIVE_FRAMES) and MavFrame.MISSION not in GLOBAL_FRAMES


def test_results_and_severities_match_common_xml():
    known = common.enums["MAV_RESULT"]
    for result in MavResult:
        if result is MavResult.CANCELLED and result.value not in known:
            continue  # MAV_RESULT_CANCELLED (6) is missing from some pymavlink releases' copy of common.xml
        assert known[result.value].name == f"MAV_RESULT_{result.name}"
    for severity in Severity:
        assert common.enums["MAV_SEVERITY"][severity.value].name == f"MAV_SEVERITY_{severity.name}"
