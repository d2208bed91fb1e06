"""The mavlink module, after PX4 src/modules/mavlink: each vehicle's links, what they receive and what they send.

Here: endpoint.py (one link: parse, dispatch, stream; HANDLER_CLASSES lists the protocols), context.py (what a
handler sees of its link and vehicle), link.py (the UDP socket, PX4's partner latching) with link_errors.py,
receiver.py (a message in -> a typed input for the vehicle; mavlink_receiver.cpp) with setpoints.py (the offboard
setpoints), link_commands.py (the commands the mavlink module answers itself), version.py (AUTOPILOT_VERSION,
PROTOCOL_VERSION). Below: protocols/ (mission, params, ftp, log, shell), telemetry/ (the streams and their message
builders), wire/ (the encoder and the messages pymavlink lacks).

May import: the kernel, params/, navigator/ (the stored plans), console/shell.py (the MAVLink shell), and the
vehicle only through the LinkVehicle protocol (context.py; the Vehicle class for type checks only). Never runtime/,
testing/ or the command line.
"""
