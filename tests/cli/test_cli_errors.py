"""Every bad value a user can type to `joyfly` or `sitl-emu` ends in one line `TOOL: sentence` on stderr, a non-zero
exit status and no traceback (issue 10.3, 10.11): ports, seeds, speeds, counts, numbers, NaN, URLs, config files."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner, Result
from support import REPO_ROOT

import joyfly.cli
import sitl_emu.cli.main

REPO = REPO_ROOT
SCRIPT = str(REPO / "examples" / "joystick_script.txt")


def _one_line_error(result: Result, tool: str) -> str:
    assert result.exit_code != 0, result.output
    assert isinstance(result.exception, SystemExit), f"not a clean exit: {result.exception!r}"
    assert "Traceback" not in result.output
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith(f"{tool}: "), lines[0]
    assert not result.stdout.strip(), result.stdout
    return lines[0]


def serve_error(*args: str, monkeypatch: pytest.MonkeyPatch) -> str:
    def never(*_a: object, **_k: object) -> None:
        raise AssertionError("the bad value was not caught before the vehicle was built")

    monkeypatch.setattr(sitl_emu.cli.main, "build_nodes", never)
    result = CliRunner().invoke(sitl_emu.cli.main.main, ["serve", "--no-console", *args], prog_name="sitl-emu")
    return _one_line_error(result, "sitl-emu")


def fly_error(*args: str) -> str:
    result = CliRunner().invoke(joyfly.cli.main, ["fly", "--connect-timeout", "1", *args], prog_name="joyfly")
    return _one_line_error(result, "joyfly")


@pytest.mark.parametrize(("args", "words"), [
    (("--port", "99999"), "'--port': 99999 is not in the range 0 to 65535"),
    (("--gcs-port", "70000"), "'--gcs-port': 70000 is not in the range 0 to 65535"),
    (("--port", "-1"), "'--port': -1 is not in the range 0 to 65535"),
    (("--seed", "-1"), "'--seed': -1 is not in the range 0 to 4294967295"),
    (("--seed", str(2**32)), "is not in the range 0 to 4294967295"),
    (("--seed", "x"), "'--seed': 'x' is not a valid integer"),
    (("--speed", "nan"), "'--speed': 'nan' is not a number from 0.1 to 100"),
    (("--speed", "0"), "'--speed': 0.0 is not in the range 0.1 to 100"),
    (("--speed", "1000"), "'--speed': 1000.0 is not in the range 0.1 to 100"),
    (("--batch-ms", "nan"), "'--batch-ms': 'nan' is not a number from 0 to 1000"),
    (("--batch-ms", "-1"), "is not in the range 0 to 1000"),
    (("--count", "0"), "'--count': 0 is not in the range 1 to 250"),
    (("--instance", "251"), "'--instance': 251 is not in the range 0 to 250"),
    (("--instance", "200", "--count", "60"), "needs system ids up to 260; keep --instance + --count at most 251"),
    (("--port", "65535", "--instance", "1"), "--port 65535 offset by instance 1 is port 65536, above 65535; use "
                                             "--port at most 65534"),
    (("--gcs-port", "65534", "--count", "3"), "--gcs-port 65534 offset by instance 2 is port 65536"),
    (("--remote", "127.0.0.1:65530", "--instance", "9"), "--remote port 65530 offset by instance 9 is above 65535; "
                                                         "use a --remote port at most 65526"),
    (("--port", "25037", "--gcs-port", "25037"), "--port and --gcs-port give two links port 25037"),
    (("--count", "3", "--port", "25040", "--gcs-port", "25041"), "--gcs-port and --port give two links port 25041"),
    (("--port", "25180", "--remote", "127.0.0.1:25180"), "--remote 127.0.0.1:25180 is a port this emulator listens "
                                                          "on (--port): it would talk to itself"),
    (("--gcs-port", "25181", "--gcs-remote", "localhost:25181"), "--gcs-remote localhost:25181 is a port this "
                                                                 "emulator listens on (--gcs-port)"),
    (("--remote", "127.0.0.1:0"), "--remote 127.0.0.1:0: port 0 is out of range; use a port from 1 to 65535"),
    (("--gcs-remote", "127.0.0.1:99999"), "port 99999 is out of range; use a port from 1 to 65535"),
    (("--remote", "nowhere"), "--remote must look like HOST:PORT"),
    (("--remote", "nosuchhost.invalid:14540"), "--remote: no such host 'nosuchhost.invalid'"),
    (("--bind", "nosuchhost.invalid"), "--bind: no such host 'nosuchhost.invalid'"),
    (("--home", "91,0,0"), "out of range (latitude ±90, longitude ±180, altitude -500..9000 m)"),
    (("--home", "nan,8,400"), "out of range (latitude ±90"),
    (("--home", "47,8"), "--home must be LAT,LON,ALT"),
    (("--param", "MIS_TAKEOFF_ALT=nan"), "--param: Parameter MIS_TAKEOFF_ALT must be a finite number"),
    (("--param", "MIS_TAKEOFF_ALT=inf"), "must be a finite number"),
    (("--param", "MPC_XY_VEL_MAX=50"), "must be within [0, 20]"),
    (("--speed", "2", "--frobnicate"), "No such option '--frobnicate'"),
    (("--count", "two"), "'--count': 'two' is not a valid integer"),
    (("--speed", "fast"), "'--speed': 'fast' is not a valid float"),
])
def test_bad_serve_values(args: tuple[str, ...], words: str, monkeypatch: pytest.MonkeyPatch) -> None:
    assert words in serve_error(*args, monkeypatch=monkeypatch)


def test_bad_values_in_a_params_file_name_the_file_and_line(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    params = tmp_path / "vehicle.params"
    params.write_text("# comment\nMIS_TAKEOFF_ALT 5\nCOM_OF_LOSS_T nan\n")
    assert f"{params}:3: Parameter COM_OF_LOSS_T must be a finite number" in serve_error(
        "--params", str(params), monkeypatch=monkeypatch)
    params.write_bytes(b"\xff\xfe\x00binary")
    assert "is not a text file" in serve_error("--params", str(params), monkeypatch=monkeypatch)
    assert "Cannot read the parameter file" in serve_error("--params", str(tmp_path), monkeypatch=monkeypatch)
    missing = tmp_path / "no_such_folder" / "vehicle.params"
    assert f"the folder {missing.parent} does not exist" in serve_error("--params", str(missing),
                                                                        monkeypatch=monkeypatch)


@pytest.mark.parametrize(("args", "words"), [
    (("--url", "udp://:99999@127.0.0.1:14557"), "the listen port 99999 is out of range; use 0 to 65535"),
    (("--url", "udpout:127.0.0.1:99999"), "the vehicle port 99999 is out of range; use 1 to 65535"),
    (("--url", "udpin:127.0.0.1:70000"), "the listen port 70000 is out of range; use 0 to 65535"),
    (("--url", "udp://:14540@127.0.0.1:0"), "the vehicle port 0 is out of range; use 1 to 65535"),
    (("--url", "tcp:127.0.0.1:99999"), "the TCP port 99999 is out of range; use 1 to 65535"),
    (("--url", "udpin:host"), "the listen address 'host' is not HOST:PORT"),
    (("--url", "/dev/ttyUSB0:12"), "the baud rate 12 is out of range; use 50 to 4000000"),
    (("--url", "carrier-pigeon"), "use udp://:14540@127.0.0.1:14557 (MAVROS style)"),
    (("--alt", "50"), "--alt 50 is out of range: use 0.5 to 10 m (from --min-alt to --max-alt)"),
    (("--alt", "-3"), "--alt -3 is out of range: use 0.5 to 10 m (from --min-alt to --max-alt)"),  # one range
    (("--alt", "nan"), "--alt nan is not a number"),
    (("--alt", "high"), "'--alt': 'high' is not a valid float"),
    (("--speed", "50000"), "--speed 50000 is out of range: use 0.1 to 100 times real time"),
    (("--speed", "0"), "--speed 0 is out of range"),
    (("--rate", "1"), "--rate 1 is out of range: use 10 to 200 Hz"),
    (("--max-speed", "inf"), "--max-speed inf is not a number: write a number from 0.1 to 20 m/s"),
    (("--max-climb", "0"), "--max-climb 0 is out of range: use 0.1 to 8 m/s"),
    (("--max-yaw-rate", "-5"), "--max-yaw-rate -5 is out of range: use 0 to 400 deg/s"),
    (("--fence", "-1"), "--fence -1 is out of range: use 0 to 10000 m"),
    (("--step", "1000"), "--step 1000 is out of range: use 0.1 to 50 m"),
    (("--min-alt", "8", "--max-alt", "6"), "--min-alt 8 must be below --max-alt (6 m)"),
    (("--joy-timeout", "0"), "--joy-timeout 0 is out of range: use 0.1 to 600 s"),
    (("--connect-timeout", "-1"), "--connect-timeout -1 is out of range: use 1 to 3600 s"),
    (("--control", "rate"), "'--control': 'rate' is not one of 'velocity', 'step'"),
    (("--on-exit", "crash"), "'--on-exit': 'crash' is not one of 'land', 'hold', 'rtl'"),
])
def test_bad_fly_values(args: tuple[str, ...], words: str) -> None:
    assert words in fly_error(*args)


@pytest.mark.parametrize(("url", "words"), [
    ("/dev/ttyUSB_no_such_device", "No serial device /dev/ttyUSB_no_such_device: plug the autopilot in"),
    ("serial:///dev/ttyUSB_no_such_device:57600", "No serial device /dev/ttyUSB_no_such_device:"),
    ("/dev/null", "Cannot open the serial device /dev/null"),
    ("udpout:nosuchhost.invalid:14557", "Unknown host 'nosuchhost.invalid' in --url"),
])
def test_links_that_cannot_open_are_one_sentence(url: str, words: str) -> None:
    assert words in fly_error("--joy", f"script:{SCRIPT}", "--url", url)


def test_a_bad_config_file_value_names_the_file_and_the_key(tmp_path: Path) -> None:
    config = tmp_path / "joyfly.toml"
    config.write_text('[fly]\nalt = "high"\n')
    line = fly_error("--config", str(config))
    assert line == f'joyfly: {config}: alt = "high" is not a number: write a number between min-alt and max-alt ' \
                   "(0.5 and 10 m unless you change them), for example alt = 3."
    config.write_text("[fly]\nurl = 'udp://:14540@127.0.0.1:99999'\n")
    assert f"{config}: url = \"udp://:14540@127.0.0.1:99999\": the vehicle port 99999" in fly_error("--config",
                                                                                                   str(config))


@pytest.mark.parametrize("args", [
    ("--speed", "0.01"), ("--speed", "nan"), ("--url", "udpin:127.0.0.1:99999"),
])
def test_bad_demo_values(args: tuple[str, ...]) -> None:
    result = CliRunner().invoke(joyfly.cli.main, ["demo", "--plain", *args], prog_name="joyfly")
    _one_line_error(result, "joyfly")


@pytest.mark.parametrize(("tool", "args"), [
    ("joyfly", ["fly", "--url", "udp://:99999@127.0.0.1:14557", "--joy", f"script:{SCRIPT}"]),
    ("joyfly", ["fly", "--url", "udpout:127.0.0.1:99999", "--joy", f"script:{SCRIPT}"]),
    ("joyfly", ["fly", "--url", "udpin:127.0.0.1:70000", "--joy", f"script:{SCRIPT}"]),
    ("sitl_emu", ["serve", "--port", "99999"]),
    ("sitl_emu", ["serve", "--seed", "-1"]),
])
def test_the_issues_examples_as_a_user_runs_them(tool: str, args: list[str]) -> None:
    proc = subprocess.run([sys.executable, "-m", tool, *args], cwd=REPO, stdin=subprocess.DEVNULL,
                          capture_output=True, text=True, timeout=30)
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1
    assert proc.stderr.startswith(f"{tool.replace('_', '-')}: ")
