"""`sitl-emu serve`: a PX4-protocol quadrotor on UDP, as PX4 SITL opens its links.

The CLI only parses options, builds the Vehicle and its node, prints one line and hands over to a runner.
Errors a user can cause (port in use, bad --param, bad --home) end in one sentence and exit status 2.
"""

from __future__ import annotations

import contextlib
import logging
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from flightview.options import view_options
from px4common.cli_style import CONTEXT, FiniteRange, OneLineGroup, UserError, WholeRange
from px4common.clock import SPEED_MAX, SPEED_MIN
from px4common.signing_key import SigningKeyError, read_signing_key
from sitl_emu._speedups import build_line
from sitl_emu.campaign.cli import campaign
from sitl_emu.cli.options import (
    MAX_SYSID,
    PORT_MAX,
    SEED_MAX,
    TOOL,
    VERSION_MESSAGE,
    UsageProblem,
    check_host,
    check_instances,
    check_own_ports,
    parse_address,
    parse_home,
)
from sitl_emu.cli.signals import EARLY, ShutdownSignals, owning_signals
from sitl_emu.cli.signing_key import attach_signing
from sitl_emu.cli.view_setup import check_view, start_view
from sitl_emu.console.console import attach_console
from sitl_emu.log.cli import log as log_command
from sitl_emu.log.serving import DEFAULT_LOG_DIR, attach_loggers, handlers_by_instance
from sitl_emu.mavlink.link_errors import PortInUseError
from sitl_emu.runtime.node import LinkSettings, VehicleNode
from sitl_emu.runtime.runner import RealTimeRunner
from sitl_emu.runtime.swarm import DEFAULT_HOME, SwarmRunner, build_nodes

if TYPE_CHECKING:  # imported where used, so that `--help` stays quick
    from sitl_emu.console.console import Console
    from sitl_emu.disturbance.wind import WindSettings
    from sitl_emu.params import ParamRegistry
    from sitl_emu.params.store import ParamStore
    from sitl_emu.vehicle.vehicle import Vehicle

log = logging.getLogger(__name__)

# Default --batch-ms (simulated ms between wake-ups). PX4's mavlink main loop sleeps between 1.5 and 10 ms
# (src/modules/mavlink/mavlink_main.h MAVLINK_MIN_INTERVAL / MAVLINK_MAX_INTERVAL, "hard limit to 100 Hz at least" in
# mavlink_main.cpp): 10 ms keeps telemetry within PX4's own slowest loop period, and every tick is still computed.
DEFAULT_BATCH_MS = 10.0
MIN_BATCH_WALL_S = 0.001  # batching never wakes more than 1000 times a wall second (high --speed)
PORT = WholeRange(0, PORT_MAX)
SHUTDOWN_LINE = "PX4 Exiting..."  # what PX4 SITL prints on Ctrl-C or SIGTERM (platforms/posix/src/px4/common/main.cpp)


def wake_period_s(batch_ms: float, speed: float) -> float:
    """The runner's least wall time between wake-ups for --batch-ms (simulated ms) at --speed; 0: every tick.

    At a high speed a few simulated ms are a tiny wall time; waking more than 1000 times a second would spend the
    CPU on wake-ups (measured: at --speed 60 the vehicle kept only x50) while no client reacts faster than that.
    """
    if batch_ms <= 0:
        return 0.0
    period_s = batch_ms / 1000.0 / speed
    return period_s if period_s > MIN_BATCH_WALL_S else MIN_BATCH_WALL_S


def read_params_file(path: Path) -> list[tuple[str, float, str]]:
    """(name, value, where) from lines `NAME VALUE`, or QGC .params lines `SYSID COMPID NAME VALUE TYPE`; '#' starts
    a comment; `where` is FILE:LINE for messages."""
    from sitl_emu.params.store import ParamFileError, read_file

    try:
        return read_file(path)
    except ParamFileError as err:
        raise UsageProblem(str(err)) from None


def parse_assignments(assignments: tuple[str, ...]) -> list[tuple[str, float, str]]:
    from sitl_emu.params.store import ParamFileError, parse_value

    entries = []
    for item in assignments:
        name, sep, value = item.partition("=")
        if not sep or not name:
            raise UsageProblem(f"--param must look like NAME=VALUE (for example MIS_TAKEOFF_ALT=5), not '{item}'.")
        try:
            entries.append((name.strip(), parse_value(name.strip(), value.strip(), "--param"), "--param"))
        except ParamFileError as err:
            raise UsageProblem(str(err)) from None
    return entries


def apply_params(registry: ParamRegistry, entries: list[tuple[str, float, str]]) -> None:
    from sitl_emu.params import ParamError
    from sitl_emu.params.store import apply_entry

    for entry in entries:
        try:
            apply_entry(registry, entry)
        except ParamError as err:
            raise UsageProblem(str(err)) from None


