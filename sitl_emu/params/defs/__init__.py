"""The emulator's own definitions of the PX4 parameters its code reads by name, one module per domain.

Each module exports `PARAMS: list[ParamDef]` with PX4's type, default, bounds and unit; catalog.DOMAINS lists the
modules and catalog.py reconciles them with PX4's list (px4_params.csv). Domains follow PX4's parameter groups:
sih, mpc, mc, commander, navigator, system, faults.

May import: params/registry.py, and px4common/manual_defaults.py (PX4's defaults joyfly models too).
"""
