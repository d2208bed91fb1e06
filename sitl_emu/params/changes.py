"""The parameter registry's change count, and a reader's watch on it, in a module of their own that is compiled with
the tick path (tools/build_speedups.py).

Settings derived from the parameters (the commander's, the controllers', the fence's, the land detector's, ...) are
built again when a parameter changes, and their owners ask at every tick or cycle. Each owner keeps a `ChangeWatch`
and asks `watch.changed()`: one compiled call that compares two C fields. ParamRegistry stays interpreted (compiled,
mypyc would turn the INT32 values of its float dict into floats), so `params.version` would cost compiled code a
Python attribute look-up (ARCHITECTURE.md, On the tick path).

    self._watch = params.changes.watch()            # the settings were built just now
    ...
    if self._watch.changed():                       # a parameter changed since: build them again
        self._settings = Settings.from_params(self.params)
"""

from __future__ import annotations

from typing import final


class ChangeCount:
    """How many accepted changes a ParamRegistry has seen (its `version`)."""

    def __init__(self) -> None:
        self.value = 0

    def watch(self, current: bool = True) -> ChangeWatch:
        """A reader's watch: `current` says the reader's settings are built from the parameters as they are now;
        False makes the first `changed()` True (settings built at first use)."""
        return ChangeWatch(self, self.value if current else -1)


@final  # compiled: calls go straight to the method, not through a vtable
class ChangeWatch:
    """`changed()`: True once after each parameter change (one answer for any number of changes in between)."""

    def __init__(self, count: ChangeCount, seen: int) -> None:
        self._count = count
        self._seen = seen

    def changed(self) -> bool:
        value = self._count.value
        if value == self._seen:
            return False
        self._seen = value
        return True
