"""Extra SDL game-controller mappings: `--sdl-mapping FILE` (a gamecontrollerdb.txt, or one mapping line given
directly), the SDL_GAMECONTROLLERCONFIG environment variable (SDL reads it too; joyfly gives it again so a broken
line is reported) and the `mappings` list of the --config file.

A mapping line is SDL's: `GUID,name,a:b0,b:b1,...,leftx:a0,...[,platform:Linux,]` (the format of the community
gamecontrollerdb.txt; SDL_GameControllerAddMapping). Blank lines and `#` comments are skipped, and so are lines for
another platform (as SDL_GameControllerAddMappingsFromFile does). A line SDL refuses ends in one sentence naming the
file (or setting) and the line.
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

from joyfly.sticks.sdl.api import MappingError

ENV_VAR = "SDL_GAMECONTROLLERCONFIG"


class MappingSink(Protocol):
    def add_mapping(self, line: str) -> str | None: ...

    def platform(self) -> str: ...


@dataclass(frozen=True, slots=True)
class SdlMappings:
    """Where extra mappings come from: a file or one line (--sdl-mapping), lines from the config, the environment."""

    file: str | None = None
    lines: tuple[str, ...] = ()
    use_env: bool = True

    @property
    def empty(self) -> bool:
        return self.file is None and not self.lines and not (self.use_env and os.environ.get(ENV_VAR))


def _platform_of(line: str) -> str | None:
    for field in line.split(","):
        key, sep, value = field.partition(":")
        if sep and key.strip() == "platform":
            return value.strip()
    return None


def add_lines(sink: MappingSink, lines: Iterable[tuple[int, str]], where: str) -> int:
    """Give SDL every mapping line (numbered for the error); returns how many it took."""
    added = 0
    here = sink.platform()
    for lineno, raw in lines:
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        platform = _platform_of(line)
        if platform is not None and platform != here:
            continue
        why = sink.add_mapping(line)
        if why is not None:
            raise MappingError(f"{where} line {lineno} is not an SDL game-controller mapping ({why}): fix or remove "
                               "that line (the format is GUID,name,a:b0,...,leftx:a0,... as in gamecontrollerdb.txt).")
        added += 1
    return added


def _read(path: str) -> str:
    try:
        return Path(path).read_text(encoding="utf-8")
    except FileNotFoundError:
        raise MappingError(f"No mapping file at {path}: check the path given with --sdl-mapping.") from None
    except UnicodeDecodeError:
        raise MappingError(f"{path} is not a text file of SDL mappings: check the path given with --sdl-mapping.") \
            from None
    except OSError as exc:
        raise MappingError(f"Cannot read the mapping file {path} ({exc.strerror}): check --sdl-mapping.") from None


def _looks_like_line(text: str) -> bool:
    """--sdl-mapping takes a file or one mapping line: a line has SDL's GUID and name before its first fields."""
    return text.count(",") >= 2 and not os.path.exists(text)


def apply_mappings(sink: MappingSink, mappings: SdlMappings) -> int:
    """Give SDL every extra mapping (the environment, the config's lines, then --sdl-mapping); returns the count.
    MappingError (one sentence) names the first bad line."""
    added = 0
    env = os.environ.get(ENV_VAR, "") if mappings.use_env else ""
    if env:
        added += add_lines(sink, enumerate(env.splitlines(), start=1), f"the {ENV_VAR} environment variable")
    if mappings.lines:
        added += add_lines(sink, enumerate(mappings.lines, start=1), "the config file's mappings")
    if mappings.file is not None:
        if _looks_like_line(mappings.file):
            added += add_lines(sink, [(1, mappings.file)], "--sdl-mapping")
        else:
            added += add_lines(sink, enumerate(_read(mappings.file).splitlines(), start=1), mappings.file)
    return added