def build_params(params_file: Path | None, assignments: tuple[str, ...]) -> ParamRegistry:
    """A registry with the file's values and then the --param ones (no persistence: see stored_params)."""
    from sitl_emu.params import default_registry

    registry = default_registry()
    if params_file is not None and not params_file.parent.is_dir():
        raise UsageProblem(f"--params {params_file}: the folder {params_file.parent} does not exist, so the vehicle "
                           "could not save its parameters there; create it or choose another file.")
    entries = read_params_file(params_file) if params_file is not None and params_file.exists() else []
    apply_params(registry, entries + parse_assignments(assignments))
    return registry


def param_file_path(params_file: Path | None, instance: int, first: int) -> Path:
    """Vehicle `instance`'s parameter file (stored_params' rule): what its FTP root shows beside log/."""
    from sitl_emu.params.store import DEFAULT_FILE, instance_path

    base = params_file if params_file is not None else Path(DEFAULT_FILE)
    return instance_path(base, instance, first if params_file is not None else 0)


def stored_params(params_file: Path | None, instance: int, first: int,
                  reset: bool) -> tuple[ParamRegistry, ParamStore, str | None]:
    """Vehicle `instance`'s registry with its saved values, its ParamStore, and a warning sentence (or None).

    The file is --params FILE, or parameters.params in the working directory (PX4 SITL's parameters.bson);
    other vehicles of a --count get `<stem>-<instance><suffix>` beside it (params/store.py instance_path). A missing
    file starts from the defaults (with --params FILE and --count, from FILE's values). --params-reset ignores it.
    A bad --params FILE is the user's mistake (UsageProblem, as before); a bad default file is a warning.
    """
    from sitl_emu.params import default_registry
    from sitl_emu.params.store import DEFAULT_FILE, ParamStore

    registry = default_registry()
    base = params_file if params_file is not None else Path(DEFAULT_FILE)
    store = ParamStore(registry, param_file_path(params_file, instance, first), instance + 1)
    if reset:
        return registry, store, None
    if params_file is None:
        return registry, store, store.load()
    source = store.path if store.path.exists() else base
    if not source.exists():
        return registry, store, (f"{store.path} does not exist yet, so vehicle {instance + 1} starts from the "
                                 "defaults and saves its changes there.")
    apply_params(registry, read_params_file(source))
    store.mark_saved()
    return registry, store, None


def build_vehicle(params: ParamRegistry, home: tuple[float, float, float] | None, seed: int, sysid: int,
                  wind: WindSettings | None = None) -> Vehicle:
    from sitl_emu.vehicle.vehicle import Vehicle

    if "MAV_SYS_ID" in params:  # rcS: param set MAV_SYS_ID $((px4_instance+1))
        with contextlib.suppress(ValueError):  # ParamError: outside MAV_SYS_ID's range
            params.set("MAV_SYS_ID", sysid)
    kwargs: dict[str, Any] = {"params": params, "seed": seed, "sysid": sysid}
    if wind is not None:
        kwargs["wind"] = wind
    if home is not None:
        kwargs["home"] = home
    return Vehicle(**kwargs)


def _wind_option(text: str | None) -> WindSettings | None:
    """--wind SPEED@FROM[,TURBULENCE] -> WindSettings (sitl_emu/disturbance/wind.py), None without it."""
    if text is None:
        return None
    from sitl_emu.disturbance.wind import parse_wind

    try:
        return parse_wind(text)
    except ValueError as err:
        raise UsageProblem(f"--wind: {err}") from None


@click.group(name=TOOL, cls=OneLineGroup, version_message=VERSION_MESSAGE, context_settings=CONTEXT)
@click.version_option(package_name="joyfly", prog_name=TOOL, message=VERSION_MESSAGE)
@click.option("-v", "--verbose", count=True, help="More log output (-v info, -vv debug).")
@click.pass_context
def main(ctx: click.Context, verbose: int) -> None:
    """A PX4-protocol quadrotor emulator speaking MAVLink over UDP."""
    level = logging.WARNING - 10 * min(verbose, 2)
    logging.basicConfig(level=level, format="%(levelname)s %(name)s: %(message)s")
    if ctx.invoked_subcommand != "serve":
        EARLY.release()  # serve owns SIGINT and SIGTERM (sitl_emu/cli/signals.py); the others, as inherited


@main.command(short_help="Run emulated PX4 quadrotors on UDP.")
@click.option("--port", type=PORT, default=14557, show_default=True,
              help="API (onboard) link listen port; 0 picks a free one.")
@click.option("--remote", default="127.0.0.1:14540", show_default=True, help="API link initial destination.")
@click.option("--gcs-port", type=PORT, default=18570, show_default=True,
              help="GCS link listen port; 0 picks a free one.")
