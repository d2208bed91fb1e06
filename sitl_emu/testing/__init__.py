"""For users' tests and ours: Sim (vehicles on loopback UDP in lockstep), a scripted client, the closed-loop
harness and step-response metrics."""

from sitl_emu.testing.sim import Sim

__all__ = ["Sim"]
