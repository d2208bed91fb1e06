"""sitl_emu.flight"""