@click.option("--gcs-remote", default="127.0.0.1:14550", show_default=True, help="GCS link initial destination.")
@click.option("--bind", "bind_host", default="127.0.0.1", show_default=True, help="Address to listen on.")
@click.option("--instance", type=WholeRange(0, MAX_SYSID - 1), default=0, show_default=True,
              help="Vehicle instance N: sysid N+1 and every port offset by N, as PX4's -i.")
@click.option("--speed", type=FiniteRange(SPEED_MIN, SPEED_MAX), default=1.0, show_default=True,
              help="Simulated seconds per wall second. A joyfly flying this vehicle needs the same factor: "
                   "joyfly fly --speed N (it warns when they differ).")
@click.option("--count", type=WholeRange(1, MAX_SYSID - 1), default=1, show_default=True,
              help="Number of vehicles: instances --instance.., sysids and ports offset per vehicle, homes 3 m apart.")
@click.option("--batch-ms", type=FiniteRange(0, 1000), default=DEFAULT_BATCH_MS, show_default=True,
              help="Wake at most every N ms of simulated time and run the ticks due in one batch (each message "
                   "still stamped at its own tick; input wakes the vehicle at once). The default wakes ~100 times a "
                   "simulated second, as PX4's mavlink loop at its slowest (MAVLINK_MAX_INTERVAL 10 ms), for about a "
                   "quarter less CPU than waking for every 4 ms tick; at most 1000 wake-ups a wall second at a high "
                   "--speed; 0 wakes for every tick, as PX4 SITL.")
@click.option("--home", default=None, help="Home as LAT,LON,ALT (deg, deg, m AMSL).")
@click.option("--param", "assignments", multiple=True, metavar="NAME=VALUE", help="Set a parameter (repeatable).")
@click.option("--params", "params_file", type=click.Path(path_type=Path), default=None,
              help="Parameter file, loaded at start and saved after every change (QGC .params format; lines 'NAME "
                   "VALUE' are read too). Default: parameters.params in the working directory (parameters-N.params "
                   "for instance N), as PX4 SITL keeps parameters.bson.")
@click.option("--params-reset", is_flag=True,
              help="Start from PX4's defaults: ignore the saved parameters (the file is overwritten).")
@click.option("--seed", type=WholeRange(0, SEED_MAX), default=0, show_default=True,
              help="Random seed for the sensor noise: the same seed, parameters and inputs fly the same trajectory.")
@click.option("--no-console", is_flag=True, help="Do not start the pxh> console even on a terminal.")
@click.option("--wind", "wind_text", default=None, metavar="SPEED@FROM[,TURBULENCE]",
              help="Wind: SPEED m/s blowing FROM degrees (5@270: 5 m/s from the west), optionally Dryden "
                   "turbulence: light, moderate, severe or the 20 ft wind speed W20 in m/s (5@270,light). Seeded "
                   "by --seed; SIH_WIND_N/E add to it.")
@click.option("--log-dir", type=click.Path(path_type=Path), default=DEFAULT_LOG_DIR, show_default=True,
              help="Write a ULog file per flight, from arming to disarming, as PX4 SITL does (DIR/YYYY-MM-DD/"
                   "HH_MM_SS.ulg, the vehicle's UTC time; DIR-N for instance N of a --count), and serve them to "
                   "ground stations' log download.")
@click.option("--no-log", is_flag=True, help="Write no flight logs.")
@click.option("--signing-key", "signing_key", type=click.Path(path_type=Path), default=None, metavar="FILE",
              help="Start with MAVLink 2 signing on, with the 32-byte key in FILE (64 hex digits or raw bytes), "
                   "stored as PX4 stores a SETUP_SIGNING key (mavlink/mavlink-signing-key.bin here); without it a "
                   "key stored there earlier is used.")
