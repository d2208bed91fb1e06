"""The parameter registry's change count, in a module of its own that is compiled with the tick path
(tools/build_speedups.py).

Settings derived from the parameters are read again when the count moves, and the controllers, the commander and the
navigator ask at every tick or cycle. ParamRegistry stays interpreted (compiled, mypyc would turn the INT32 values of
its float dict into floats), so `params.version` costs compiled code a Python attribute look-up; a reader that keeps
the registry's ChangeCount reads a C field (ARCHITECTURE.md, On the tick path).
"""

from __future__ import annotations


class ChangeCount:
    """How many accepted changes a ParamRegistry has seen (its `version`)."""

    def __init__(self) -> None:
        self.value = 0
