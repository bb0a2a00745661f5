"""`fishgen sky`'s work as one function: cloud models in, a lit scene of many clouds out."""
from __future__ import annotations

import os
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from fishgen.clouds.lighting import Lighting
from fishgen.clouds.model import DEFAULT_MAX_PARTICLES, CubeFile
from fishgen.scene.model import Scene
from fishgen.sky.modes import ALTITUDE, AREA, MODES, NOISE

MODELS = Path(__file__).resolve().parent / "models"
"""The shipped cloud models: the report's two real editor files (Tables 4.3 and 4.4)."""


def shipped_models() -> list[Path]:
    return sorted(MODELS.glob("*.awn"))


@dataclass(frozen=True)
class Sky:
    """A composed, lit sky: its scene (write it with :func:`fishgen.exchange.export`) and, per
    cloud, what it holds."""

    scene: Scene
    clouds: tuple[dict[str, Any], ...]
    mode: str
    seed: int
    models: tuple[Path, ...]
    textures: tuple[Path, ...] = ()     # the PNGs texture clouds (.awa) named

    @property
    def particles(self) -> int:
        return sum(c["particles"] for c in self.clouds)

    @property
    def distant_particles(self) -> int:
        return sum(v for c in self.clouds for k, v in c.items() if k.startswith("lod"))


def load_models(paths: Sequence[str | os.PathLike] = (), *, max_particles: int = DEFAULT_MAX_PARTICLES,
                textures_dir: str | os.PathLike | None = None) -> tuple[list[CubeFile], list[Path]]:
    """The cube files a sky draws its clouds from: ``paths``, or the shipped models."""
    from fishgen.clouds.pipeline import read_cube_files

    files = [Path(p) for p in paths] or shipped_models()
    return read_cube_files(files, max_particles=max_particles, textures_dir=textures_dir,
                           raise_with="--max-particles"), files


def steps(mode: str) -> int:
    """How many times :func:`build_sky` advances for a sky of ``mode``: fill, light, level, a cloud."""
    return 3 * MODES[mode].clouds


def build_sky(mode: str = "medium", *, seed: int = 0, area: tuple[float, float] = AREA,
              altitude: tuple[float, float] = ALTITUDE, models: Sequence[str | os.PathLike] = (),
              noise: float = NOISE, particles: int | None = None, lighting: Lighting | None = None,
              shadow_map: str = "cloud", billboards: bool = False, lod: bool = True,
              textures_dir: str | os.PathLike | None = None,
              max_particles: int = DEFAULT_MAX_PARTICLES,
              advance: Callable[[int], None] | None = None) -> Sky:
    """Compose, fill, light and level a sky of ``mode`` (thin, medium, thick) from ``models`` (cube
    files, .awn or .awa; default: the shipped ones). Same arguments, same scene, bit for bit.
    ``advance(1)`` as each cloud is filled, lit and levelled: three steps a cloud (``steps``)."""
    from fishgen.clouds.pipeline import cloud_textures
    from fishgen.errors import UsageError
    from fishgen.sky.compose import fill_sky, plan_sky
    from fishgen.sky.light import light_sky
    from fishgen.sky.scene import sky_scene

    # the parser refuses a file without particles, so every model has some. A model's own count is
    # no size: each cloud re-fills it with its share of the sky's, and the sky's is checked below
    cubes, files = load_models(models, max_particles=sys.maxsize, textures_dir=textures_dir)
    sky_mode = MODES[mode]
    total = sky_mode.particles if particles is None else particles
    # the sky's size is the command line's (--particles, --mode), so a usage error
    if total > max_particles:
        raise UsageError(f"expected at most {max_particles:,} particles (raise --max-particles), found "
                         f"{total:,} for a {mode} sky")
    # every cloud needs a particle in each of its model's cubes: fewer leaves clouds empty
    need = sky_mode.clouds * max(sum(1 for c in f.cubes if c.particles) for f in cubes)
    if total < need:
        raise UsageError(f"expected --particles of at least {need:,} for a {mode} sky of {sky_mode.clouds} "
                         f"clouds (one in each cube of every cloud), found {total:,}")
    plan = plan_sky(sky_mode, cubes, seed=seed, area=area, altitude=altitude, particles=total)
    filled = fill_sky(plan, cubes, noise=noise, max_particles=max_particles, advance=advance)
    clouds = light_sky(filled, lighting or Lighting(), method=shadow_map, advance=advance)
    scene, facts = sky_scene(plan, clouds, [p.name for p in files], billboards=billboards, lod=lod,
                             advance=advance)
    return Sky(scene, tuple(facts), mode, seed, tuple(files), cloud_textures(cubes))
