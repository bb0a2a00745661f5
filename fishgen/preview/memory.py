"""How much memory `fishgen preview` needs, known from its size and frames before anything is drawn.

A leaf module (no numpy). Measured as whole commands (2026-12-05, BonyBream, Mesa's llvmpipe): a
still peaks at about 130 MiB resident and 830 MiB of address space (the GL driver's), then 47 bytes
a pixel of one render (its 4x multisampled colour and depth, the resolved copy, the read-back and
the PNG): 3.2 GiB resident at 8192 x 8192. A scene with particles is blended in 16-bit colour,
28 bytes a pixel more (Table 4.4's cloud at 4096 x 4096: 1.32 GiB against 0.88). Every frame or
contact sheet an animation holds adds about 10 bytes a pixel in a GIF (RGBA, then a palette) and 4
in a WebP. Rounded up.
"""
from __future__ import annotations

from fishgen.memory import ADDRESS_SPACE, allowed, over

RESIDENT_BASE = 160 * 2**20
ADDRESS_BASE = 900 * 2**20
PER_RENDER_PIXEL = 52
PER_FINE_RENDER_PIXEL = 80
PER_HELD_PIXEL = 11


def estimate(width: int, height: int, held: int, fine: bool = False) -> tuple[int, int]:
    """(resident, address space) bytes a preview of ``width`` x ``height`` renders is expected to
    peak at, holding ``held`` pixels of frames and sheets for an animation or a sheet (0: a still);
    ``fine``: blended in 16-bit colour (particles)."""
    per = PER_FINE_RENDER_PIXEL if fine else PER_RENDER_PIXEL
    pixels = per * width * height + PER_HELD_PIXEL * held
    return RESIDENT_BASE + pixels, ADDRESS_BASE + pixels


def check_fits(width: int, height: int, held: int, fine: bool = False) -> None:
    """Refuse, before anything is drawn, a preview whose estimated peak is more than this process
    may use (a usage error: the size and the frames are the command line's)."""
    from fishgen.errors import UsageError

    limit = allowed()
    if limit is None:
        return
    resident, address = estimate(width, height, held, fine)
    texts = over(limit, address if limit[1] == ADDRESS_SPACE else resident)
    if texts is not None:
        have, want = texts
        raise UsageError(f"expected a preview that fits in {have} ({limit[1]}), found {width}x{height}"
                         f"{f' holding {held:,} pixels of frames' if held else ''}, which needs about "
                         f"{want}: use a smaller --size or fewer --frames")
