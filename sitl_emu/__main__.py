"""The `sitl-emu` command (and `python -m sitl_emu`): SIGINT and SIGTERM are taken in hand before anything else is
imported (sitl_emu/cli/signals.py), then the CLI (sitl_emu/cli/main.py) runs."""

from __future__ import annotations

from sitl_emu.cli.signals import EARLY


def main() -> None:
    EARLY.install()
    from sitl_emu.cli.main import main as cli

    cli(prog_name="sitl-emu")


if __name__ == "__main__":
    main()
