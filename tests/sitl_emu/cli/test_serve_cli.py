"""`sitl-emu serve` as a user runs it: one line, heartbeats at once, clean exits, one-sentence errors with status 2."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest
from pymavlink.dialects.v20 import development as dialect
from support import REPO_ROOT
from support.ports import free_udp_ports

from sitl_emu.px4 import MavCmd

REPO = REPO_ROOT




def _serve(cwd: Path, *args: str) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "sitl_emu", "serve", "--no-console", *args], cwd=cwd,
                            stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env={**os.environ, "PYTHONPATH": str(REPO)})


def _listener(port: int) -> socket.socket:
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.bind(("127.0.0.1", port))
    s.settimeout(10.0)
    return s


def _first_message(sock: socket.socket) -> object:
    parser = dialect.MAVLink(None)
    while True:
        data, _ = sock.recvfrom(65535)
        for msg in parser.parse_buffer(data) or []:
            return msg


@pytest.mark.slow
def test_serve_sends_px4_heartbeats_to_both_remotes_then_exits_cleanly_on_sigterm(tmp_path):
    api_port, gcs_port, api_remote, gcs_remote = free_udp_ports(4)
    with _listener(api_remote) as api_sock, _listener(gcs_remote) as gcs_sock:
        proc = _serve(tmp_path, "--port", str(api_port), "--gcs-port", str(gcs_port),
                      "--remote", f"127.0.0.1:{api_remote}", "--gcs-remote", f"127.0.0.1:{gcs_remote}")
        try:
            hb = _first_message(api_sock)
            assert hb.get_type() == "HEARTBEAT" and (hb.type, hb.autopilot) == (2, 12)
            assert (hb.get_srcSystem(), hb.get_srcComponent()) == (1, 1)
            assert _first_message(gcs_sock).get_type() == "HEARTBEAT"
        finally:
            proc.send_signal(signal.SIGTERM)
            out, err = proc.communicate(timeout=10)
    assert proc.returncode == 0
    assert "Traceback" not in err
    lines = out.strip().splitlines()
    assert len(lines) == 4 and lines[1].startswith("sitl-emu: core: ")  # the vehicle, then which build runs
    assert lines[2:] == ["", "PX4 Exiting..."]  # PX4's shutdown line (main.cpp), after "\n"
    assert f"{api_port}" in lines[0] and f"{api_remote}" in lines[0] and f"{gcs_port}" in lines[0]


@pytest.mark.slow
def test_ctrl_c_exits_without_traceback(tmp_path):
    api_port, gcs_port, remote = free_udp_ports(3)
    proc = _serve(tmp_path, "--port", str(api_port), "--gcs-port", str(gcs_port), "--remote", f"127.0.0.1:{remote}")
    try:
        assert proc.stdout is not None
        proc.stdout.readline()  # up and running
        time.sleep(0.2)
    finally:
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=10)
    assert proc.returncode == 0
    assert "Traceback" not in err and "KeyboardInterrupt" not in err
    assert out.endswith("\nPX4 Exiting...\n")  # as PX4 SITL on Ctrl-C (main.cpp sig_int_handler)


@pytest.mark.slow
def test_instance_gives_sysid_and_offset_ports(tmp_path):
    base_api, base_gcs, remote = free_udp_ports(3)
    with _listener(remote + 3) if remote + 3 < 65536 else pytest.skip("no room for the offset port") as sock:
        proc = _serve(tmp_path, "--instance", "3", "--port", str(base_api - 3), "--gcs-port", str(base_gcs - 3),
                      "--remote", f"127.0.0.1:{remote}")
        try:
            hb = _first_message(sock)
            assert hb.get_srcSystem() == 4
        finally:
            proc.terminate()
            out, _ = proc.communicate(timeout=10)
    assert f":{base_api}," in out and f":{base_gcs}," in out


@pytest.mark.slow
def test_port_in_use_is_one_sentence_and_status_2(tmp_path):
    holder = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    holder.bind(("127.0.0.1", 0))
    port = holder.getsockname()[1]
    try:
        (gcs_port,) = free_udp_ports(1)
        proc = _serve(tmp_path, "--port", str(port), "--gcs-port", str(gcs_port))
        _out, err = proc.communicate(timeout=10)
    finally:
        holder.close()
    assert proc.returncode == 2
    assert "Traceback" not in err
    assert len(err.strip().splitlines()) == 1 and str(port) in err and "in use" in err


@pytest.mark.parametrize("args, words", [
    (("--param", "NO_SUCH_PARAM=1"), "NO_SUCH_PARAM"),
    (("--param", "MIS_TAKEOFF_ALT"), "NAME=VALUE"),
    (("--param", "MIS_TAKEOFF_ALT=high"), "number"),
    (("--home", "47.3,8.5"), "LAT,LON,ALT"),
    (("--remote", "nowhere"), "HOST:PORT"),
    (("--wind", "5"), "SPEED@FROM_DEG"),
])
@pytest.mark.slow
def test_bad_options_are_one_sentence_and_status_2(args, words, tmp_path):
    api_port, gcs_port = free_udp_ports(2)
    proc = _serve(tmp_path, "--port", str(api_port), "--gcs-port", str(gcs_port), *args)
    _out, err = proc.communicate(timeout=10)
    assert proc.returncode == 2
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1 and words in err


def test_wind_option_reaches_the_vehicle():
    from sitl_emu.cli.main import _wind_option, build_vehicle
    from sitl_emu.params import default_registry

    wind = _wind_option("5@270,light")
    v = build_vehicle(default_registry(), None, 3, 1, wind)
    assert v.faults.wind is not None and v.faults.wind.settings == wind
    assert build_vehicle(default_registry(), None, 3, 1).faults.wind is None


def test_params_file_in_both_formats_sets_parameters(tmp_path):
    from sitl_emu.cli.main import build_params

    f = tmp_path / "vehicle.params"
    f.write_text("# QGC style\n1\t1\tMIS_TAKEOFF_ALT\t5.0\t9\nCOM_OF_LOSS_T 2.0  # plain\n")
    registry = build_params(f, ("COM_DISARM_LAND=3",))
    assert registry.get("MIS_TAKEOFF_ALT") == 5.0
    assert registry.get("COM_OF_LOSS_T") == 2.0
    assert registry.get("COM_DISARM_LAND") == 3.0


@pytest.mark.slow
def test_a_plain_pymavlink_client_arms_and_takes_off_via_serve(tmp_path):
    """mavutil's own PX4 mode map and arm helper against the real process (run at 5x real time)."""
    from pymavlink import mavutil

    api_port, gcs_port, remote = free_udp_ports(3)
    conn = mavutil.mavlink_connection(f"udpin:127.0.0.1:{remote}", source_system=255, source_component=190)
    proc = _serve(tmp_path, "--port", str(api_port), "--gcs-port", str(gcs_port), "--remote", f"127.0.0.1:{remote}",
                  "--speed", "5")
    try:
        hb = conn.wait_heartbeat(timeout=10)
        assert hb is not None and conn.target_system == 1
        assert conn.recv_match(type="HEARTBEAT", condition="HEARTBEAT.system_status==3", blocking=True, timeout=10)
        assert conn.flightmode == "LOITER"
        conn.arducopter_arm()
        ack = conn.recv_match(type="COMMAND_ACK", blocking=True, timeout=5)
        assert (ack.command, ack.result) == (MavCmd.COMPONENT_ARM_DISARM, 0)
        conn.set_mode("TAKEOFF")
        assert conn.recv_match(type="COMMAND_ACK", blocking=True, timeout=5).result == 0
        seen: list[str] = []
        deadline = time.monotonic() + 10
        while time.monotonic() < deadline and not (seen and seen[-1] == "LOITER" and "TAKEOFF" in seen):
            if conn.recv_match(type="HEARTBEAT", blocking=True, timeout=1) is not None:
                seen.append(conn.flightmode)
        assert seen[0] == "TAKEOFF" and seen[-1] == "LOITER", seen
        gpi = conn.recv_match(type="GLOBAL_POSITION_INT", blocking=True, timeout=5)
        assert gpi.relative_alt > 1500
    finally:
        proc.terminate()
        proc.communicate(timeout=10)
        conn.close()


