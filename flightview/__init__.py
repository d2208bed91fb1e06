"""A live 3D view of flights in the browser, with Rerun (the optional `view` extra): used by `sitl-emu serve --view`
(sitl_emu/view.py, from the emulator's snapshots) and `joyfly fly|demo --view` (joyfly/view.py, from what joyfly
hears over MAVLink). It knows neither package: both hand it plain Frames (scene.py)."""
