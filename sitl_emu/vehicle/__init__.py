"""The vehicle: the ONE deterministic step over simulated time and what it joins together.

vehicle.py (Vehicle.step, snapshot(): what the MAVLink side reads), control_chain.py (mode executor -> control
cascade -> land detector, with their inputs), faults.py (wind, estimator noise, injected failures, battery and the
GCS-link watchdog applied each tick), fence.py (the geofence hooked to the stored plans and the commander) +
rtl_avoidance.py (Return's way around it, as navigator_main.cpp and rtl.cpp drive the planner), land_detector.py (PX4
src/modules/land_detector: MulticopterLandDetector).

In PX4 these are the parts a px4_sitl instance wires together through uORB (the SIH simulator, commander, navigator,
flight_mode_manager, the controllers, land_detector); here one object owns them and steps them in a fixed order.
May import: the kernel (px4, types, geo, physics), params/, control/, disturbance/, commander/, navigator/,
flight_tasks/, motion_planning/. Never mavlink/, runtime/, testing/, the faces, or a clock: it takes `now_us`.
"""
