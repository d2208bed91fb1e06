"""The navigator, after PX4 src/modules/navigator: the stored plans and where the auto modes go next.

mission_store.py (PX4 dataman: the mission, fence and rally plans, replaced whole), mission.py (AUTO.MISSION: the
current item, reached, jumps, the end; mission.cpp, mission_base.cpp, mission_block.cpp), mission_items.py (the
stored items as the navigator flies them), geofence.py (the fence and its point tests; geofence.cpp),
geofence_monitor.py (the breach check every 200 ms), rally.py (RTL's destination; rtl.cpp), commands.py (what a
command asks of the navigator: takeoff altitude, reposition, altitude change, orbit).

May import: the kernel (px4, types, geo), params/, motion_planning/, and flight_tasks/core.py (the task inputs the
mission progression reads). Never vehicle/, commander/, mavlink/, runtime/, the faces, or a clock.
"""
