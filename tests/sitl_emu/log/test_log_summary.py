"""`sitl-emu log FILE.ulg` on a flight logged in lockstep: the summary's numbers are the flight's, and --plot a PNG.

One OFFBOARD square (sitl_emu.testing.client.fly_square) is flown with Sim(log_dir=...) for the module; the client
records what the link said (LOCAL_POSITION_NED, STATUSTEXT), and the summary of the log must agree with it.
"""

from __future__ import annotations

import math
import struct
import sys
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from support.log_flight import RecordingClient, log_files

from sitl_emu.cli.main import main
from sitl_emu.log.plot import INSTALL_HINT
from sitl_emu.log.summary import mode_label, read_ulog, series, summarise
from sitl_emu.testing.client import fly_square
from sitl_emu.testing.sim import Sim

pytestmark = pytest.mark.slow  # processes or long flights: not in `make test-fast`

pytest.importorskip("pyulog", reason="the summary reads logs with pyulog: pip install pyulog (the test extra)")

SIDE_M = 4.0
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


class Flown:
    def __init__(self, log: Path, client: RecordingClient) -> None:
        self.log = log
        self.client = client
        positions = client.received["LOCAL_POSITION_NED"]
        self.max_alt_m = max(-p.z for p in positions) - (-positions[0].z)
        self.max_hspeed_mps = max(math.hypot(p.vx, p.vy) for p in positions)
        self.texts = _whole_texts(client.received["STATUSTEXT"])


def _whole_texts(chunks: list) -> list[str]:
    """STATUSTEXT chunks joined into texts (chunk_seq > 0 continues the previous), without PX4's trailing tab."""
    texts: list[str] = []
    for m in chunks:
        if m.chunk_seq and texts:
            texts[-1] += m.text
        else:
            texts.append(m.text)
    return [t.rstrip() for t in texts]


@pytest.fixture(scope="module")
def flown(tmp_path_factory: pytest.TempPathFactory) -> Flown:
    log_dir = tmp_path_factory.mktemp("logs")
    sim = Sim(log_dir=log_dir, params={"MIS_TAKEOFF_ALT": 2.5})
    try:
        client = RecordingClient(sim.ports(0).gcs, sim.clock)
        result = fly_square(client, side_m=SIDE_M, altitude_m=2.5)
        assert result.ok, result.error
        client.spin(1.0)
    finally:
        sim.close()
    files = log_files(log_dir)
    assert len(files) == 1, files
    return Flown(files[0], client)


def _run(*args: str) -> tuple[int, str, str]:
    result = CliRunner().invoke(main, ["log", *args], prog_name="sitl-emu")
    return result.exit_code, result.stdout, result.stderr


def test_the_summary_numbers_are_the_flights(flown: Flown):
    s = summarise(read_ulog(flown.log), flown.log)
    assert s.sys_name == "PX4"
    assert s.max_alt_m == pytest.approx(flown.max_alt_m, abs=0.1)
    assert s.max_hspeed_mps == pytest.approx(flown.max_hspeed_mps, rel=0.1)
    assert flown.max_hspeed_mps > 1.0  # the square moved: the speed is not trivially 0
    assert [t.text for t in s.texts] == flown.texts
    assert [t.time_s for t in s.texts] == sorted(t.time_s for t in s.texts)
    # from arming to disarming: the client saw both, so the log spans most of its flight, and no more
    assert 10.0 < s.duration_s < flown.client.clock.now() - flown.client.start_s


def test_modes_over_time_have_px4_names_in_flight_order(flown: Flown):
    s = summarise(read_ulog(flown.log), flown.log)
    names = [m.name for m in s.modes]
    flown_order = ["Takeoff", "Hold", "Offboard", "Land"]
    it = iter(names)
    assert all(name in it for name in flown_order), names  # in this order, each after the previous
    starts = [m.start_s for m in s.modes]
    assert starts == sorted(starts) and starts[0] >= 0.0 and starts[-1] <= s.duration_s


