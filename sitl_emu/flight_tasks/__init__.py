"""The flight tasks, after PX4 src/modules/flight_mode_manager: one module per task, each turning a mode into setpoints.

core.py (the shared machinery: settings, the base Task, FlightTaskAuto's core; the tasks' input is
navigator/setpoint.py's NavInput), auto.py (takeoff, hold, land, reposition: tasks/Auto with navigator takeoff.cpp,
loiter.cpp, land.cpp), rtl.py (return: rtl_direct.cpp), rtl_mission.py (RTL_TYPE's choice of return; the mission
flown back or on to its landing, or its landing flown from its start: rtl_mission_fast_reverse.cpp,
rtl_mission_fast.cpp, rtl_direct_mission_land.cpp), mission.py (AUTO.MISSION flown
from the navigator's items), orbit.py (tasks/Orbit), follow.py (tasks/AutoFollowTarget) with follow_estimator.py (its
target estimator), manual.py (tasks/ManualAltitude, ManualPosition) with sticks.py (StickAccelerationXY, StickYaw,
the expo curves), stabilized.py (Stabilized: sticks -> attitude and thrust), mode_executor.py (FlightModeManager:
which task runs for the mode in force and which setpoint drives the controllers).

May import: the kernel (px4, types, geo), params/, control/ (plain maths, takeoff state), motion_planning/,
navigator/ (the plans, the mission progression, navigator requests, NavInput), commander/manual_control.py (the
centred sticks), px4common/manual_defaults.py. Never vehicle/, mavlink/, runtime/, the faces, or a clock.
"""
