"""`python -m sitl_emu serve ...` runs the same CLI as `sitl-emu`."""

from __future__ import annotations

from sitl_emu.cli.main import main

if __name__ == "__main__":
    main(prog_name="sitl-emu")
