"""The pxh> `param` command (src/systemcmds/param/param.cpp, PX4 main): show, set, get, reset, reset_all, touch, save.

Output formats follow param.cpp: `param show` prints "x + NAME [index,used index] : value" lines (x: used, +: changed
from the default), the value followed by its unit where PX4's metadata gives one (our addition), and "N/M parameters
used."; `param set` prints "curr: old -> new". `param get` is our addition
(= `param show -q`). `param save` writes the vehicle's parameter file (sitl_emu/params/store.py) at once; PX4 saves
after every change anyway, and so does `sitl-emu serve`.
"""

from __future__ import annotations

import fnmatch
from pathlib import Path

from sitl_emu.params.registry import ParamError, ParamRegistry, ParamType
from sitl_emu.params.store import format_file

USAGE = """Usage: param <command> [arguments...]
 Commands:
   save          Save params to a file
     [<file>]    File name (use default if not given)
   show          Show parameter values
     [-a]        Show all parameters (not just used)
     [-c]        Show only changed params (unused too)
     [-q]        quiet mode, print only param value (name needs to be exact)
     [<filter>]  Filter by param name (wildcard at end allowed, eg. sys_*)
   set           Set parameter to a value
     <param_name> <value> Parameter name and value to set
     [fail]      If provided, let the command fail if param is not found
   get           Print a parameter's value (sitl_emu addition; same as show -q)
     <param_name> Parameter name
   touch         Mark a parameter as used
     [<param_name1> [<param_name2>]] Parameter name (one or more)
   reset         Reset only specified params to default
     [<param1> [<param2>]] Parameter names to reset (wildcard at end allowed)
   reset_all     Reset all params to default
     [<exclude1> [<exclude2>]] Do not reset matching params (wildcard at end allowed)
"""


def log_line(level: str, module: str, text: str) -> str:
    """One PX4 console log line, e.g. 'ERROR [param] Parameter X not found' (platforms/common/px4_log.cpp)."""
    return f"{level:<5} [{module}] {text}\n"


def param_command(registry: ParamRegistry, args: list[str], sysid: int = 1) -> tuple[int, str]:
    """Run `param <args>` on a vehicle's registry; (status, output)."""
    sub, rest = (args[0], args[1:]) if args else ("", [])
    if sub == "show":
        return _show(registry, rest)
    if sub == "set":
        if len(rest) < 2:
            name = rest[0] if rest else "PARAM_NAME"
            return 1, log_line("ERROR", "param", f"not enough arguments.\nTry 'param set {name} 3 [fail]'")
        return _set(registry, rest[0], rest[1], fail=rest[2:3] == ["fail"])
    if sub == "get" and len(rest) == 1:
        if rest[0] not in registry:
            return 1, log_line("ERROR", "param", f"Parameter {rest[0]} not found")
        return 0, format_value(registry, rest[0]) + "\n"
    if sub == "save":
        return _save(registry, rest, sysid)
    commands = {"reset": _reset, "reset_all": _reset_all, "touch": _touch}
    if sub in commands:
        return commands[sub](registry, rest)
    return 1, USAGE


def format_value(registry: ParamRegistry, name: str) -> str:
    value = registry.get(name)
    if registry.definition(name).type is ParamType.INT32:
        return f"{int(value)}"
    return f"{float(value):4.4f}"


def _matches(name: str, pattern: str | None) -> bool:
    """param.cpp do_show_print: case-insensitive, exact unless a '*' wildcard is given."""
    return pattern is None or fnmatch.fnmatchcase(name, pattern.upper())


def _show(registry: ParamRegistry, args: list[str]) -> tuple[int, str]:
    if args[:1] == ["-q"]:
        if len(args) < 2 or args[1] not in registry:
            return 1, ""
        return 0, format_value(registry, args[1]) + "\n"
    flag = args[0] if args[:1] in (["-a"], ["-c"]) else ""
    pattern = args[1 if flag else 0] if len(args) > (1 if flag else 0) else None
    lines = ["Symbols: x = used, + = saved, * = unsaved\n"]
    for all_index, d in enumerate(registry.known()):
        used, changed = registry.is_used(d.name), not registry.is_default(d.name)
        shown = changed if flag == "-c" else used or flag == "-a"
        if shown and _matches(d.name, pattern):
            unit = f" {d.unit}" if d.unit else ""
            lines.append(f"{'x' if used else ' '} {'+' if changed else ' '} {d.name} [{all_index},"
                         f"{registry.index_of(d.name)}] : {format_value(registry, d.name)}{unit}\n")
    lines.append(f"\n {len(registry)}/{sum(1 for _ in registry.known())} parameters used.\n")
    return 0, "".join(lines)


def _set(registry: ParamRegistry, name: str, text: str, fail: bool) -> tuple[int, str]:
    if name not in registry:
        return (1 if fail else 0), log_line("ERROR", "param", f"Parameter {name} not found.")
    try:
        value = float(text)  # BE SAFER THAN PX4: strtol/strtod would turn "abc" into 0 and set it
    except ValueError:
        return 1, log_line("ERROR", "param", f"'{text}' is not a number.")
    registry.mark_used(name)  # param.cpp do_set finds it with param_find, which marks it used
    old = format_value(registry, name)
    marker = " " if registry.is_default(name) else "+"
    if registry.get(name) == value:
        return 0, ""
    try:
        registry.set(name, value)
    except ParamError as err:
        return 1, log_line("ERROR", "param", str(err))
    return 0, f"{marker} {name}: curr: {old} -> new: {format_value(registry, name)}\n"


def _names(registry: ParamRegistry, patterns: list[str]) -> list[str]:
    """The known names matching any pattern (exact, or a prefix ending in '*': param.cpp param_reset_specific)."""
    return [d.name for d in registry.known()
            if any(d.name == p or (p.endswith("*") and d.name.startswith(p[:-1])) for p in patterns)]


def _reset(registry: ParamRegistry, args: list[str]) -> tuple[int, str]:
    if not args:
        return 1, log_line("ERROR", "param", "not enough arguments (use 'param reset_all' to reset all).")
    registry.reset(_names(registry, args))
    return 0, ""


def _reset_all(registry: ParamRegistry, args: list[str]) -> tuple[int, str]:
    keep = set(_names(registry, args))
    registry.reset([d.name for d in registry.known() if d.name not in keep])
    return 0, ""


def _touch(registry: ParamRegistry, args: list[str]) -> tuple[int, str]:
    if not args:
        return 1, log_line("ERROR", "param", "not enough arguments.")
    for name in args:
        if name in registry:
            registry.mark_used(name)
    return 0, ""


def _save(registry: ParamRegistry, args: list[str], sysid: int) -> tuple[int, str]:
    """`param save FILE` exports to FILE; `param save` writes the vehicle's own parameter file now."""
    try:
        if args:
            Path(args[0]).write_text(format_file(registry, sysid), encoding="utf-8")
            return 0, ""
        if registry.storage is None:
            return 1, log_line("ERROR", "param", "Param save failed (no parameter file: this vehicle keeps none)")
        where = registry.storage.save()
    except OSError as err:
        target = args[0] if args else "the parameter file"
        return 1, log_line("ERROR", "param", f"exporting to '{target}' failed ({err.strerror})")
    return 0, log_line("INFO", "param", f"saved to {where}")
