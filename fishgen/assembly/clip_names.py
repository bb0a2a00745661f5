"""The clips a built fish can carry (a leaf module: the CLI lists them without numpy)."""

CLIP_NAMES = ("swim", "idle", "sprint", "turn_left", "turn_right", "burst")
"""``swim`` cruises at --speed; ``idle`` hovers, sculling its pectoral fins over a faint body wave;
``sprint`` swims at 3 body lengths per second, paired fins folded; ``turn_left``/``turn_right``
cruise with the body bent into a steady arc; ``burst`` is a C-start escape to the left, played once."""
DEFAULT_CLIPS = ("swim",)
BENDING_CLIPS = ("turn_left", "turn_right", "burst")
"""Clips that bend the body: they need the body wave's morph targets (--swim body)."""
