"""A campaign file (TOML) read into its scenario, limits and cases.

    scenario = "campaign_square.py:fly"      # path.py:function (relative to this file) or module:function
    [limits]
    sim_s = 120.0                            # simulated seconds per case
    wall_s = 300.0                           # wall seconds per case
    [fixed]                                  # in every case
    params = { SYS_FAILURE_EN = 1 }
    options = { side_m = 5.0 }
    [grid]                                   # every combination
    params = { SIH_WIND_N = [0.0, 5.0, 10.0] }
    [random]                                 # `count` draws per grid point
    count = 20
    seed = 2026                              # the draws' seed (each case also gets its own vehicle seed)
    params = { SIH_WIND_E = { uniform = [-5.0, 5.0] } }
    [[random.faults]]                        # a timed fault with a probability, at a drawn time
    name = "gps_off"
    at = { uniform = [10.0, 20.0] }
    probability = 0.5

`seed` and `faults` (a list of [time_s, "name"]) may stand in [fixed] or [grid] too. Without [grid] and [random]
there is one case.
"""

from __future__ import annotations

import sys
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sitl_emu.campaign.cases import Case, FaultDraw, make_cases
from sitl_emu.campaign.errors import CampaignError, CaseError
from sitl_emu.campaign.scenario import Limits

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

__all__ = ["CampaignSpec", "read_spec"]

SECTIONS = {"scenario", "limits", "fixed", "grid", "random"}
NESTED = ("params", "options")


@dataclass(frozen=True)
class CampaignSpec:
    scenario: str | None
    cases: list[Case]
    limits: Limits


def read_spec(path: Path) -> CampaignSpec:
    """The campaign in `path`; CampaignError (one sentence naming the file) for any mistake in it."""
    try:
        data = tomllib.loads(path.read_text())
    except OSError as err:
        raise CampaignError(f"cannot read the campaign file {path}: {err.strerror}.") from None
    except tomllib.TOMLDecodeError as err:
        raise CampaignError(f"{path} is not valid TOML: {err}.") from None
    except UnicodeDecodeError:
        raise CampaignError(f"{path} is not a text file: a campaign file is TOML (UTF-8 text).") from None
    try:
        return _spec(data, path.parent)
    except CaseError as err:
        raise CampaignError(f"{path}: {err}") from None


def _spec(data: Mapping[str, Any], base: Path) -> CampaignSpec:
    unknown = sorted(set(data) - SECTIONS)
    if unknown:
        raise CaseError(f"unknown key '{unknown[0]}'; a campaign file has {', '.join(sorted(SECTIONS))}.")
    random = dict(_table(data, "random"))
    count, draw_seed = random.pop("count", 0), random.pop("seed", 0)
    faults = random.pop("faults", [])
    for name, value in (("count", count), ("seed", draw_seed)):
        if isinstance(value, bool) or not isinstance(value, int) or value < 0:
            raise CaseError(f"random.{name} must be a whole number >= 0, not {value!r}.")
    cases = make_cases(_flat(_table(data, "fixed")), _flat(_table(data, "grid")), _flat(random), count, draw_seed,
                       [_fault_draw(f) for f in _list(faults, "random.faults")])
    return CampaignSpec(_scenario(data.get("scenario"), base), cases, _limits(_table(data, "limits")))


def _table(data: Mapping[str, Any], name: str) -> Mapping[str, Any]:
    value = data.get(name, {})
    if not isinstance(value, Mapping):
        raise CaseError(f"'{name}' must be a table ([{name}]), not {value!r}.")
    return value


def _list(value: Any, name: str) -> list[Any]:
    if not isinstance(value, list):
        raise CaseError(f"'{name}' must be a list, not {value!r}.")
    return value


def _flat(table: Mapping[str, Any]) -> dict[str, Any]:
    """[grid] params = {A = [..]} as {"params.A": [..]}; seed and faults stay as they are."""
    flat: dict[str, Any] = {}
    for key, value in table.items():
        if key in NESTED and isinstance(value, Mapping):
            flat.update({f"{key}.{name}": v for name, v in value.items()})
        else:
            flat[key] = value
    return flat


def _fault_draw(item: Any) -> FaultDraw:
    if not isinstance(item, Mapping) or "name" not in item or "at" not in item or set(item) - {"name", "at",
                                                                                              "probability"}:
        raise CaseError(f"each [[random.faults]] needs name and at (and may have probability), not {item!r}.")
    probability = item.get("probability", 1.0)
    if isinstance(probability, bool) or not isinstance(probability, (int, float)) or not 0 <= probability <= 1:
        raise CaseError(f"fault {item['name']}: probability must be from 0 to 1, not {probability!r}.")
    return FaultDraw(str(item["name"]), item["at"], float(probability))


def _scenario(value: Any, base: Path) -> str | None:
    if value is None:
        return None
    if not isinstance(value, str):
        raise CaseError(f"scenario must be a string such as \"flight.py:fly\", not {value!r}.")
    where, sep, name = value.rpartition(":")
    if sep and where.endswith(".py") and not Path(where).is_absolute():
        return f"{(base / where).resolve()}:{name}"
    return value


def _limits(table: Mapping[str, Any]) -> Limits:
    unknown = sorted(set(table) - {"sim_s", "wall_s"})
    if unknown:
        raise CaseError(f"unknown limit '{unknown[0]}'; [limits] has sim_s and wall_s.")
    values = {}
    for key in ("sim_s", "wall_s"):
        value = table.get(key, getattr(Limits(), key))
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not value > 0:
            raise CaseError(f"limits.{key} must be a number of seconds > 0, not {value!r}.")
        values[key] = float(value)
    return Limits(**values)
