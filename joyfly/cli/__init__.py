"""The `joyfly` command line: the console script `joyfly = "joyfly.cli:main"` and `python -m joyfly` run `main`.

main.py (the click group `main`, `joyfly fly` and `joyfly demo`: options into the pieces, the run, the closing
words), joystick.py (`joyfly joystick list|test|profiles`: find joysticks and watch what they send), calibrate.py
(`joyfly joystick calibrate`: the wizard of sticks/profiles/calibrate.py on a terminal).

The outermost face: may import everything in joyfly, flightview and px4common; nothing in joyfly imports it.
"""

from joyfly.cli.main import main

__all__ = ["main"]
