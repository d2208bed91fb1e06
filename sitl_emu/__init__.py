"""sitl_emu: a PX4-protocol quadrotor emulator speaking MAVLink."""

from sitl_emu._speedups import guard as _guard_speedups

__version__ = "0.1.0"

# Opt-in compiled build (`make speedups`): fall back to the .py sources, with a warning, if it is stale or foreign.
_guard_speedups()
