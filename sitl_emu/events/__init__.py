"""PX4's events (src/lib/events, platforms/common/include/px4_platform_common/events.h, Tools/px4events): the typed
messages PX4 sends beside its STATUSTEXTs, which QGroundControl shows in its arming-check and health panels.

library.py (the id hash, log levels, argument packing), enums.py (PX4's event enums the emulator's events use),
definition.py (an event's definition and the event_s it sends), catalogue.py (the events the emulator emits: PX4's
name, message, arguments and levels, and which of the vehicle's texts each one goes with), failsafe_notices.py
(framework.cpp notifyUser's events) and health_events.py (the health and arming check report's), metadata.py (the
events metadata JSON a ground station decodes them with).
Imports only the kernel (px4.py, types.py); the commander sends the events no text tells, the vehicle keeps all of
them in order, and the MAVLink side (mavlink/protocols/events.py) sends them.
"""
