"""Cube files (.awn, .awa) to filled, lit particle clouds: the one path every caller takes.

    models = read_cube_files(["a.awn", "b.awa"])                 # parse: the typed model
    made = cube_clouds(models, seed=7, offsets=[(0, 0, 0), (25, 3, -10)], lighting=Lighting())
    export_cloud(made.cloud, "sky.glb", billboards=made.textured)  # or cloud_scene(made.cloud, ...)

`fishgen clouds`, its preview (:func:`fishgen.clouds.scene.cube_file_scene`), the editor's fill,
fly's cube files and `fishgen sky` all fill through :func:`cube_clouds` (input i with seed + i,
scaled down alike to ``most`` when asked). Fly and the sky light their clouds as a sky instead
(each its own node, ``light=False``): the sky reads its models here and fills each of its clouds,
the model scaled by its plan, with the cloud's own seed. The module imports nothing heavy.
"""
from __future__ import annotations

import os
import warnings
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

from fishgen.clouds.model import DEFAULT_MAX_PARTICLES, CubeFile

if TYPE_CHECKING:
    from fishgen.clouds.lighting import Lighting
    from fishgen.clouds.model import Cloud

PREVIEW_PARTICLES = 100_000
"""Most particles a preview fills: a picture shows no more, a CPU rasterizer draws 10^5 soft discs in
about 2.5 s, and a 46-byte file of 2x10^7 particles took 6.6 GB and 42 s before this cap."""


def read_cube_files(paths: Iterable[str | os.PathLike], *, max_particles: int = DEFAULT_MAX_PARTICLES,
                    textures_dir: str | os.PathLike | None = None, note: Callable[[str], None] | None = None,
                    raise_with: str | None = None) -> list[CubeFile]:
    """Parse each cube file (``max_particles`` per file; ``raise_with``, the option that raises
    it, if any). The parser's warnings go to ``note`` when given, else out as Python warnings
    (:class:`~fishgen.clouds.parser.CubeFileWarning`)."""
    from fishgen.clouds.parser import CubeFileWarning, load_cubes

    models = []
    for path in paths:
        if note is None:
            models.append(load_cubes(path, max_particles=max_particles, textures_dir=textures_dir,
                                     raise_with=raise_with))
            continue
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", CubeFileWarning)
            models.append(load_cubes(path, max_particles=max_particles, textures_dir=textures_dir,
                                     raise_with=raise_with))
        for warning in caught:
            note(str(warning.message))
    return models


def cloud_textures(models: Iterable[CubeFile]) -> tuple[Path, ...]:
    """The PNGs the billboards of texture clouds carry, each once, in file and cube order."""
    return tuple(dict.fromkeys(Path(c.texture) for m in models for c in m.cubes if c.texture))


def scaled(model: CubeFile, most: int) -> CubeFile:
    """``model`` with every cube's count scaled by ``most / total``, rounded down, so its shape and
    density pattern are kept: a cube that had particles keeps at least 1, an empty cube stays empty
    (docs/decisions.md)."""
    ratio = most / model.total
    return replace(model, cubes=tuple(replace(c, particles=max(1, int(c.particles * ratio)) if c.particles
                                              else 0) for c in model.cubes))


@dataclass(frozen=True)
class CubeClouds:
    """Cube files filled (and lit): what the exporters and the pages need."""

    models: tuple[CubeFile, ...]    # as read
    filled: tuple[CubeFile, ...]    # as filled: scaled down alike when over ``most``
    clouds: tuple[Cloud, ...]       # unlit (light=False): each file's particles; lit: () (all are in lit)
    lit: Cloud | None               # all the files' particles in one, lit together; None when not lit

    @property
    def cloud(self) -> Cloud:
        """All the files' particles in one, lit together (clouds shadow clouds)."""
        if self.lit is None:
            raise ValueError("cube_clouds(light=False) left the clouds unlit")
        return self.lit

    @property
    def whole(self) -> int:
        """Particles the files hold."""
        return sum(m.total for m in self.models)

    @property
    def particles(self) -> int:
        """Particles filled."""
        return sum(m.total for m in self.filled)

    @property
    def textured(self) -> bool:
        """A texture cloud among them: its particles are textured billboards."""
        return any(c.texture for m in self.models for c in m.cubes)

    @property
    def noun(self) -> str:
        return "billboard" if self.textured else "particle"

    @property
    def textures(self) -> tuple[Path, ...]:
        return cloud_textures(self.models)

    @property
    def note(self) -> str | None:
        """What a scaled-down fill says: ``previewing 100,000 of its 200,000 particles``."""
        if self.particles == self.whole:
            return None
        return f"previewing {self.particles:,} of its {self.whole:,} {self.noun}s"


def cube_clouds(models: Sequence[CubeFile], *, seed: int = 0, method: str = "paper",
                offsets: Sequence[Sequence[float]] = (), most: int | None = None,
                lighting: Lighting | None = None, light: bool = True,
                max_particles: int = DEFAULT_MAX_PARTICLES,
                advance: Callable[[int], None] | None = None) -> CubeClouds:
    """Fill every cube file (input i with seed + i, at ``offsets[i]``), then light them together.

    A file of more than ``most`` particles is filled with every cube's count scaled down alike
    (:func:`scaled`). More than ``max_particles`` in all is refused before anything is allocated.
    ``light=False`` leaves the clouds unlit, for a caller that lights them as a sky (fly, `fishgen sky`).
    ``advance(k)`` as work is done, ``cloud_steps`` of it in all (a progress bar's).
    """
    from fishgen.clouds.fill import fill_cloud, merge_clouds
    from fishgen.clouds.light import light_cloud

    models = tuple(models)
    places = tuple(offsets) or ((0.0, 0.0, 0.0),) * len(models)
    filled = tuple(scaled(m, most) if most is not None and m.total > most else m for m in models)
    check_total(filled, max_particles)
    fills = (fill_cloud(m, seed=seed + i, method=method, offset=place, advance=advance)
             for i, (m, place) in enumerate(zip(filled, places, strict=True)))
    if not light:
        return CubeClouds(models, filled, tuple(fills), None)
    # the files' clouds are dropped once merged: a scene near the limit is not held twice while lit
    return CubeClouds(models, filled, (), light_cloud(merge_clouds(list(fills)), lighting, advance=advance))


def check_total(models: Sequence[CubeFile], max_particles: int = DEFAULT_MAX_PARTICLES) -> None:
    """Refuse more than ``max_particles`` in all the files (each was read under it)."""
    from fishgen.errors import UsageError, plural

    total = sum(m.total for m in models)
    if total > max_particles:
        files = plural(len(models), "file")
        raise UsageError(f"expected at most {max_particles:,} particles in the scene (raise the limit with "
                         f"--max-particles), found {total:,} in {files}")


def cloud_steps(models: Sequence[CubeFile], *, light: bool = True) -> int:
    """How far :func:`cube_clouds` advances for ``models`` (none scaled down): a step a particle
    filled, and the light's."""
    from fishgen.clouds.light import light_steps

    total = sum(m.total for m in models)
    return total + (light_steps(total) if light else 0)
