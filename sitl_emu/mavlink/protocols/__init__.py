"""The MAVLink microservices, one module per protocol, each a Handler listed in endpoint.HANDLER_CLASSES.

After PX4 src/modules/mavlink: mission.py (mavlink_mission.cpp: upload, download, clear, current, for mission,
fence and rally) with mission_items.py (its item checks) and command_params.py (mavlink_command_params.hpp: the
params each command may carry), params.py (mavlink_parameters.cpp), ftp.py
(mavlink_ftp.cpp) with ftp_sandbox.py (its root), log.py (mavlink_log_handler.cpp: LOG_REQUEST_*), shell.py
(mavlink_shell.cpp: SERIAL_CONTROL to the pxh> shell), events.py (mavlink_events.cpp: EVENT, CURRENT_EVENT_SEQUENCE,
REQUEST_EVENT), component_metadata.py (streams/COMPONENT_METADATA.hpp and the metadata files FTP serves; not a
Handler: link_commands.py answers the request, ftp.py mounts the files).

May import: the kernel, params/, events/, navigator/ (the stored plans), console/shell.py (the shell),
mavlink/context.py and mavlink/wire/. Never runtime/, testing/ or the other faces.
"""
