"""Trajectory and heading smoothing, after PX4 src/lib/motion_planning.

smoothing.py (VelocitySmoothing, PositionSmoothing, TrajMath, TrajectoryConstraints: jerk- and acceleration-limited
trajectories to a waypoint or along a mission leg), heading.py (HeadingSmoothing: the auto modes' heading).

Pure library code: may import the kernel (types) and control/qmath.py only.
"""