def test_the_command_prints_the_summary(flown: Flown):
    code, out, err = _run(str(flown.log))
    assert code == 0, err
    assert out.startswith(f"{flown.log}: PX4 ")
    s = summarise(read_ulog(flown.log), flown.log)
    assert f"Max altitude over start: {s.max_alt_m:.2f} m" in out
    assert f"Max horizontal speed:   {s.max_hspeed_mps:.2f} m/s" in out
    assert "  Offboard" in out
    for text in flown.texts:
        assert text in out


def _png_size(data: bytes) -> tuple[int, int]:
    assert data[:8] == PNG_MAGIC and data[12:16] == b"IHDR"
    return struct.unpack(">II", data[16:24])


def test_plot_writes_a_png(flown: Flown, tmp_path: Path):
    pytest.importorskip("matplotlib", reason="--plot draws with matplotlib: pip install matplotlib (the test extra)")
    out = tmp_path / "flight.png"
    code, stdout, err = _run(str(flown.log), "--plot", str(out))
    assert code == 0, err
    assert f"Plot: {out}" in stdout
    data = out.read_bytes()
    width, height = _png_size(data)
    assert width >= 400 and height >= 400
    assert len(data) > 20_000  # four panels of lines, not an empty canvas
    assert data.endswith(b"IEND\xaeB`\x82")


def test_plot_without_matplotlib_says_how_to_install_it(flown: Flown, tmp_path: Path, monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib", None)  # `import matplotlib` raises ImportError
    code, out, err = _run(str(flown.log), "--plot", str(tmp_path / "x.png"))
    assert code == 2
    assert err == f"sitl-emu: {INSTALL_HINT}\n"
    assert "Duration:" in out  # the summary is printed all the same
    assert not (tmp_path / "x.png").exists()


def _bad_inputs(tmp_path: Path, log: Path) -> dict[str, Path]:
    data = log.read_bytes()
    not_ulog = tmp_path / "notes.ulg"
    not_ulog.write_bytes(b"this is not a log\n" * 100)
    cut_in_data = tmp_path / "cut_in_data.ulg"
    cut_in_data.write_bytes(data[: len(data) // 2 + 7])
    cut_in_header = tmp_path / "cut_in_header.ulg"
    cut_in_header.write_bytes(data[:300])
    empty = tmp_path / "empty.ulg"
    empty.write_bytes(b"")
    return {"missing": tmp_path / "missing.ulg", "not ULog": not_ulog, "cut in the data": cut_in_data,
            "cut in the definitions": cut_in_header, "empty": empty, "a directory": tmp_path}


@pytest.mark.parametrize("case", ["missing", "not ULog", "cut in the data", "cut in the definitions", "empty",
                                  "a directory"])
def test_bad_input_is_one_sentence_and_status_2(flown: Flown, tmp_path: Path, case: str):
    path = _bad_inputs(tmp_path, flown.log)[case]
    code, out, err = _run(str(path))
    assert code == 2
    assert out == ""
    assert err.startswith(f"sitl-emu: {path}") and err.endswith(".\n") and err.count("\n") == 1, err
    assert "Traceback" not in err


class _Dataset:
    def __init__(self, data: dict) -> None:
        self.data = data


class _PX4LikeULog:
    """What pyulog gives for a real PX4 log whose first vehicle_status sample predates the log's start (PX4 logs the
    last published sample of each topic when the logger starts): uint64 timestamps before start_timestamp."""

    start_timestamp = 5_000_000

    def get_dataset(self, name: str, multi_id: int = 0) -> _Dataset:
        if name != "vehicle_status":
            raise KeyError(name)
        return _Dataset({"timestamp": np.array([4_000_000, 6_000_000, 7_500_000], dtype=np.uint64),
                         "nav_state": np.array([4, 17, 99], dtype=np.uint8)})


def test_samples_before_the_logs_start_and_unknown_modes():
    t, nav = series(_PX4LikeULog(), "vehicle_status", "nav_state")
    assert list(t) == pytest.approx([-1.0, 1.0, 2.5])  # negative, not wrapped around 2**64
    assert list(nav) == [4, 17, 99]
    assert series(_PX4LikeULog(), "vehicle_local_position", "z") is None
    assert [mode_label(n) for n in (4, 17, 14, 99)] == ["Hold", "Takeoff", "Offboard", "nav_state 99"]
