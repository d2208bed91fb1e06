"""The Linux joystick (js) API read directly (no SDL, no evdev): devices, FIFOs, ptys and raw captures.

reader.py (`open_joystick`: js devices by path or number, FIFOs, and the virtual kinds by prefix; it needs `fcntl`
for the joystick ioctls), events.py (the 8-byte js_event records, the state they build, the check that tells them
from other bytes, and the joystick errors every source raises), seam.py (the one platform seam: joyfly imports
reader.py only through it, so that where there is no `fcntl` SDL and the virtual joysticks still work),
raw_capture.py (`raw:FILE`: a capture of js_event records, checked whole and played back).

May import: joyfly.types and sticks/virtual.py. Elsewhere in joyfly, reader.py is loaded only through seam.py.
"""
