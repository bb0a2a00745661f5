"""Swim modes of a built fish (a leaf module: the CLI lists them without numpy)."""

SWIM_MODES = ("body", "fins")
"""``body``: a travelling body wave under the fin swings; ``fins``: a rigid body, only the fins move."""
DEFAULT_SPEED = 1.0
"""Cruising speed of a built fish's swim loop, body lengths per second."""
