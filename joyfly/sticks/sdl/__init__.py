"""Joysticks and game controllers through SDL2 (pysdl2 over pysdl2-dll's SDL 2.32), as QGroundControl reads them.

api.py (the one seam to SDL: every SDL call joyfly makes goes through `SdlApi`, so tests drive it with SDL's own
virtual joysticks and a machine without SDL gets one sentence), source.py (`SdlSource`: `--joy sdl`, `sdl:N`,
`sdl:NAME`; hot-plug by GUID), mappings.py (`--sdl-mapping`, SDL_GAMECONTROLLERCONFIG and the config file's game
controller mappings), listing.py (what `joyfly joystick list` says of SDL's devices).

May import: joyfly.types, js/events.py (the joystick errors and the axis range every source uses), profiles/ and
sources.py (listing.py only: the profile a device would fly with). Never the link, the session or the face.
"""
