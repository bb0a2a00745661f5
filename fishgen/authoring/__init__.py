"""Species-authoring tools: making VRFish species files rather than building them.

- :mod:`.photo` -- `fishgen texture`: Fixel's texture points measured on a side photo.
- :mod:`.sampler`, :mod:`.species_files` -- `fishgen species --random`.
- :mod:`.painter` -- procedural skins painted from a species' texture points.
- :mod:`.texture_points` -- Fixel-style points projected from a species' own geometry.

The build pipeline does not use them.
"""
