"""The one style of user errors of both command lines (`sitl-emu`, `joyfly`): one line `<tool>: <what is wrong and
what to do>` on stderr, a non-zero exit status, no traceback; click's own usage errors too.

A program makes its click group a `OneLineGroup` named after the tool (`@click.group(name="joyfly",
cls=OneLineGroup)`) and raises `UserError` (exit status 2) or `UserFailure` (1) with one sentence. Every error leaving
a command passes through the group, which turns click's errors into `UserError` and names the tool on each. A
subgroup that is a OneLineGroup too says its tool (`@click.group("joystick", cls=OneLineGroup, tool="joyfly")`), so
its errors name the tool even when it runs alone; the outermost group has the last word. Each command added to a
OneLineGroup takes --version too, printing the group's `version_message` as the tool's own --version does.
"""

from __future__ import annotations

import importlib.metadata
import math
import os
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from typing import IO, Any

import click

CONTEXT = {"help_option_names": ["-h", "--help"]}
DISTRIBUTION = "joyfly"  # the distribution both tools come in: its version is theirs
VERSION_MESSAGE = "%(prog)s %(version)s"  # what --version prints, unless a group says otherwise


class UserError(click.ClickException):
    """A mistake the user can fix, shown as one line `<tool>: sentence` on stderr; exit status 2."""

    exit_code = 2

    def __init__(self, message: str) -> None:
        super().__init__(message)
        self.tool = os.path.basename(sys.argv[0]) if sys.argv and sys.argv[0] else "error"  # a group names it

    def show(self, file: IO[Any] | None = None) -> None:
        click.echo(f"{self.tool}: {self.message}", err=True)


class UserFailure(UserError):
    """The same with exit status 1 (click.ClickException's status: a command that could not do its work)."""

    exit_code = 1


def one_line(err: click.ClickException) -> UserError:
    """click's error as a UserError with its exit status; a usage error says where the help is."""
    text = " ".join(err.format_message().split())
    ctx = getattr(err, "ctx", None)
    if isinstance(err, click.UsageError) and ctx is not None:
        hint = f"see '{ctx.command_path} --help'"
        text = f"{text} ({hint})" if text.endswith("?") else f"{text.rstrip('.')} ({hint})."
    return UserFailure(text) if err.exit_code == 1 else UserError(text)


def version_option(tool: str, message: str = VERSION_MESSAGE) -> click.Option:
    """--version as on the tool itself, for one of its commands."""

    def show(ctx: click.Context, param: click.Parameter, value: bool) -> None:
        if value and not ctx.resilient_parsing:
            click.echo(message % {"prog": tool, "version": importlib.metadata.version(DISTRIBUTION)})
            ctx.exit()

    return click.Option(["--version"], is_flag=True, expose_value=False, is_eager=True, callback=show,
                        help="Show the version and exit.")


class OneLineGroup(click.Group):
    """A click group whose errors, click's usage errors included, are one line (`UserError`) naming the tool (`tool`,
    by default the group's name); each command added to it takes --version too, as the tool does."""

    def __init__(self, *args: Any, tool: str | None = None, version_message: str = VERSION_MESSAGE,
                 **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.tool = tool or self.name
        self.version_message = version_message

    def add_command(self, cmd: click.Command, name: str | None = None) -> None:
        if not any("--version" in param.opts for param in cmd.params):
            cmd.params.append(version_option(self.tool or "", self.version_message))
        super().add_command(cmd, name)

    def make_context(self, info_name: str | None, args: list[str], parent: click.Context | None = None,
                     **extra: Any) -> click.Context:
        with self._one_line_errors():
            return super().make_context(info_name, args, parent, **extra)

    def invoke(self, ctx: click.Context) -> Any:
        with self._one_line_errors():
            return super().invoke(ctx)

    @contextmanager
    def _one_line_errors(self) -> Iterator[None]:
        try:
            yield
        except UserError as err:
            err.tool = self.tool or err.tool  # the outermost group is the last to pass it on
            raise
        except click.ClickException as err:
            error = one_line(err)
            error.tool = self.tool or error.tool
            raise error from None


def describe_range(low: float | None, high: float | None) -> str:
    """A range as help texts and errors say it, in both programs: "0.1 to 100", "at least 0", "at most 5"."""
    def text(number: float | None) -> str:
        return format(number, ".15g")  # 100.0 as 100, 4294967295 in full

    if low is None:
        return f"at most {text(high)}"
    return f"at least {text(low)}" if high is None else f"{text(low)} to {text(high)}"


class WholeRange(click.IntRange):
    """click.IntRange that calls its values whole numbers ("not a valid integer", not "integer range"), and its range
    "0 to 65535" (click: "0<=x<=65535"), as joyfly's option help does."""

    name = "integer"

    def _describe_range(self) -> str:
        return describe_range(self.min, self.max)


class FiniteRange(click.FloatRange):
    """click.FloatRange that also refuses nan (nan compares false with both bounds, so FloatRange lets it through); its
    range reads "0.1 to 100" as WholeRange's."""

    name = "float"

    def _describe_range(self) -> str:
        return describe_range(self.min, self.max)

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        number = super().convert(value, param, ctx)
        if not math.isfinite(number):
            self.fail(f"{value!r} is not a number from {self.min:g} to {self.max:g}.", param, ctx)
        return number
