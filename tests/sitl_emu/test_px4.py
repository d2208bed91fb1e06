"""px4.py holds PX4's and MAVLink's numbering once; these tests hold it to the MAVLink definitions (common.xml, as
pymavlink generates it)."""

from __future__ import annotations

from pymavlink.dialects.v20 import common

from sitl_emu.px4 import MavCmd, MavResult, Severity


def test_every_mav_cmd_has_the_number_and_name_of_common_xml():
    for cmd in MavCmd:
        assert common.enums["MAV_CMD"][cmd.value].name == f"MAV_CMD_{cmd.name}"


def test_mav_cmd_holds_the_commands_the_emulator_answers():
    # commander (Commander.cpp handle_command) and the mavlink module (mavlink_receiver.cpp)
    assert {int(c) for c in MavCmd} == {20, 21, 22, 34, 176, 179, 185, 186, 192, 241, 246, 300, 400, 401, 410, 510, 511,
                                        512, 519, 520}


def test_results_and_severities_match_common_xml():
    known = common.enums["MAV_RESULT"]
    for result in MavResult:
        if result is MavResult.CANCELLED and result.value not in known:
            continue  # MAV_RESULT_CANCELLED (6) is missing from some pymavlink releases' copy of common.xml
        assert known[result.value].name == f"MAV_RESULT_{result.name}"
    for severity in Severity:
        assert common.enums["MAV_SEVERITY"][severity.value].name == f"MAV_SEVERITY_{severity.name}"
