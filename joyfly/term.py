"""A block of lines redrawn in place at the bottom of a terminal (ANSI: cursor up N lines, erase to the end)."""

from __future__ import annotations

from typing import TextIO


class LiveBlock:
    def __init__(self, out: TextIO) -> None:
        self.out = out
        self._lines = 0

    def erase(self) -> None:
        """Remove the block, so a note can be printed where it was (the block is redrawn below it)."""
        if self._lines:
            self.out.write(f"\x1b[{self._lines}F\x1b[J")
            self._lines = 0

    def draw(self, lines: list[str]) -> None:
        self.erase()
        self.out.write("\n".join(lines) + "\n")
        self.out.flush()
        self._lines = len(lines)
