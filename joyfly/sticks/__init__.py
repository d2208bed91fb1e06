"""The stick side: a joystick read from any source, mapped into stick commands, and turned into what goes to the
vehicle (local-NED setpoints, MANUAL_CONTROL values).

sources.py (what `--joy` names, opened: `auto`, SDL devices, or the js reader; the profile a source flies with),
virtual.py (the virtual joysticks: `script:`, `replay:`, recordings), mapping.py (raw axes and buttons ->
StickCommand: deadzone, expo, holds), setpoints.py (sticks -> local-NED setpoints, the fence, the altitude band),
manual.py (sticks -> MANUAL_CONTROL values, the throttle interlock), manual_fence.py (the fence as stick limits in
PX4's manual modes), takeoff_check.py (can these sticks take off in Position/Altitude mode).
sdl/: joysticks and game controllers through SDL2. js/: the Linux joystick (js) API, FIFOs and raw captures.
profiles/: controller layouts (built in, the user's own, and the calibration wizard that writes them).

A new joystick source: a class meeting joyfly.types.JoystickSource in a module here (or a folder beside sdl/ and
js/), and its `--joy` prefix in sources.py's `open_source`.

May import: joyfly.types and px4common; never joyfly.link, joyfly.session or the face (tests/test_architecture.py).
"""
