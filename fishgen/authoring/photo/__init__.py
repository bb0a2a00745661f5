"""Texture points from a side photo of a fish: Fixel's clicks, found by measuring the picture.

The stages, one module each: :mod:`.image` (safe decoding), :mod:`.silhouette`
(fish vs background), :mod:`.frame` (head left, midline level), :mod:`.sideview`
(the species' own side view in thesis units), :mod:`.anatomy` (nose, tail base,
body outline under the fins), :mod:`.points` (Fixel's points), :mod:`.fit`
(--fit-shape), :mod:`.fxl` (Fixel's .FXL files) and :mod:`.run` (the command).
"""

#: The focal lengths `--focal-length` takes, mm on a 36 mm wide sensor.
FOCAL_LENGTHS = (4.0, 2000.0)
