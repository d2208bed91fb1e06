"""Disturbances acting on the vehicle: wind (mean, Dryden turbulence, discrete gusts) and estimator noise.

Pure and seeded: every random draw comes from a numpy Generator derived from the vehicle's seed; no clock, no MAVLink.
"""
