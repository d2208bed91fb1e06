"""joyfly: fly a PX4 vehicle (real or emulated) with a joystick over MAVLink."""

__version__ = "0.1.0"
