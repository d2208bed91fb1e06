"""The pxh> shell: the commands it sends to the vehicle (reference 5.1) and PX4's output formats."""

from __future__ import annotations

import math

import pytest
from support.handler_ctx import FakeVehicle, make_snapshot

from sitl_emu.console.shell import Shell
from sitl_emu.px4 import SHELL_MODE_NAMES, MavResult, NavState, main_sub


@pytest.fixture()
def vehicle() -> FakeVehicle:
    return FakeVehicle()


def _only_command(vehicle: FakeVehicle):
    (cmd,) = vehicle.commands
    assert cmd.from_external is False
    assert (cmd.source_system, cmd.source_component) == (1, 1)
    return cmd


def test_arm_sends_internal_unforced_arm(vehicle):
    assert Shell(vehicle).execute("commander arm") == ""
    cmd = _only_command(vehicle)
    assert cmd.command == 400 and cmd.param(1) == 1.0 and cmd.param(2) != 21196


def test_arm_force_sends_21196(vehicle):
    Shell(vehicle).execute("commander arm -f")
    cmd = _only_command(vehicle)
    assert cmd.param(1) == 1.0 and cmd.param(2) == 21196


@pytest.mark.parametrize(("line", "param2"), [("commander disarm", 0.0), ("commander disarm -f", 21196.0)])
def test_disarm(vehicle, line, param2):
    Shell(vehicle).execute(line)
    cmd = _only_command(vehicle)
    assert cmd.command == 400 and cmd.param(1) == 0.0 and cmd.param(2) == param2


def test_takeoff_sends_nan_takeoff_then_arms(vehicle):
    Shell(vehicle).execute("commander takeoff")
    takeoff, arm = vehicle.commands
    assert takeoff.command == 22 and all(math.isnan(p) for p in takeoff.params)
    assert arm.command == 400 and arm.param(1) == 1.0 and arm.param(2) != 21196
    assert not arm.from_external


def test_takeoff_rejected_does_not_arm(vehicle):
    vehicle.results[22] = MavResult.TEMPORARILY_REJECTED
    Shell(vehicle).execute("commander takeoff")
    assert [c.command for c in vehicle.commands] == [22]


def test_land(vehicle):
    Shell(vehicle).execute("commander land")
    assert _only_command(vehicle).command == 21


@pytest.mark.parametrize("name", sorted(SHELL_MODE_NAMES))
def test_mode_sends_custom_do_set_mode(vehicle, name):
    Shell(vehicle).execute(f"commander mode {name}")
    cmd = _only_command(vehicle)
    main, sub = main_sub(SHELL_MODE_NAMES[name])
    assert cmd.command == 176
    assert (cmd.param(1), cmd.param(2), cmd.param(3)) == (1.0, main, sub)


def test_unknown_mode_is_an_error_and_sends_nothing(vehicle):
    out = Shell(vehicle).execute("commander mode warp")
    assert out == "ERROR [commander] argument warp unsupported.\n"
    assert vehicle.commands == []


def test_status_prints_px4_lines(vehicle):
    vehicle.snap = make_snapshot(armed=True, nav_state=NavState.AUTO_RTL, user_intended_nav_state=NavState.OFFBOARD,
                                 failsafe=True)
    out = Shell(vehicle).execute("commander status")
    assert out.splitlines() == [
        "INFO  [commander] Armed",
        "INFO  [commander] prearm safety: Off",
        "INFO  [commander] navigation mode: Return",
        "INFO  [commander] user intended navigation mode: Offboard",
        "INFO  [commander] in failsafe: yes",
    ]


@pytest.mark.parametrize(("ok", "word"), [(True, "OK"), (False, "FAILED")])
def test_check(vehicle, ok, word):
    vehicle.snap = make_snapshot(pre_flight_checks_pass=ok)
    out = Shell(vehicle).execute("commander check")
    assert out == f"INFO  [commander] Preflight check: {word}\n"
    assert _only_command(vehicle).command == 401


def test_unknown_commander_subcommand_fails_with_usage(vehicle):
    out = Shell(vehicle).execute("commander fly")
    assert "Usage: commander" in out and out.endswith("Command 'commander' failed, returned 1.\n")


def test_param_show_format_and_pattern(vehicle):
    out = Shell(vehicle).execute("param show bat_*")
    lines = out.splitlines()
    assert lines[0] == "Symbols: x = used, + = saved, * = unsaved"
    assert f"x   BAT_LOW_THR [{_table_index(vehicle, 'BAT_LOW_THR')},{vehicle.params.index_of('BAT_LOW_THR')}] : " \
           "0.1500 norm" in lines  # the unit where PX4's metadata gives one
    assert all("BAT" in line for line in lines[1:-2])
    known = sum(1 for _ in vehicle.params.known())
    assert lines[-1] == f" {len(vehicle.params)}/{known} parameters used." == " 994/1002 parameters used."


