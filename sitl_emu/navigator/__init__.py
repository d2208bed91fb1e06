"""The navigator, after PX4 src/modules/navigator: the stored plans and where the auto modes go next.

mission_store.py (PX4 dataman: the mission, fence and rally plans, replaced whole), mission.py (AUTO.MISSION: the
current item, reached, jumps, the end; mission.cpp, mission_base.cpp, mission_block.cpp), mission_items.py (the stored
items as the navigator flies them), return_path.py (the mission as Return flies it, back or on to its landing:
rtl_mission_fast_reverse.cpp, rtl_mission_fast.cpp, rtl_direct_mission_land.cpp), geofence.py (the fence and its point
tests; geofence.cpp), geofence_monitor.py (the breach check every 200 ms), rally.py (RTL's destination: home, a rally
point or the mission's landing; rtl.cpp), geofence_avoidance.py with planner_polygons.py (Return's way around the fence:
geofence_avoidance_planner.cpp, lib/geofence), commands.py (what a command asks of the navigator: takeoff altitude,
reposition, altitude change, orbit), setpoint.py (what the navigator and the flight tasks share: NavInput, the vehicle's
state as they read it, and SetpointType, position_setpoint.type).

May import: the kernel (px4, types, geo), params/, motion_planning/, control/takeoff.py (takeoff_status). Never
vehicle/, commander/, flight_tasks/, mavlink/, runtime/, the faces, or a clock.
"""
