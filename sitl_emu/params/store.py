"""A vehicle's parameter file: what survives a restart, as PX4 SITL's parameters.bson in its working directory.

PX4 (src/lib/parameters/parameters.cpp) loads the file at boot and saves every value that differs from its default
shortly after any change (param_autosave). Here `sitl-emu serve` gives each vehicle a ParamStore: `load()` at start,
`autosave()` from the runner loop after every change, `save()` at shutdown and on the console's `param save`.

The file is QGroundControl's .params text, so QGC loads it and `serve --params FILE` reads it: '#' comment lines, then
one `SYSID COMPID NAME VALUE TYPE` line per changed parameter (TYPE: MAV_PARAM_TYPE, 6 INT32, 9 REAL32). Hand-written
`NAME VALUE` lines are read too. A REAL32 value is written as the shortest decimal that reads back as the same double,
so a value survives a save and a load bit for bit.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Iterable
from pathlib import Path

from sitl_emu.params.registry import ParamError, ParamRegistry, ParamType

log = logging.getLogger(__name__)

DEFAULT_FILE = "parameters.params"  # in the working directory, as PX4 SITL's parameters.bson
_TYPE_CODE = {ParamType.INT32: 6, ParamType.REAL32: 9}


class ParamFileError(ValueError):
    """A parameter file that cannot be used; str(err) is one sentence."""


Entry = tuple[str, float, str]  # (name, value, where: FILE:LINE or the option it came from)


def parse_lines(lines: Iterable[str], source: str) -> list[Entry]:
    """(name, value, where) from `NAME VALUE` lines or QGC .params lines `SYSID COMPID NAME VALUE TYPE`; '#' starts a
    comment. ParamFileError on any other line, or a value that is not a number."""
    entries: list[Entry] = []
    for n, raw in enumerate(lines, 1):
        parts = raw.split("#", 1)[0].split()
        if not parts:
            continue
        if len(parts) >= 4 and parts[0].isdigit() and parts[1].isdigit():
            parts = parts[2:4]
        elif len(parts) != 2:
            raise ParamFileError(f"{source}:{n}: expected 'NAME VALUE' or a QGC .params line, not '{raw.strip()}'.")
        entries.append((parts[0], parse_value(parts[0], parts[1], f"{source}:{n}"), f"{source}:{n}"))
    return entries


def parse_value(name: str, text: str, where: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise ParamFileError(f"{where}: parameter {name} needs a number, not '{text}'.") from None


MAX_FILE_BYTES = 1 << 20  # every PX4 parameter as a 'NAME VALUE' line takes about 30 kB


def read_file(path: Path) -> list[Entry]:
    """The entries of a parameter file; ParamFileError if it cannot be read or is not one."""
    try:
        with path.open("rb") as f:
            raw = f.read(MAX_FILE_BYTES + 1)  # bounded: --params /dev/urandom must not read forever
    except OSError as err:
        raise ParamFileError(f"Cannot read the parameter file {path}: {err.strerror}.") from None
    if len(raw) > MAX_FILE_BYTES:
        raise ParamFileError(f"{path} is over {MAX_FILE_BYTES >> 20} MB: not a parameter file ('NAME VALUE' lines).")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        raise ParamFileError(f"{path} is not a text file: a parameter file has 'NAME VALUE' lines.") from None
    return parse_lines(text.splitlines(), str(path))


def apply_entry(registry: ParamRegistry, entry: Entry) -> None:
    """Set one parameter; ParamError (one sentence, starting with where it came from) if refused."""
    name, value, where = entry
    try:
        registry.set(name, value)
    except ParamError as err:
        raise ParamError(f"{where}: {err}") from None


def format_file(registry: ParamRegistry, sysid: int, compid: int = 1) -> str:
    lines = [f"# Parameters of vehicle {sysid} that differ from PX4's defaults, saved by sitl-emu (QGC .params format)",
             "# MAV ID\tCOMPONENT ID\tPARAM NAME\tVALUE\t(TYPE)"]
    for name, value in registry.changed().items():
        kind = registry.definition(name).type
        text = str(int(value)) if kind is ParamType.INT32 else repr(float(value))
        lines.append(f"{sysid}\t{compid}\t{name}\t{text}\t{_TYPE_CODE[kind]}")
    return "\n".join(lines) + "\n"


def instance_path(base: Path, instance: int, first: int) -> Path:
    """Vehicle `instance`'s file: `base` for instance `first`, `<stem>-<instance><suffix>` beside it for the others
    (PX4 SITL keeps one working directory per instance)."""
    if instance == first:
        return base
    return base.with_name(f"{base.stem}-{instance}{base.suffix}")


class ParamStore:
    """One vehicle's parameter file (module docstring). It registers itself as `registry.storage`."""

    def __init__(self, registry: ParamRegistry, path: Path, sysid: int = 1) -> None:
        self.registry = registry
        self.path = path
        self.sysid = sysid
        self._saved_version = registry.version
        self._failed_version: int | None = None  # the version a save failed at: not retried until the next change
        registry.storage = self

    def load(self, fallback: Path | None = None) -> str | None:
        """Apply the file (or `fallback` while the file does not exist yet); return one warning sentence, or None.

        A file that is not a parameter file leaves every default in place; it is renamed to `<name>.bad` so the next
        save does not overwrite it. Unknown names and refused values are skipped (PX4 ignores unknown names too).
        """
        source = self.path if self.path.exists() or fallback is None else fallback
        if not source.exists():
            return None
        try:
            entries = read_file(source)
        except ParamFileError as err:
            return self._set_aside(source, err)
        skipped = []
        for entry in entries:
            try:
                apply_entry(self.registry, entry)
            except ParamError:
                skipped.append(entry[0])
        self.mark_saved()
        if skipped:
            return (f"{source}: skipped {', '.join(skipped)} (unknown, or a value this vehicle refuses); the other "
                    "values were loaded.")
        return None

    def _set_aside(self, source: Path, err: ParamFileError) -> str:
        bad = source.with_name(source.name + ".bad")
        why = str(err).rstrip(".")
        try:
            source.replace(bad)
        except OSError:
            return f"{source} is not a usable parameter file ({why}), so vehicle {self.sysid} starts from the defaults."
        return (f"{source} is not a usable parameter file ({why}), so vehicle {self.sysid} starts from the defaults; "
                f"the file was kept as {bad}.")

    def mark_saved(self) -> None:
        """The registry's current values are what the file holds (after a load)."""
        self._saved_version = self.registry.version

    @property
    def unsaved(self) -> bool:
        return self.registry.version != self._saved_version

    def save(self) -> str:
        """Write the changed values now (atomically: a temporary file, then a rename); return the path."""
        text = format_file(self.registry, self.sysid)
        tmp = self.path.with_name(self.path.name + ".tmp")
        tmp.write_text(text, encoding="utf-8")
        os.replace(tmp, self.path)
        self.mark_saved()
        return str(self.path)

    def autosave(self) -> None:
        """Save if anything changed since the last save (the runner calls it every loop iteration); a failure is
        logged once and tried again at the next change (and at shutdown)."""
        version = self.registry.version
        if version == self._saved_version or version == self._failed_version:
            return
        try:
            self.save()
        except OSError as err:
            if self._failed_version is None:
                log.warning("cannot save the parameters to %s: %s", self.path, err.strerror)
            self._failed_version = version
