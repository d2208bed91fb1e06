"""sitl_emu.control"""
