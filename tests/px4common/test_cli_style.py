"""px4common's one style of user errors: one line naming the tool (the outermost group's name), exit 2 or 1, for
errors the command raises and for click's own, in subgroups too."""

from __future__ import annotations

import click
from click.testing import CliRunner

from px4common.cli_style import CONTEXT, FiniteRange, OneLineGroup, UserError, UserFailure, WholeRange


@click.group(name="tool-x", cls=OneLineGroup, context_settings=CONTEXT)
def tool() -> None:
    pass


@tool.command()
@click.option("--rate", type=FiniteRange(1, 10))
@click.option("--count", type=WholeRange(1, 3))
def run(rate: float | None, count: int | None) -> None:
    if rate == 5:
        raise UserError("rate 5 is taken; use another.")
    if rate == 6:
        raise UserFailure("the work failed.")


@tool.group(cls=OneLineGroup)
def sub() -> None:
    pass


@click.group("part", cls=OneLineGroup, tool="tool-x")
def part() -> None:
    pass


@part.command()
def work() -> None:
    raise UserError("part trouble.")


tool.add_command(part)


@sub.command()
def inner() -> None:
    raise UserError("inner trouble.")


def invoke(*args: str) -> tuple[int, str]:
    """(exit status, stderr) of a run that must end cleanly with nothing on stdout."""
    result = CliRunner().invoke(tool, list(args), prog_name="some-other-prog-name")
    assert isinstance(result.exception, SystemExit) and not result.stdout, (result.exception, result.stdout)
    return result.exit_code, result.stderr


def test_a_raised_user_error_is_one_line_naming_the_tool() -> None:
    assert invoke("run", "--rate", "5") == (2, "tool-x: rate 5 is taken; use another.\n")
    assert invoke("run", "--rate", "6") == (1, "tool-x: the work failed.\n")


def test_clicks_usage_errors_become_one_line_with_the_help_hint() -> None:
    code, text = invoke("run", "--rate", "nan")
    assert code == 2 and text.count("\n") == 1 and text.startswith("tool-x: ")
    assert "'nan' is not a number from 1 to 10" in text and "see 'some-other-prog-name run --help'" in text
    code, text = invoke("run", "--count", "1.5")
    assert code == 2 and text.startswith("tool-x: ") and "not a valid integer" in text
    code, text = invoke("nosuch")
    assert code == 2 and text.startswith("tool-x: ") and text.count("\n") == 1


def test_a_subgroups_errors_name_the_tool_not_the_subgroup() -> None:
    assert invoke("sub", "inner") == (2, "tool-x: inner trouble.\n")
    code, text = invoke("sub", "--bogus")
    assert code == 2 and text.startswith("tool-x: ") and text.count("\n") == 1
    assert invoke("part", "work") == (2, "tool-x: part trouble.\n")


def test_a_subgroup_run_alone_names_the_tool_it_says() -> None:
    result = CliRunner().invoke(part, ["work"])
    assert result.exit_code == 2 and result.stderr == "tool-x: part trouble.\n"
