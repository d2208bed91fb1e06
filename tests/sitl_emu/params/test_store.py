"""Parameter values that survive a restart (PX4 SITL's parameters.bson): the store, and `sitl-emu serve` twice."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from pymavlink import mavutil
from support import REPO_ROOT
from support.ports import free_udp_ports

from sitl_emu.cli.main import stored_params
from sitl_emu.params import default_registry
from sitl_emu.params import store as store_module
from sitl_emu.params.store import DEFAULT_FILE, ParamFileError, ParamStore, instance_path, read_file


def test_save_and_load_give_back_every_changed_value_bit_for_bit(tmp_path):
    reg = default_registry()
    store = ParamStore(reg, tmp_path / DEFAULT_FILE)
    reg.set("MPC_XY_P", 0.949999988079071 + 0.1)  # any double, as a REAL32 set over MAVLink gives
    reg.set("BAT1_N_CELLS", 6)
    reg.set("ADSB_CALLSIGN_1", -(2**31))
    reg.set("SENS_BOARD_X_OFF", 1.5e-7)
    assert store.unsaved and store.save() == str(store.path) and not store.unsaved
    assert [name for name, _, _ in read_file(store.path)] == sorted(reg.changed())
    again = default_registry()
    assert ParamStore(again, store.path).load() is None
    assert again.changed() == reg.changed() and again.values() == reg.values()


def test_the_file_is_qgc_params_text(tmp_path):
    reg = default_registry()
    reg.set("MIS_TAKEOFF_ALT", 5.0)
    reg.set("BAT1_N_CELLS", 6)
    store = ParamStore(reg, tmp_path / DEFAULT_FILE, sysid=3)
    store.save()
    lines = [ln for ln in store.path.read_text().splitlines() if not ln.startswith("#")]
    assert lines == ["3\t1\tBAT1_N_CELLS\t6\t6", "3\t1\tMIS_TAKEOFF_ALT\t5.0\t9"]


def test_garbage_is_one_warning_sentence_the_defaults_and_the_file_kept_aside(tmp_path):
    path = tmp_path / DEFAULT_FILE
    path.write_text("MIS_TAKEOFF_ALT 5\nthis is not a parameter line\n")
    reg = default_registry()
    warning = ParamStore(reg, path).load()
    assert warning is not None and "\n" not in warning and warning.endswith(".")
    assert "is not a usable parameter file" in warning and "starts from the defaults" in warning
    assert reg.changed() == {} and not path.exists() and (tmp_path / (DEFAULT_FILE + ".bad")).exists()


@pytest.mark.parametrize("content", [b"\x89PNG\r\n\x1a\n\x00\x00binary", b"{\"MIS_TAKEOFF_ALT\": 5}\n",
                                     b"MIS_TAKEOFF_ALT five\n"])
def test_other_garbage_is_refused_too(tmp_path, content):
    path = tmp_path / DEFAULT_FILE
    path.write_bytes(content)
    reg = default_registry()
    assert "not a usable parameter file" in (ParamStore(reg, path).load() or "")
    assert reg.changed() == {}


def test_an_endless_or_huge_file_is_read_only_so_far():
    with pytest.raises(ParamFileError, match="is over 1 MB: not a parameter file"):
        read_file(Path("/dev/zero"))


def test_unknown_names_and_refused_values_are_skipped_the_rest_loaded(tmp_path):
    path = tmp_path / DEFAULT_FILE
    path.write_text("1\t1\tMIS_TAKEOFF_ALT\t5.0\t9\nNO_SUCH_PARAM 3\nMPC_XY_VEL_MAX 99\n")
    reg = default_registry()
    warning = ParamStore(reg, path).load()
    assert warning is not None and "NO_SUCH_PARAM, MPC_XY_VEL_MAX" in warning
    assert reg.changed() == {"MIS_TAKEOFF_ALT": 5.0} and path.exists()


def test_autosave_writes_after_a_change_only(tmp_path):
    reg = default_registry()
    store = ParamStore(reg, tmp_path / DEFAULT_FILE)
    store.autosave()
    assert not store.path.exists()
    reg.set("MIS_TAKEOFF_ALT", 4.0)
    store.autosave()
    assert read_file(store.path)[0][:2] == ("MIS_TAKEOFF_ALT", 4.0)
    stamp = store.path.stat().st_mtime_ns
    store.autosave()
    assert store.path.stat().st_mtime_ns == stamp


def test_a_failed_autosave_is_logged_once_and_left_unsaved(tmp_path, monkeypatch):
    warnings: list[str] = []
    monkeypatch.setattr(store_module.log, "warning", lambda fmt, *args: warnings.append(fmt % args))
    reg = default_registry()
    store = ParamStore(reg, tmp_path / "missing-dir" / DEFAULT_FILE)
    reg.set("MIS_TAKEOFF_ALT", 4.0)
    store.autosave()
    store.autosave()
    reg.set("MIS_TAKEOFF_ALT", 4.5)
    store.autosave()
    assert len(warnings) == 1 and "cannot save the parameters" in warnings[0]
    assert store.unsaved


def test_each_instance_has_its_own_file():
    base = Path("parameters.params")
    assert instance_path(base, 0, 0) == base
    assert instance_path(base, 2, 0) == Path("parameters-2.params")
    assert instance_path(Path("/x/v.params"), 3, 3) == Path("/x/v.params")


def test_serve_finds_its_file_in_the_working_directory(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / DEFAULT_FILE).write_text("MIS_TAKEOFF_ALT 6\n")
    (tmp_path / "parameters-1.params").write_text("MIS_TAKEOFF_ALT 7\n")
    first, store, warning = stored_params(None, 0, 0, reset=False)
    second, _, _ = stored_params(None, 1, 0, reset=False)
    assert (first.get("MIS_TAKEOFF_ALT"), second.get("MIS_TAKEOFF_ALT")) == (6.0, 7.0)
    assert warning is None and store.path == Path(DEFAULT_FILE) and first.storage is store
    fresh, _, _ = stored_params(None, 0, 0, reset=True)
    assert fresh.changed() == {}


def test_an_explicit_file_with_a_count_seeds_the_vehicles_without_a_file_of_their_own(tmp_path):
    base = tmp_path / "v.params"
    base.write_text("MIS_TAKEOFF_ALT 6\n")
    other, store, _ = stored_params(base, 1, 0, reset=False)
    assert other.get("MIS_TAKEOFF_ALT") == 6.0 and store.path == tmp_path / "v-1.params"
    _, _, note = stored_params(tmp_path / "new.params", 0, 0, reset=False)
    assert note is not None and "does not exist yet" in note


# --- two real starts of `sitl-emu serve` ---------------------------------------------------------------------------
def _serve(cwd: Path, ports: tuple[int, int, int], *args: str) -> subprocess.Popen:
    api, gcs, remote = ports
    return subprocess.Popen([sys.executable, "-m", "sitl_emu", "serve", "--no-console", "--port", str(api),
                             "--gcs-port", str(gcs), "--remote", f"127.0.0.1:{remote}", *args], cwd=cwd,
                            stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env={**os.environ, "PYTHONPATH": str(REPO_ROOT)})


def _stop(proc: subprocess.Popen) -> str:
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=10)
    assert proc.returncode == 0 and "Traceback" not in err
    return err


def _read(conn, name: str) -> float:
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline:
        conn.mav.param_request_read_send(1, 1, name.encode(), -1)
        msg = conn.recv_match(type="PARAM_VALUE", blocking=True, timeout=1)
        if msg is not None and msg.param_id == name:
            return float(msg.param_value)
    raise AssertionError(f"no PARAM_VALUE for {name}")


def _session(cwd: Path, *args: str, set_to: float | None = None) -> tuple[float, str]:
    """Start serve in `cwd`, read MIS_TAKEOFF_ALT (and set it if asked), stop; (value read, stderr)."""
    ports = free_udp_ports(3)
    conn = mavutil.mavlink_connection(f"udpin:127.0.0.1:{ports[2]}", source_system=255, source_component=190)
    proc = _serve(cwd, ports, *args)
    try:
        assert conn.wait_heartbeat(timeout=10) is not None
        value = _read(conn, "MIS_TAKEOFF_ALT")
        if set_to is not None:
            conn.mav.param_set_send(1, 1, b"MIS_TAKEOFF_ALT", set_to, mavutil.mavlink.MAV_PARAM_TYPE_REAL32)
            assert conn.recv_match(type="PARAM_VALUE", blocking=True, timeout=5).param_value == set_to
    finally:
        err = _stop(proc)
        conn.close()
    return value, err


@pytest.mark.slow
def test_serve_keeps_a_set_value_across_a_restart_and_params_reset_starts_from_the_defaults(tmp_path):
    assert _session(tmp_path, set_to=7.0)[0] == 2.5
    assert read_file(tmp_path / DEFAULT_FILE)[0][:2] == ("MIS_TAKEOFF_ALT", 7.0)
    assert _session(tmp_path)[0] == 7.0
    assert _session(tmp_path, "--params-reset")[0] == 2.5
    assert read_file(tmp_path / DEFAULT_FILE) == []
    assert _session(tmp_path)[0] == 2.5


@pytest.mark.slow
def test_serve_with_a_garbage_file_warns_once_and_starts_from_the_defaults(tmp_path):
    (tmp_path / DEFAULT_FILE).write_bytes(b"\x00\x01garbage that is no parameter file\n")
    value, err = _session(tmp_path)
    assert value == 2.5
    assert len(err.strip().splitlines()) == 1 and "is not a usable parameter file" in err