def _table_index(vehicle, name: str) -> int:
    """The index among every known parameter (param.cpp's first number; the second is the used index)."""
    return [d.name for d in vehicle.params.known()].index(name)


def test_param_show_gives_the_unit_where_known_and_get_only_the_value(vehicle):
    shell = Shell(vehicle)
    assert shell.execute("param show MPC_XY_CRUISE").splitlines()[1].endswith(" : 5.0000 m/s")
    assert shell.execute("param show SIH_KDW").splitlines()[1].endswith(" : 0.0250 Nm/(rad/s)")
    assert shell.execute("param get MPC_XY_CRUISE") == shell.execute("param show -q MPC_XY_CRUISE") == "5.0000\n"


def test_param_show_exact_name_without_wildcard(vehicle):
    out = Shell(vehicle).execute("param show MAV_SYS_ID")
    assert [ln for ln in out.splitlines() if ln.startswith("x")] == [
        f"x   MAV_SYS_ID [{_table_index(vehicle, 'MAV_SYS_ID')},{vehicle.params.index_of('MAV_SYS_ID')}] : 1"]


def test_param_show_lists_unused_parameters_only_with_a(vehicle):
    shell = Shell(vehicle)
    assert "MIS_DIST_1WP" not in shell.execute("param show MIS_*")
    assert f"    MIS_DIST_1WP [{_table_index(vehicle, 'MIS_DIST_1WP')},-1] : 10000.0000 m" in \
        shell.execute("param show -a MIS_*").splitlines()
    assert shell.execute("param touch MIS_DIST_1WP NO_SUCH") == ""
    assert "x   MIS_DIST_1WP" in shell.execute("param show MIS_DIST_1WP")
    count = len(vehicle.params)
    shell.execute("param set MIS_TKO_LAND_REQ 1")  # PX4's param set looks the parameter up: it is used from now on
    assert len(vehicle.params) == count + 1 and "x + MIS_TKO_LAND_REQ" in shell.execute("param show MIS_TKO*")


def test_param_reset_and_reset_all(vehicle):
    shell = Shell(vehicle)
    shell.execute("param set BAT1_N_CELLS 6")
    shell.execute("param set BAT_LOW_THR 0.2")
    shell.execute("param set MPC_XY_P 1.1")
    assert "not enough arguments" in shell.execute("param reset")
    shell.execute("param reset BAT*")
    assert vehicle.params.changed() == {"MPC_XY_P": 1.1}
    shell.execute("param set BAT1_N_CELLS 6")
    shell.execute("param reset_all MPC_XY_*")
    assert vehicle.params.changed() == {"MPC_XY_P": 1.1}
    shell.execute("param reset_all")
    assert vehicle.params.changed() == {}


def test_param_save_writes_the_vehicles_file_or_says_there_is_none(vehicle, tmp_path):
    from sitl_emu.params.store import ParamStore, read_file

    shell = Shell(vehicle)
    assert shell.execute("param save").startswith("ERROR [param] Param save failed")
    store = ParamStore(vehicle.params, tmp_path / "parameters.params")
    shell.execute("param set BAT1_N_CELLS 6")
    assert shell.execute("param save") == f"INFO  [param] saved to {store.path}\n" and not store.unsaved
    assert read_file(store.path)[0][:2] == ("BAT1_N_CELLS", 6.0)
    assert shell.execute(f"param save {tmp_path / 'export.params'}") == ""
    assert read_file(tmp_path / "export.params") == [("BAT1_N_CELLS", 6.0, f"{tmp_path / 'export.params'}:3")]


def test_param_set_prints_old_and_new_and_applies(vehicle):
    shell = Shell(vehicle)
    assert shell.execute("param set BAT_LOW_THR 0.2") == "  BAT_LOW_THR: curr: 0.1500 -> new: 0.2000\n"
    assert vehicle.params.get("BAT_LOW_THR") == pytest.approx(0.2)
    assert shell.execute("param set BAT1_N_CELLS 6") == "  BAT1_N_CELLS: curr: 4 -> new: 6\n"
    assert shell.execute("param set BAT1_N_CELLS 6") == ""  # unchanged: PX4 prints nothing
    assert "x + BAT1_N_CELLS" in shell.execute("param show -c")


def test_param_get(vehicle):
    shell = Shell(vehicle)
    assert shell.execute("param get BAT_LOW_THR") == "0.1500\n"
    assert shell.execute("param get MAV_SYS_ID") == "1\n"
    assert shell.execute("param show -q MAV_SYS_ID") == "1\n"


def test_param_set_unknown_is_an_error_line(vehicle):
    assert Shell(vehicle).execute("param set NO_SUCH 1") == "ERROR [param] Parameter NO_SUCH not found.\n"


