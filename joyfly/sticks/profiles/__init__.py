"""Controller profiles: which axis and button does what on a given controller, matched by its name.

profile.py (`Profile`, the built-in layouts (every gamepad flies "mode 2"), TOML overrides, the sticks-at-rest
check), user.py (the profiles the user wrote, one TOML file per device, looked up before the built-in ones),
calibrate.py (the wizard of `joyfly joystick calibrate`: it learns a layout from the pilot's hands, for any source).

May import: joyfly.types and js/events.py (the joystick errors and the axis range). Never a source, the link or the
session.
"""
