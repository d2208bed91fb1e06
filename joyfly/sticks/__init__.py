"""The stick side: joystick sources (js API, FIFO, raw file, script, replay), profiles, mapping, setpoints."""
