"""`sitl-emu campaign`: the command line of sitl_emu.campaign (sitl_emu/cli/main.py only lists this command)."""

from __future__ import annotations

import shlex
import sys
from collections.abc import Callable, Iterator
from contextlib import AbstractContextManager, contextmanager
from pathlib import Path
from typing import Any, NoReturn

import click

from px4common.cli_style import FiniteRange, UserError, WholeRange
from sitl_emu.cli.extras import in_clone
from sitl_emu.cli.options import SEED_MAX

__all__ = ["campaign"]

LIMIT = FiniteRange(0.001, 1e7)


@click.command(short_help="Fly a scenario over many cases; one results table.")
@click.argument("cases_file", metavar="[CASES.toml]", required=False, type=click.Path(path_type=Path))
@click.option("--scenario", metavar="REF", default=None,
              help="The scenario: module:function or path/to/file.py:function, a function (sim, case) returning "
                   "an Outcome; overrides the campaign file's `scenario`.")
@click.option("--out", default="campaign-results.csv", show_default=True, metavar="FILE.csv",
              help="Results: one CSV row per case, written as each finishes (and FILE.parquet when pyarrow is "
                   "installed), in a folder that exists; cases already in it are skipped; '-' writes no file.")
@click.option("--engine", type=click.Choice(["local", "ray", "serial"]), default="local", show_default=True,
              help=f"local: worker processes on this machine; ray: a Ray cluster (the ray extra: {in_clone('ray')}); "
                   "serial: this process, one case after another (for a debugger).")
@click.option("--workers", type=WholeRange(1, 4096), default=None,
              help="Worker processes (local; default: one per core) or CPUs of a Ray started here.")
@click.option("--address", default=None, help="Ray only: the address of an existing cluster (default: start one here).")
@click.option("--seed", "seeds", multiple=True, type=WholeRange(0, SEED_MAX),
              help="Without CASES.toml: one case per --seed (repeatable; default: seed 0).")
@click.option("--param", "assignments", multiple=True, metavar="NAME=VALUE",
              help="Without CASES.toml: a PX4 parameter in every case (repeatable).")
@click.option("--fault", "faults", multiple=True, metavar="NAME@SECONDS",
              help="Without CASES.toml: a timed fault in every case, e.g. gps_off@12 (repeatable).")
@click.option("--option", "options", multiple=True, metavar="NAME=VALUE",
              help="Without CASES.toml: an option for the scenario (and Sim, if it takes NAME); VALUE in TOML.")
@click.option("--sim-limit", type=LIMIT, default=None, help="Simulated seconds a case may take [default: 600].")
@click.option("--wall-limit", type=LIMIT, default=None, help="Wall seconds a case may take [default: 300].")
@click.option("--worst-by", metavar="METRIC", default=None, help="Rank the worst cases by this metric (largest "
                                                                 "first) [default: the first metric].")
@click.option("--no-progress", is_flag=True, help="No progress bar (without a terminal: no progress lines).")
def campaign(cases_file: Path | None, scenario: str | None, out: str, engine: str, workers: int | None,
             address: str | None, seeds: tuple[int, ...], assignments: tuple[str, ...], faults: tuple[str, ...],
             options: tuple[str, ...], sim_limit: float | None, wall_limit: float | None, worst_by: str | None,
             no_progress: bool) -> None:
    """Fly a scenario (your client against an in-process vehicle) over every case of CASES.toml, or over the cases
    the options give, on a pool of processes or Ray; write one row per case and print a summary with the command
    that reruns each failed case alone. Exit status 1 when a case failed. The file format: sitl_emu/campaign/spec.py.
    """
    from sitl_emu.campaign.errors import CampaignError, CampaignInterrupted
    from sitl_emu.campaign.progress import CampaignProgress
    from sitl_emu.campaign.run import run_campaign

    progress = None if no_progress else CampaignProgress()
    try:
        ref, cases, limits = _inputs(cases_file, scenario, seeds, assignments, faults, options, sim_limit, wall_limit)
        summary = run_campaign(ref, cases, None if out == "-" else out, engine=engine, workers=workers,
                               address=address, limits=limits,
                               progress=_announcing(progress.start if progress else None),
                               worst_by=worst_by, on_row=progress.row if progress else None)
    except CampaignError as err:
        raise UserError(str(err)) from None
    except CampaignInterrupted as stop:
        _interrupted(stop, out)
    click.echo(summary.text())
    if out != "-":
        click.echo(f"\nresults: {out}")
    if summary.passed < summary.total:
        sys.exit(1)


