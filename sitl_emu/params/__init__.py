"""The parameter registry and PX4's parameter definitions.

Each domain owns one `defs_<domain>.py` module exporting `PARAMS: list[ParamDef]`; add a new module's name to
`_DOMAINS` below.
"""

from __future__ import annotations

import importlib

from sitl_emu.params.registry import ParamDef, ParamError, ParamRegistry, ParamType, integer, real

__all__ = ["ParamDef", "ParamError", "ParamRegistry", "ParamType", "default_registry", "integer", "real"]

_DOMAINS = ("sih", "mpc", "mc", "commander", "navigator", "system")


def all_definitions() -> list[ParamDef]:
    defs: list[ParamDef] = []
    for domain in _DOMAINS:
        try:
            module = importlib.import_module(f"sitl_emu.params.defs_{domain}")
        except ModuleNotFoundError as err:
            if err.name != f"sitl_emu.params.defs_{domain}":
                raise
            continue
        defs.extend(module.PARAMS)
    return defs


def default_registry() -> ParamRegistry:
    return ParamRegistry(all_definitions())
