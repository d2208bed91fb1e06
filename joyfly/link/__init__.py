"""The vehicle side: joyfly's MAVLink client and the byte transports under it."""
