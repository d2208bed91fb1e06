"""Write the ranges and units of sitl_emu/params/px4_param_meta.csv from PX4's parameter reference.

usage: .venv/bin/python tools/px4_param_meta.py [REFERENCE.md]

The source is PX4's generated parameter reference, docs/en/advanced_config/parameter_reference.md of PX4-Autopilot at
the commit the parameter list was recorded from (px4_params.csv: the fork dakejahl/PX4-Autopilot at 0d4ae424d3), e.g.
`git -C PX4-Autopilot show 0d4ae424d3:docs/en/advanced_config/parameter_reference.md > px4-parameter-reference.md`.
Without an argument the tool reads ../shared/reference/px4-parameter-reference.md beside the repository.

For every parameter of px4_params.csv the tool writes PX4's minimum, maximum and unit as PX4 states them (empty where
PX4 states none). A parameter the reference lacks takes the values of the listed instance of the same family: the
reference is generated for a board with 8 PWM outputs, SITL has 16, so PWM_MAIN_FUNC9..16 take PWM_MAIN_FUNC1's.

The description column is ours, not PX4's: the tool keeps the one already in the file, never writes PX4's text, and
refuses to write when a description is missing or shares more than MAX_OVERLAP of its words with PX4's text for that
parameter (word_overlap). New parameters therefore need a description written by hand before the file is rewritten.
"""

from __future__ import annotations

import csv
import io
import re
import sys
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
SOURCES = [up / "shared" / "reference" / "px4-parameter-reference.md" for up in (REPO.parent, REPO.parent.parent)]
PARAMS = REPO / "sitl_emu" / "params" / "px4_params.csv"
TARGET = REPO / "sitl_emu" / "params" / "px4_param_meta.csv"
MAX_OVERLAP = 0.6

HEADER = """\
# Metadata of every parameter in px4_params.csv, in the same order: PX4's minimum, maximum and unit as PX4's parameter
# metadata states them (empty: PX4 states none), and a one-line description in our own words.
# The ranges and units are written by tools/px4_param_meta.py from PX4's parameter reference (PX4-Autopilot
# 0d4ae424d3, docs/en/advanced_config/parameter_reference.md); the descriptions are kept as written here.
name,min,max,unit,description
"""

# Words too common to say anything about copying.
STOP_WORDS = frozenset({
    "a", "an", "and", "are", "as", "at", "be", "been", "by", "can", "for", "from", "has", "have", "if", "in", "into",
    "is", "it", "its", "may", "no", "not", "of", "on", "or", "per", "than", "that", "the", "then", "this", "to", "was",
    "when", "which", "while", "will", "with",
})


@dataclass(frozen=True)
class Px4Entry:
    min: str
    max: str
    unit: str
    text: str  # PX4's own words about the parameter (title and description), only to measure overlap


def parse_reference(markdown: str) -> dict[str, Px4Entry]:
    """name -> PX4's range, unit and text, from the '### NAME (`TYPE`)' sections and their one-row tables."""
    entries: dict[str, Px4Entry] = {}
    for section in re.split(r"^### ", markdown, flags=re.MULTILINE)[1:]:
        head = re.match(r"(\w+) \(`\w+`\)", section)
        if head is None:
            continue
        rows = [line for line in section.splitlines() if line.startswith("|")]
        if len(rows) < 3:
            raise ValueError(f"{head.group(1)}: no metadata table")
        cells = [cell.strip() for cell in rows[2].strip().strip("|").split("|")]
        _reboot, lo, hi, _increment, _default, unit, _read_only = cells
        text = "\n".join(line for line in section.splitlines()[1:] if not line.startswith(("|", "<Badge", "## ")))
        entries[head.group(1)] = Px4Entry(_number(lo), _number(hi), "" if unit == "&nbsp;" else unit, text)
    return entries


def _number(cell: str) -> str:
    if cell in ("", "&nbsp;"):
        return ""
    float(cell)  # a number or an error
    return cell


def family(name: str) -> str:
    """The name with its instance numbers replaced, e.g. PWM_MAIN_FUNC9 -> PWM_MAIN_FUNC#."""
    return re.sub(r"\d+", "#", name)


def lookup(entries: dict[str, Px4Entry], name: str) -> Px4Entry | None:
    """PX4's entry for `name`, or that of the first listed instance of its family (module docstring)."""
    if name in entries:
        return entries[name]
    return next((e for n, e in entries.items() if family(n) == family(name)), None)


def words(text: str) -> set[str]:
    """The content words of a text: lower case, letters (digits alone do not count), no stop words."""
    return {w for w in re.findall(r"[a-z][a-z0-9]*", text.lower()) if w not in STOP_WORDS}


def word_overlap(ours: str, px4_text: str) -> float:
    """The share of our description's content words that PX4's text about the same parameter also uses."""
    mine = words(ours)
    return len(mine & words(px4_text)) / len(mine) if mine else 1.0


def read_table(text: str) -> list[dict[str, str]]:
    """The rows of a CSV data file ('#' comment lines, then a header line)."""
    lines = [line for line in text.splitlines() if line and not line.startswith("#")]
    return list(csv.DictReader(io.StringIO("\n".join(lines))))


def build(entries: dict[str, Px4Entry], names: list[str], described: dict[str, str]) -> tuple[str, list[str]]:
    """The file's text and the problems that keep it from being written (missing or copied descriptions)."""
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    problems = []
    for name in names:
        entry = lookup(entries, name)
        if entry is None:
            problems.append(f"{name}: not in PX4's reference")
            continue
        description = described.get(name, "")
        if not description:
            problems.append(f"{name}: write a description (PX4: {entry.text.strip().splitlines()[0]})")
        elif (share := word_overlap(description, entry.text)) > MAX_OVERLAP:
            problems.append(f"{name}: the description repeats PX4's words ({share:.0%})")
        writer.writerow([name, entry.min, entry.max, entry.unit, description])
    return HEADER + out.getvalue(), problems


def main(argv: list[str]) -> None:
    source = Path(argv[0]) if argv else next((s for s in SOURCES if s.exists()), SOURCES[0])
    entries = parse_reference(source.read_text(encoding="utf-8"))
    names = [row["name"] for row in read_table(PARAMS.read_text(encoding="ascii"))]
    old = read_table(TARGET.read_text(encoding="utf-8")) if TARGET.exists() else []
    text, problems = build(entries, names, {row["name"]: row["description"] for row in old})
    if problems:
        raise SystemExit("not written:\n  " + "\n  ".join(problems))
    TARGET.write_text(text, encoding="utf-8")
    print(f"wrote {len(names)} parameters to {TARGET.relative_to(REPO)}")


if __name__ == "__main__":
    main(sys.argv[1:])
