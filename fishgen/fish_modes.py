"""How a built fish may be drawn and swim: the choices its options offer.

A leaf module below both :mod:`fishgen.options`, which declares the options (the CLI lists the
choices without numpy), and :mod:`fishgen.assembly`, which builds them.
"""

FIN_MODES = ("blend", "mask", "opaque")
"""The fin techniques of thesis chapter 5."""
SWIM_MODES = ("body", "fins")
"""``body``: a travelling body wave under the fin swings; ``fins``: a rigid body, only the fins move."""
DEFAULT_SPEED = 1.0
"""Cruising speed of a built fish's swim loop, body lengths per second."""
MAX_TAIL_BEAT_HZ = 8.0
"""The body wave's tail-beat frequency cap (docs/decisions.md), reached at 16/3 body lengths a second."""
