"""The one style of joyfly's user errors: one line `joyfly: <what is wrong and what to do>` on stderr, a non-zero
exit status, no traceback; click's own usage errors too (`OneLineGroup` turns them into `UserError`).

sitl_emu/cli/options.py does the same for `sitl-emu` (joyfly imports sitl_emu only to run the demo's emulator, and
sitl_emu never imports joyfly: ARCHITECTURE.md); change both.
"""

from __future__ import annotations

import importlib.metadata
import math
from typing import IO, Any

import click

TOOL = "joyfly"
CONTEXT = {"help_option_names": ["-h", "--help"]}


class UserError(click.ClickException):
    """A mistake the user can fix, shown as one line `joyfly: sentence` on stderr; exit status 2."""

    exit_code = 2

    def show(self, file: IO[Any] | None = None) -> None:
        click.echo(f"{TOOL}: {self.message}", err=True)


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


VERSION_MESSAGE = "%(prog)s %(version)s"  # what --version prints, on the tool and on each of its commands


def _show_version(ctx: click.Context, param: click.Parameter, value: bool) -> None:
    if value and not ctx.resilient_parsing:
        click.echo(VERSION_MESSAGE % {"prog": TOOL, "version": importlib.metadata.version("joyfly")})
        ctx.exit()


def version_option() -> click.Option:
    """--version as on the tool itself, for one of its commands."""
    return click.Option(["--version"], is_flag=True, expose_value=False, is_eager=True, callback=_show_version,
                        help="Show the version and exit.")


class OneLineGroup(click.Group):
    """A click group whose errors, click's usage errors included, are one line (`UserError`); each command added to
    it takes --version too, as the tool does."""

    def add_command(self, cmd: click.Command, name: str | None = None) -> None:
        if not any("--version" in param.opts for param in cmd.params):
            cmd.params.append(version_option())
        super().add_command(cmd, name)

    def make_context(self, info_name: str | None, args: list[str], parent: click.Context | None = None,
                     **extra: Any) -> click.Context:
        try:
            return super().make_context(info_name, args, parent, **extra)
        except UserError:
            raise
        except click.ClickException as err:
            raise one_line(err) from None

    def invoke(self, ctx: click.Context) -> Any:
        try:
            return super().invoke(ctx)
        except UserError:
            raise
        except click.ClickException as err:
            raise one_line(err) from None


class FiniteRange(click.FloatRange):
    """click.FloatRange that also refuses nan (nan compares false with both bounds, so FloatRange lets it through)."""

    name = "float"

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        number = super().convert(value, param, ctx)
        if not math.isfinite(number):
            self.fail(f"{value!r} is not a number from {self.min:g} to {self.max:g}.", param, ctx)
        return number
