"""The scene model every asset passes through (see fishgen.scene.model) and how to pose it."""
from fishgen.scene.model import (
    INTERPOLATIONS,
    PATHS,
    Channel,
    Clip,
    Image,
    Material,
    Mesh,
    Node,
    Primitive,
    Sampler,
    Scene,
    Skin,
)

__all__ = ["INTERPOLATIONS", "PATHS", "Channel", "Clip", "Image", "Material", "Mesh", "Node",
           "Primitive", "Sampler", "Scene", "Skin"]
