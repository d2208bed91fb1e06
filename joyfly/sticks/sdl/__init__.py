"""Joysticks and game controllers through SDL2, as QGroundControl reads them (pysdl2 over pysdl2-dll's SDL 2.32).

api.py (the one seam to SDL's calls: SdlApi; a machine without a loadable SDL gets SdlUnavailable), source.py (a
JoystickSource over an SDL game controller or joystick, hot-plug by GUID), mappings.py (--sdl-mapping: extra
game-controller mappings), listing.py (the lines `joyfly joystick list` prints for SDL's devices).

May import: joyfly.types and the rest of joyfly/sticks/ (profiles, mapping); never joyfly/link/ or joyfly/session/.
"""
