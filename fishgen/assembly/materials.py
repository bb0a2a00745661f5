"""Materials and textures for the three fin techniques of thesis chapter 5.

``blend``  semi-translucent fins (alphaMode BLEND) with alpha from the file's
           transparency, 0.5 where it is 1.0 as the thesis' blending did.
``mask``   the black/white mask cuts the fin shape out of the fin triangles:
           colour and mask become one RGBA texture, alphaMode MASK -- what the
           thesis' stencil + alpha test achieved, in one pass.
``opaque`` plain textured fins.
"""
from __future__ import annotations

import io

from fishgen.errors import FishgenError
from fishgen.scene.model import Material
from fishgen.species.model import Species

MASK_CUTOFF = 0.5


def fin_alpha(transparency: float) -> float:
    return 0.5 if transparency >= 1.0 else transparency


def default_fin_mode(species: Species) -> str:
    return "mask" if species.masked and species.textured else "blend"


def load_textures(species: Species, mode: str) -> dict[str, bytes]:
    """PNG bytes of the textures a build needs, turned upright for glTF.

    VRFish stores its textures upside down for OpenGL (thesis chapter 6) while
    the texture points are measured from the top of the upright picture, so
    flipping the image back lets the file's (u, v) be used as glTF UVs as they are.
    """
    from PIL import Image, ImageOps

    if not species.textured or species.colour_texture is None:
        return {}
    colour = ImageOps.flip(_decode(species, species.colour_texture, "RGB"))
    if mode == "mask":
        mask = ImageOps.flip(_decode(species, species.mask_texture, "L"))
        if mask.size != colour.size:
            mask = mask.resize(colour.size, Image.Resampling.NEAREST)
        colour = colour.convert("RGBA")
        colour.putalpha(mask)
    return {"skin": _png(colour)}


def _decode(species: Species, path, mode: str):
    """Decode a whole texture; a damaged file is the species file's error, at its texture line."""
    from PIL import Image

    from fishgen.reading import in_srgb

    try:
        with Image.open(path) as img:
            # a colour texture's profile gives its colours; a mask's levels are no colours
            return (img if mode == "L" else in_srgb(img, img.info.get("icc_profile"))).convert(mode)
    except (OSError, ValueError, Image.DecompressionBombError) as err:
        raise FishgenError(f"expected a readable texture image, found {path.name!r} damaged ({err})",
                           species.source, species.line_of("texture")) from None


def _png(image) -> bytes:
    out = io.BytesIO()
    image.save(out, format="PNG", optimize=False, compress_level=6)
    return out.getvalue()


def make_materials(species: Species, mode: str, texture: int | None) -> tuple[Material, Material]:
    """(body, fins) materials; ``texture`` is the scene image index of the skin, if any."""
    textured = texture is not None
    colour = (*species.colour, 1.0)
    tex = texture
    body = Material(f"{species.name}_body", (1.0, 1.0, 1.0, 1.0) if textured else colour, tex)
    fin_rgb = (1.0, 1.0, 1.0) if textured else species.colour
    if mode == "blend":
        fins = Material(f"{species.name}_fins", (*fin_rgb, fin_alpha(species.transparency)), tex, "BLEND",
                        None, True)
    elif mode == "mask" and textured:
        fins = Material(f"{species.name}_fins", (*fin_rgb, 1.0), tex, "MASK", MASK_CUTOFF, True)
    else:
        fins = Material(f"{species.name}_fins", (*fin_rgb, 1.0), tex, "OPAQUE", None, True)
    return body, fins
