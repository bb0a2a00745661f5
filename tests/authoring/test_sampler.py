"""`fishgen species --random`'s sampler: 500 seeds all parse, build, export and validate; no fin
stands off the body and no body folds through itself."""
from __future__ import annotations

import numpy as np
import pytest
import trimesh

from fishgen.assembly.fins import build_fins
from fishgen.assembly.fish import build_fish
from fishgen.authoring.sampler import RANGES, sample_species
from fishgen.authoring.species_files import sample_files
from fishgen.geometry.body import build_body
from fishgen.geometry.shapes import profile_for
from fishgen.species.parser import load_species, parse_species
from fishgen.species.writer import format_species

SEEDS = range(500)


def _body_and_fins(sp):
    body = build_body(profile_for(sp.shape_class, sp.shape_params), sp.body_sections, sp.circle_sections,
                      sp.scale)
    return body, build_fins(sp, body.rings)


def test_500_samples_parse_build_and_hold_together():
    for seed in SEEDS:
        sample = sample_species(seed)
        sp = parse_species(format_species(sample.species, "s.png", "s_mask.png"), f"seed{seed}.txt")
        scene = build_fish(sp, fins="blend")
        assert len(scene.meshes) >= 6, seed
        body, fins = _body_and_fins(sp)
        # Not self-intersecting: the body is slabs between ring planes, so rings in strictly
        # increasing x, each a convex polygon about the axis (radius >= 0), cannot cross; the
        # closed mesh is then a proper volume.
        xs = body.rings[:, 0, 0]
        assert np.all(np.diff(xs) > 0) and np.all(body.radii >= 0) and np.isfinite(body.radii).all(), seed
        mesh = trimesh.Trimesh(body.mesh.positions, body.mesh.faces, process=False)
        assert mesh.is_watertight and mesh.is_winding_consistent and mesh.volume > 0, seed
        scale = float(np.ptp(body.mesh.positions[:, 0]))
        attached = []
        for fin in fins:
            if fin.name == "caudal_fin":   # joined on the axis inside the tail's tip
                assert fin.pivot is not None and np.linalg.norm(fin.pivot[1:]) < 1e-9, seed
                assert xs[0] <= fin.pivot[0] <= xs[-1], seed
                continue
            attached.append(fin)
        # every other fin's nearest vertex to the body: one query of all their vertices
        vertices = np.concatenate([f.mesh.positions for f in attached])
        _, dist, _ = trimesh.proximity.closest_point(mesh, vertices)
        ends = np.cumsum([len(f.mesh.positions) for f in attached])
        for fin, part in zip(attached, np.split(dist, ends[:-1]), strict=True):
            assert part.min() < 1e-6 * scale, (seed, fin.name)


def test_samples_stay_in_their_ranges():
    for seed in range(100):
        sp = sample_species(seed).species
        sx, sy, sz = sp.scale
        lo, hi = RANGES["scale_x"]
        assert lo <= sx <= hi
        assert RANGES["depth_ratio"][0] - 1e-9 <= sy / sx <= RANGES["depth_ratio"][1] + 1e-9
        assert 0 < sp.dorsal.start_section < sp.dorsal.end_section < sp.body_sections
        assert sp.anal.start_section > sp.dorsal.start_section


def test_same_seed_same_species_and_texture():
    assert sample_files(42, "a") == sample_files(42, "a")
    assert sample_files(42, "a") != sample_files(43, "a")


@pytest.mark.parametrize("stride", [25])
def test_painted_samples_are_validator_clean(tmp_path, gltf_validator, stride):
    """Textured glbs of every 25th seed (20 files) through the Khronos validator here; the whole
    500 are validated by benchmarks/species.py."""
    import fishgen

    paths = []
    for seed in range(0, 500, stride):
        for name, data in sample_files(seed, f"s{seed}").items():
            (tmp_path / name).write_bytes(data)
        sp = load_species(tmp_path / f"s{seed}.txt")
        out = tmp_path / f"s{seed}.glb"
        fishgen.export(build_fish(sp), out)
        paths.append(out)
    gltf_validator(*paths)
