"""The flight session: one FlightSession (connect, pre-stream, arm, OFFBOARD, stream, watchdogs, clean exit)."""
