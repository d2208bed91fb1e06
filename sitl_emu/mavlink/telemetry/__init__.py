"""The streams and their message builders: a VehicleSnapshot in, MAVLink messages out.

After PX4 src/modules/mavlink/streams and mavlink_main.cpp's stream configuration: streams.py (which message at
which rate on each link, the stream phases), messages.py (attitude, position, status and the like), health.py
(SYS_STATUS, EXTENDED_SYS_STATE, MISSION_CURRENT, events), actuators.py, sensors.py, modes.py (AVAILABLE_MODES,
on request), fields.py (the float-to-integer conversions they share).

May import: the kernel (px4, types, control/qmath's float helpers), mavlink/context.py, mavlink/version.py,
mavlink/wire/ and protocols/mission_items.py (MISSION_CURRENT's fields). Pure builders: no socket, no clock.
"""
