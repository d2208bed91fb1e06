"""A pilot with an SDL virtual controller, for end-to-end tests: run as a program, it attaches a virtual device (which
exists in this process only, so joyfly must run here too), then runs `joyfly ARGS...` in its main thread (joyfly's
Ctrl-C/SIGTERM handling needs the main thread), and moves the virtual sticks as told on its stdin, one command a
line:

    axis N VALUE      SDL axis N to VALUE (-1..1; Y axes: negative = pushed forward)
    button N 0|1      SDL button N up/down
    detach            unplug the device
    attach            plug the same device (same GUID) in again
    other             plug in a different controller (another GUID)

    python tests/support/sdl_pilot.py [--joystick NAME] [--also NAME] [--none] -- fly --joy sdl --url ...

(--joystick: a plain joystick instead of the game controller; --also: a second game controller; --none: attach
nothing, so that joyfly sees no SDL device.)

Each command is acknowledged on stderr as `pilot: done COMMAND`. Rumble calls the device receives are reported as
`pilot: rumble LOW HIGH`.
"""

from __future__ import annotations

import sys
import threading
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))  # support.* when run as a program
sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from sdl_virtual import VirtualPad


def _say(text: str) -> None:
    sys.stderr.write(f"pilot: {text}\n")
    sys.stderr.flush()


class Pilot:
    def __init__(self, pad: VirtualPad) -> None:
        self.pad = pad
        self.others: list[VirtualPad] = []
        self._rumbles_told = 0

    def run(self) -> None:
        for line in sys.stdin:
            words = line.split()
            if words:
                self.command(words)
                _say("done " + " ".join(words))

    def command(self, words: list[str]) -> None:
        verb = words[0]
        if verb == "axis":
            self.pad.axis(int(words[1]), float(words[2]))
        elif verb == "button":
            self.pad.button(int(words[1]), words[2] == "1")
        elif verb == "detach":
            self.pad.detach()
        elif verb == "attach":
            self.pad.reattach()
        elif verb == "other":
            self.others.append(VirtualPad.controller("Somebody Else's Pad", product=0x0BAD))
        elif verb == "rumbles":
            for low, high, _ in self.pad.rumbles:
                _say(f"rumble {low} {high}")


def main() -> None:
    args = sys.argv[1:]
    split = args.index("--") if "--" in args else len(args)
    own, joyfly_args = args[:split], args[split + 1:]
    if "--none" not in own:
        pad = (VirtualPad.joystick(own[own.index("--joystick") + 1]) if "--joystick" in own
               else VirtualPad.controller("Pilot Pad"))
        pilot = Pilot(pad)
        if "--also" in own:
            pilot.others.append(VirtualPad.controller(own[own.index("--also") + 1], product=0x0A15))
        threading.Thread(target=pilot.run, name="pilot", daemon=True).start()
    from joyfly.cli import main as joyfly_main

    joyfly_main(args=joyfly_args, prog_name="joyfly")


if __name__ == "__main__":
    main()
