"""What both programs of this distribution need, in one place: sitl_emu (the emulated PX4) and joyfly (its client).

modes.py (PX4's custom_mode: main and sub mode numbers, their layout in HEARTBEAT.custom_mode, their names),
results.py (MAV_RESULT, the COMMAND_ACK result), cli_style.py (the one style of user errors of both command lines),
clock.py (the wall clock, plain or sped up to pair with an emulator run at --speed), manual_defaults.py (PX4's
defaults of the stick parameters the emulator flies with and joyfly's manual fence models), signing_key.py (the
MAVLink 2 signing key file both `--signing-key` options read).

Small and a leaf: it imports neither sitl_emu nor joyfly nor flightview (tests/test_architecture.py), and only the
two programs import it. A fact belongs here only when both programs need it; sitl_emu/px4.py keeps the rest of
PX4's numbering.
"""