def test_instance_sets_mav_sys_id_like_rcs():
    from sitl_emu.cli.main import build_vehicle
    from sitl_emu.params import default_registry

    vehicle = build_vehicle(default_registry(), None, 0, 4)
    assert vehicle.sysid == 4 and vehicle.params.get("MAV_SYS_ID") == 4


@pytest.mark.slow
def test_real_time_runner_follows_the_wall_clock_across_a_reboot():
    import threading

    from support.fakes import Harness

    from sitl_emu.runtime.runner import RealTimeRunner
    from sitl_emu.vehicle.vehicle import Vehicle

    h = Harness(Vehicle())
    runner = RealTimeRunner([h.node], speed=4.0)
    thread = threading.Thread(target=runner.run, daemon=True)
    try:
        thread.start()
        time.sleep(0.8)
        h.gcs.command_long(MavCmd.PREFLIGHT_REBOOT_SHUTDOWN, 1)  # reboot: simulated time starts again at 0
        time.sleep(0.5)
        after_s = h.vehicle.time_us / 1e6
    finally:
        runner.stop()
        thread.join(timeout=5)
        h.close()
    assert 0.5 < after_s < 3.0, f"{after_s:.2f} s simulated in 0.5 s wall at 4x after the reboot"
    assert runner.dropped_us == 0