def _announcing(progress: Callable[[int], AbstractContextManager[Any]] | None,
                ) -> Callable[[int], AbstractContextManager[Any]]:
    """The progress display, started after a line that says which build the workers run (they import the same
    sitl_emu as this process): printed once the cases are checked, so that a mistake stays one line."""

    @contextmanager
    def start(total: int) -> Iterator[Any]:
        from sitl_emu._speedups import build_line

        click.echo(f"sitl-emu campaign: {build_line()}", err=True)
        if progress is None:
            yield None
        else:
            with progress(total) as bar:
                yield bar

    return start


def _inputs(cases_file: Path | None, scenario: str | None, seeds: tuple[int, ...], assignments: tuple[str, ...],
            faults: tuple[str, ...], options: tuple[str, ...], sim_limit: float | None,
            wall_limit: float | None) -> tuple[str, list[Any], Any]:
    from sitl_emu.campaign.errors import CampaignError
    from sitl_emu.campaign.scenario import Limits
    from sitl_emu.campaign.spec import read_spec

    if cases_file is not None:
        if seeds or assignments or faults or options:
            raise CampaignError("give the cases either in CASES.toml or with --seed, --param, --fault and "
                                "--option, not both.")
        spec = read_spec(cases_file)
        ref, cases, limits = scenario or spec.scenario, spec.cases, spec.limits
    else:
        ref, cases, limits = scenario, _cases_from_options(seeds, assignments, faults, options), Limits()
    if ref is None:
        raise CampaignError("no scenario: give --scenario module:function (or file.py:function), or `scenario` in "
                            "the campaign file.")
    limits = Limits(sim_limit if sim_limit is not None else limits.sim_s,
                    wall_limit if wall_limit is not None else limits.wall_s)
    return ref, cases, limits


def _cases_from_options(seeds: tuple[int, ...], assignments: tuple[str, ...], faults: tuple[str, ...],
                        options: tuple[str, ...]) -> list[Any]:
    from sitl_emu.campaign.cases import make_cases

    fixed: dict[str, Any] = {f"params.{k}": v for k, v in (_number_pair(a, "--param") for a in assignments)}
    fixed.update({f"options.{k}": v for k, v in (_toml_pair(o) for o in options)})
    fixed["faults"] = [_fault_pair(f) for f in faults]
    return make_cases(fixed, {"seed": list(seeds) or [0]})


def _number_pair(text: str, option: str) -> tuple[str, float]:
    from sitl_emu.campaign.errors import CampaignError

    name, sep, value = text.partition("=")
    try:
        if not sep or not name.strip():
            raise ValueError(text)
        return name.strip(), float(value)
    except ValueError:
        raise CampaignError(f"{option} must look like NAME=NUMBER (for example SIH_WIND_N=5), not '{text}'.") from None


def _toml_pair(text: str) -> tuple[str, Any]:
    from sitl_emu.campaign.errors import CampaignError
    from sitl_emu.campaign.spec import tomllib

    name, sep, value = text.partition("=")
    if not sep or not name.strip():
        raise CampaignError(f"--option must look like NAME=VALUE (for example side_m=5), not '{text}'.")
    try:
        return name.strip(), tomllib.loads(f"v = {value}")["v"]
    except tomllib.TOMLDecodeError:
        return name.strip(), value  # a bare word: the string itself


def _fault_pair(text: str) -> tuple[float, str]:
    from sitl_emu.campaign.errors import CampaignError

    name, _, at = text.rpartition("@")
    try:
        return float(at), name
    except ValueError:
        raise CampaignError(f"--fault must look like NAME@SECONDS (for example gps_off@12), not '{text}'.") from None


def _interrupted(stop: Any, out: str) -> NoReturn:
    """Ctrl-C: the summary of the cases finished so far and the command that flies the others (exit status 130)."""
    click.echo(f"interrupted (Ctrl-C) after {stop.flown} of the {stop.to_fly} cases this run was to fly.\n")
    click.echo(stop.summary.text())
    if out == "-":
        click.echo("\nno results file was written (--out -): a run with --out FILE.csv can be resumed.")
    else:
        click.echo(f"\nresults so far: {out}\nresume (the cases in {out} are not flown again):\n  "
                   f"{command_line(click.get_current_context())}")
    sys.exit(130)


def command_line(ctx: click.Context) -> str:
    """The command as given (defaults left out), with --out always: what resumes an interrupted campaign."""
    args = ctx.command_path.split()
    for param in ctx.command.params:
        value: Any = ctx.params.get(param.name or "")
        if isinstance(param, click.Argument):
            args += [str(value)] if value is not None else []
        elif isinstance(param, click.Option) and (param.name == "out" or value not in (None, False, (), param.default)):
            flag = param.opts[0]
            if param.is_flag:
                args.append(flag)
            else:
                items: tuple[Any, ...] = tuple(value) if param.multiple else (value,)
                for item in items:
                    args += [flag, str(item)]
    return shlex.join(args)