@view_options
@owning_signals  # SIGINT and SIGTERM end serve from its first line, whatever its phase (sitl_emu/cli/signals.py)
def serve(port: int, remote: str, gcs_port: int, gcs_remote: str, bind_host: str, instance: int, speed: float,
          count: int, batch_ms: float, home: str | None, assignments: tuple[str, ...], params_file: Path | None,
          params_reset: bool, seed: int, no_console: bool, wind_text: str | None, log_dir: Path, no_log: bool,
          signing_key: Path | None, signals: ShutdownSignals, **view: Any) -> None:
    """Run one emulated PX4 quadrotor (or --count of them) with its API and GCS MAVLink links."""
    try:
        check_view(view)
        check_host(bind_host, "--bind")
        api_remote = parse_address(remote, "--remote")
        settings = LinkSettings(bind_host, port, api_remote, gcs_port, parse_address(gcs_remote, "--gcs-remote"))
        home_lla = parse_home(home) if home else DEFAULT_HOME
        wind = _wind_option(wind_text)
        check_instances(instance, count, {"--port": port, "--gcs-port": gcs_port}, api_remote[1])
        check_own_ports([settings.for_instance(i) for i in range(instance, instance + count)])
        build_params(None if params_reset else params_file, assignments)  # a bad one: one sentence, no port open
        key = read_signing_key(signing_key) if signing_key is not None else None
        if signals.received:  # SIGINT or SIGTERM during the imports or the checks: no port is opened
            _say_exiting()
            return
        stores: list[ParamStore] = []
        vehicles: list[Vehicle] = []

        def vehicle(i: int, h: tuple[float, float, float]) -> Vehicle:
            registry, store, warning = stored_params(params_file, i, instance, params_reset)
            if warning:
                click.echo(f"{TOOL}: {warning}", err=True)
            built = build_vehicle(registry, h, seed + i - instance, i + 1, wind)
            store.mark_saved()  # PX4's rcS sets MAV_SYS_ID at every boot: nothing to save for that
            apply_params(registry, parse_assignments(assignments))  # saved like any change (PX4's `param set`)
            if params_reset and store.path.exists():
                _save_or_fail(store)  # the saved values are gone: the next start is from the defaults too
            stores.append(store)
            vehicles.append(built)
            return built

        nodes = build_nodes(count, settings, vehicle, first_instance=instance, home=home_lla,
                            epoch_unix_us=int(time.time() * 1e6),
                            handlers_for=None if no_log else handlers_by_instance(
                                log_dir, instance, lambda i: param_file_path(params_file, i, instance)))
        _sign(nodes, instance, key)
    except (UsageProblem, PortInUseError, SigningKeyError) as err:
        raise UserError(str(err)) from None
    loggers = [] if no_log else attach_loggers(nodes, log_dir, instance)
    runner = RealTimeRunner(nodes, speed=speed) if count == 1 else SwarmRunner(nodes, speed=speed)
    runner.min_wake_s = wake_period_s(batch_ms, speed)
    signals.stop_with(runner.stop)  # a signal from now on (or one already received) stops the loop, or never starts it
    up = [f"sitl-emu: PX4 quadrotor sysid {node.sysid}: {node.describe()}" for node in nodes]
    click.echo("\n".join([*up, f"sitl-emu: {build_line()}"]))  # the build after the vehicles, which scripts read first
    sys.stdout.flush()
    runner.hooks.extend(store.autosave for store in stores)  # PX4 saves shortly after every change (param_autosave)
    live = None if runner.stopped else start_view(vehicles, nodes, view, runner)
    console = None if runner.stopped else attach_console(vehicles, runner, not no_console)
    try:
        _run_until_signalled(runner, console, signals)
    finally:
        if live is not None:
            live.close()
        for logger in loggers:
            logger.close()  # a flight cut short keeps its log up to here
    _close_all(nodes, stores)


def _sign(nodes: list[VehicleNode], instance: int, key: bytes | None) -> None:
    """Each vehicle's signing key (cli/signing_key.py); the nodes are closed if it cannot be stored."""
    try:
        warnings = attach_signing(nodes, instance, key)
    except UsageProblem:
        for node in nodes:
            node.close()
        raise
    for warning in warnings:
        click.echo(f"{TOOL}: {warning}", err=True)


def _close_all(nodes: list[VehicleNode], stores: list[ParamStore]) -> None:
    for node in nodes:
        node.close()
    _save_all(stores)


def _save_or_fail(store: ParamStore) -> None:
    try:
        store.save()
    except OSError as err:
        raise UsageProblem(f"Cannot write the parameter file {store.path}: {err.strerror}.") from None


def _save_all(stores: list[ParamStore]) -> None:
    for store in stores:
        if store.unsaved:
            try:
                store.save()
            except OSError as err:
                click.echo(f"{TOOL}: cannot save the parameters to {store.path}: {err.strerror}.", err=True)


def _run_until_signalled(runner: RealTimeRunner, console: Console | None, signals: ShutdownSignals) -> None:
    """Run until `shutdown`, SIGTERM or Ctrl-C; on a signal print PX4's "PX4 Exiting..." (main.cpp sig_int_handler,
    with its leading newline that ends the prompt line)."""
    runner.run()
    if console is not None:
        console.stop()
    if signals.received:
        _say_exiting()


def _say_exiting() -> None:
    with contextlib.suppress(OSError, ValueError):  # stdout already gone: nothing to tell
        click.echo(f"\n{SHUTDOWN_LINE}")
        sys.stdout.flush()


main.add_command(campaign)  # sitl_emu/campaign/cli.py (issue 16)
main.add_command(log_command)  # sitl_emu/log/cli.py (issue 15)


if __name__ == "__main__":
    main()
