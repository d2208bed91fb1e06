"""The bytes on the wire: the fast MAVLink 2 encoder and the messages pymavlink lacks.

fastpack.py (MAVLink 2 frames packed from pymavlink's message metadata, byte-identical to pymavlink's encoder),
encoding.py (what builds a link's messages, as the type checker sees it), extra_messages.py (field lists of the
messages pymavlink's dialects lack).

May import: pymavlink only (the leaves of the mavlink package).
"""
