"""The pxh> console and the shell commands, after PX4 platforms/posix (pxh) and src/systemcmds.

console.py (the terminal console of `sitl-emu serve`: prompt, events as PX4 log lines, one vehicle at a time),
terminal.py (reading lines: readline on a terminal, in the foreground only), shell.py (the commands shared by the
console and the MAVLink shell: `commander ...`, pxh's line handling), param.py (src/systemcmds/param),
mission.py (our `mission`: the stored plans and progress), failure.py (src/systemcmds/failure), listener.py
(src/systemcmds/topic_listener).

A face: may import the kernel, params/, commander/, navigator/ (their tables and plans); it drives the vehicle only
through the object it is handed. Never runtime/ or testing/.
"""
