"""sitl_emu.mavlink"""
