"""--view on both command lines: without the extra, on a port in use, with an unwritable recording (one sentence each,
before anything opens); `sitl-emu serve --count 2 --view` listens on 127.0.0.1 only, serves the page and records
every vehicle; its viewer goes away with it."""

from __future__ import annotations

import signal
import socket
import subprocess
import sys
import urllib.request
from pathlib import Path
from typing import Any

import pytest
from click.testing import CliRunner
from support import REPO_ROOT
from support.view_process import listening_sockets, require_rerun, view_process, wait_until

from joyfly.cli import main as joyfly_main
from sitl_emu.cli.main import main as sitl_main

SERVE = ["serve", "--port", "0", "--gcs-port", "0", "--no-console", "--params-reset"]


def run(main: Any, args: list[str], tmp_path: Path) -> tuple[int, str]:
    result = CliRunner().invoke(main, args, catch_exceptions=False)
    return result.exit_code, result.output


@pytest.mark.parametrize(("main", "args"), [
    (sitl_main, [*SERVE, "--view"]),
    (joyfly_main, ["demo", "--view"]),
    (joyfly_main, ["fly", "--joy", "/nonexistent", "--view"]),
], ids=["serve", "demo", "fly"])
def test_view_without_the_extra_says_how_to_install_it(main: Any, args: list[str], tmp_path: Path,
                                                       monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "rerun", None)  # `import rerun` raises ImportError, as without the extra
    monkeypatch.chdir(tmp_path)
    code, output = run(main, args, tmp_path)
    assert code == 2
    lines = output.strip().splitlines()
    assert len(lines) == 1, output
    # README's and -h's `pip install -e '.[view]'`, with this Python and this clone, so it works as printed
    assert lines[0].endswith(f"is not installed: {sys.executable} -m pip install -e '{REPO_ROOT}[view]'"), lines[0]
    assert not list(tmp_path.glob("*.params"))  # nothing started


@pytest.mark.parametrize(("main", "args"), [(sitl_main, SERVE), (joyfly_main, ["demo"])], ids=["serve", "demo"])
def test_a_view_port_in_use_is_one_sentence(main: Any, args: list[str], tmp_path: Path,
                                           monkeypatch: pytest.MonkeyPatch) -> None:
    require_rerun()
    monkeypatch.chdir(tmp_path)
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        port = busy.getsockname()[1]
        code, output = run(main, [*args, "--view-port", str(port)], tmp_path)
    assert code == 2
    assert output.strip().splitlines() == [output.strip()]
    assert f"Port {port} on 127.0.0.1 is in use" in output and "--view-port" in output


def test_an_unwritable_recording_is_one_sentence(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    require_rerun()
    monkeypatch.chdir(tmp_path)
    code, output = run(sitl_main, [*SERVE, "--record-view", str(tmp_path / "missing" / "view.rrd")], tmp_path)
    assert code == 2
    assert output.strip() == (f"sitl-emu: Cannot write the view recording {tmp_path / 'missing' / 'view.rrd'}: "
                              "No such file or directory.")


@pytest.mark.slow
def test_serve_view_listens_on_loopback_only_and_records_every_vehicle(tmp_path: Path) -> None:
    require_rerun()
    record = tmp_path / "view.rrd"
    args = ["sitl_emu", *SERVE, "--count", "2", "--view", "--record-view", str(record)]
    with view_process(args, tmp_path) as view:
        sockets = listening_sockets(view.proc.pid)
        assert len(sockets) >= 2  # the web page and the gRPC proxy
        assert {s.laddr.ip for s in sockets} == {"127.0.0.1"}, sockets
        assert view.url.startswith("http://127.0.0.1:")
        with urllib.request.urlopen(view.url, timeout=10) as page:
            assert page.status == 200 and b"<html" in page.read().lower()
        assert wait_until(lambda: record.exists() and record.stat().st_size > 20_000, 30)
        ports = {s.laddr.port for s in sockets}
        view.proc.send_signal(signal.SIGTERM)
        view.proc.wait(10)
    assert wait_until(lambda: not ports & {s.laddr.port for s in _all_listening()}, 10), "the viewer outlived serve"
    entities = _entities(record)
    for sysid in (1, 2):
        assert {f"/world/sysid{sysid}/body", f"/plots/altitude/sysid{sysid}",
                f"/plots/armed/sysid{sysid}"} <= entities


def _all_listening() -> list[object]:
    import psutil

    return [c for c in psutil.net_connections(kind="tcp") if c.status == psutil.CONN_LISTEN]


def _entities(record: Path) -> set[str]:
    """The entity paths in a .rrd, as Rerun's own `rerun rrd print` lists them."""
    from flightview.server import rerun_program

    printed = subprocess.run([rerun_program(), "rrd", "print", str(record)], capture_output=True, text=True,
                             timeout=60, check=True).stdout
    return {word.rstrip(":,") for word in printed.split() if word.startswith(("/world/", "/plots/"))}


@pytest.mark.slow
def test_both_view_ports_can_be_set(tmp_path: Path) -> None:
    """--view-port sets the page's port, --view-grpc-port the data stream's (Rerun's gRPC proxy) that the page reads."""
    require_rerun()
    web, grpc = _free_tcp_ports(2)
    args = ["sitl_emu", *SERVE, "--view-port", str(web), "--view-grpc-port", str(grpc)]
    with view_process(args, tmp_path) as view:
        assert {web, grpc} <= {s.laddr.port for s in listening_sockets(view.proc.pid)}
        assert view.url.startswith(f"http://127.0.0.1:{web}/?url=rerun%2Bhttp%3A%2F%2F127.0.0.1%3A{grpc}%2Fproxy")


@pytest.mark.parametrize("same", [False, True])
def test_a_grpc_port_in_use_or_shared_with_the_page_is_one_sentence(same: bool, tmp_path: Path,
                                                                   monkeypatch: pytest.MonkeyPatch) -> None:
    require_rerun()
    monkeypatch.chdir(tmp_path)
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        port = busy.getsockname()[1]
        web = port if same else _free_tcp_ports(1)[0]
        code, output = run(joyfly_main, ["demo", "--view-port", str(web), "--view-grpc-port", str(port)], tmp_path)
    assert code == 2
    assert output.strip().splitlines() == [output.strip()]
    if same:
        assert f"--view-port and --view-grpc-port are both {port}" in output
    else:
        assert f"Port {port} on 127.0.0.1 is in use" in output and "--view-grpc-port" in output


def _free_tcp_ports(n: int) -> list[int]:
    socks = [socket.socket() for _ in range(n)]
    try:
        for sock in socks:
            sock.bind(("127.0.0.1", 0))
        return [int(sock.getsockname()[1]) for sock in socks]
    finally:
        for sock in socks:
            sock.close()
