"""The commander, after PX4 src/modules/commander: who may fly, in which mode, and what happens when things fail.

commander.py (arming, the mode the user asked for vs the mode in force, auto-disarm), settings.py (its parameters as
plain settings), commands.py (vehicle_command -> ACK and PX4 texts), arming.py (HealthAndArmingChecks: what a mode
needs to run or arm), mode_intention.py, failsafe.py (src/modules/commander/failsafe: the fallback mode, the worst
action wins) with fault_failsafes.py (battery, failures, link loss) and geofence_failsafe.py (GF_ACTION),
offboard.py and manual_control.py (what keeps OFFBOARD and the sticks alive and what their loss does),
stick_gestures.py (arm/disarm gestures, a pilot taking over), battery.py (the battery model and its warnings),
failure_injection.py (src/systemcmds/failure and the FailureDetector rules), health_report.py
(HealthAndArmingChecks' report: the failing checks, can_arm / can_run per mode, when it goes out) and notices.py
(the PX4 events the commander sends without a text).

May import: the kernel (px4, types, geo), params/, control/ (plain maths), navigator/ (the stored plans, the fence
result, navigator requests), events/ (PX4's event definitions). Never vehicle/, flight_tasks/, mavlink/, runtime/,
the faces, or a clock.
"""
