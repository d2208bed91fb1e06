"""The `sitl-emu` command line.

main.py (the click group `main`, the `serve` command, building vehicles, nodes and runners; `log` and `campaign`
come from log/cli.py and campaign/cli.py), options.py (option types and checks, and the one style of user errors:
one sentence, no traceback), view_setup.py (--view checked, then started), signals.py, signing_key.py, extras.py
(how to install an optional extra, in help texts and errors).

The outermost face: may import everything in sitl_emu and flightview; nothing in sitl_emu imports main.py
(log/ and campaign/ import options.py and extras.py only).
"""