@pytest.mark.parametrize("value", ["abc", "nan", "inf", "7.5", "1e9"])
def test_param_set_refuses_bad_values(vehicle, value):
    before = vehicle.params.get("MAV_SYS_ID")
    out = Shell(vehicle).execute(f"param set MAV_SYS_ID {value}")
    assert out.startswith("ERROR [param]") and "failed" in out
    assert vehicle.params.get("MAV_SYS_ID") == before


def test_unknown_command_and_help(vehicle):
    shell = Shell(vehicle)
    assert shell.execute("fly away") == "Invalid command: fly\ntype 'help' for a list of commands\n"
    help_text = shell.execute("help")
    assert help_text.startswith("Builtin Commands:") and "  commander\n" in help_text and "  param\n" in help_text
    assert shell.execute("") == "" and shell.execute("   ") == ""


def test_shutdown_calls_back(vehicle):
    calls = []
    assert Shell(vehicle, on_shutdown=lambda: calls.append(1)).execute("shutdown") == "Exiting NOW.\n"
    assert calls == [1]
    assert "failed" in Shell(vehicle).execute("shutdown")


def test_commander_takeoff_flies_the_real_vehicle():
    from sitl_emu.vehicle.vehicle import Vehicle

    vehicle = Vehicle()
    vehicle.run_until(3_000_000)  # ready to arm
    shell = Shell(vehicle)
    assert shell.execute("commander takeoff") == ""
    vehicle.run_until(15_000_000)
    texts = [e.text for e in vehicle.events_after(-1)]
    assert "Armed by internal command" in texts and "Takeoff detected" in texts
    snap = vehicle.snapshot()
    assert snap.armed and snap.nav_state == NavState.AUTO_LOITER
    assert -snap.pos_ned_m[2] == pytest.approx(2.5, abs=0.2)
    assert "INFO  [commander] navigation mode: Hold" in shell.execute("commander status")


def test_a_failing_command_reports_instead_of_raising(vehicle):
    def boom(cmd):
        raise RuntimeError("vehicle exploded")
    vehicle.on_command = boom
    out = Shell(vehicle).execute("commander arm")
    assert out == "ERROR [commander] internal error: vehicle exploded\nCommand 'commander' failed, returned 1.\n"


def test_commander_mode_auto_mission_sends_set_mode(vehicle):
    Shell(vehicle).execute("commander mode auto:mission")
    cmd = _only_command(vehicle)
    assert (cmd.command, cmd.param(1), cmd.param(2), cmd.param(3)) == (176, 1.0, 4.0, 4.0)


def test_mission_summary(vehicle):
    from sitl_emu.navigator.mission_store import PLAN_MISSION, MissionItem

    shell = Shell(vehicle)
    assert shell.execute("mission") == ("INFO  [mission] mission: none\n"
                                        "INFO  [mission] fence: 0 items, rally: 0 points\n")
    store = vehicle.mission_store()
    store.replace(PLAN_MISSION, (MissionItem(0, 6, 22, 1, 0, 0, 0, math.nan, 473977430, 85455939, 5.0),
                                 MissionItem(1, 2, 20, 1, 0, 0, 0, 0, 0, 0, 0.0)))
    store.current_seq, store.seq_reached = 1, 0
    assert shell.execute("mission").splitlines() == [
        "INFO  [mission] mission: 2 items, current 1, state PAUSED, last reached 0",
        "INFO  [mission]   0 TAKEOFF 47.3977430 8.5455939 5.0 m rel",
        "INFO  [mission] > 1 RETURN_TO_LAUNCH 0 0",
        "INFO  [mission] fence: 0 items, rally: 0 points",
    ]
    assert "mission" in shell.execute("help")
    assert shell.execute("mission clear").startswith("Usage: mission")


@pytest.mark.parametrize(("word", "name"), [("offboard", "Offboard"), ("posctl", "Position")])
def test_a_mode_refused_in_the_air_says_so(word: str, name: str):
    """In the air without setpoints (OFFBOARD) or sticks (Position), PX4 refuses the mode; the console says it in
    PX4's words (printRejectMode) instead of nothing."""
    from sitl_emu.vehicle.vehicle import Vehicle

    vehicle = Vehicle()
    vehicle.run_until(3_000_000)  # ready to arm
    shell = Shell(vehicle)
    shell.execute("commander takeoff")
    vehicle.run_until(12_000_000)
    assert vehicle.snapshot().armed and vehicle.snapshot().nav_state == NavState.AUTO_LOITER
    assert shell.execute(f"commander mode {word}") == (
        f"ERROR [commander] Switching to {name} is currently not available\n")
    assert vehicle.snapshot().nav_state == NavState.AUTO_LOITER
    assert shell.execute("commander mode auto:rtl") == ""  # accepted: nothing to say
