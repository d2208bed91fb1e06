"""sitl_emu: a PX4-protocol quadrotor emulator speaking MAVLink."""

__version__ = "0.1.0"
