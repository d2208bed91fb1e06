"""The parameter registry and PX4's parameters.

`default_registry()` gives every PX4 parameter (sitl_emu/params/px4_params.csv, PX4's order and defaults; their
ranges, units and descriptions in px4_param_meta.csv) plus the emulator's own definitions of the parameters its code
reads by name (`defs/<domain>.py`, one module per domain, exporting `PARAMS: list[ParamDef]`; add a new module's name
to catalog.DOMAINS). catalog.py says how they are reconciled.
"""

from __future__ import annotations

from sitl_emu.params.catalog import emulator_definitions, px4_catalog
from sitl_emu.params.registry import ParamDef, ParamError, ParamRegistry, ParamType, integer, real

__all__ = ["ParamDef", "ParamError", "ParamRegistry", "ParamType", "all_definitions", "default_registry", "integer",
           "real"]


def all_definitions() -> list[ParamDef]:
    """The emulator's own definitions (the parameters its code reads by name)."""
    return emulator_definitions()


def default_registry() -> ParamRegistry:
    """A fresh registry at the defaults: PX4's list used (listed), the emulator's other definitions known."""
    cat = px4_catalog()
    return ParamRegistry(cat.defs, used=cat.used)
