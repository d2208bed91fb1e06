"""The link's errors, in a module of their own: `make speedups` compiles link.py, and mypyc cannot compile a subclass
of OSError."""


class PortInUseError(OSError):
    """The local UDP port is taken; str(err) is one sentence for the user."""
