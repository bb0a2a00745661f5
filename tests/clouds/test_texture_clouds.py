"""Texture clouds (.awa): the format, its one-line errors, where textures may come from, the fill
and the textured, lit billboards they export to."""
from __future__ import annotations

import io
import os

import numpy as np
import pytest
from cloud_tables import PARAMS
from PIL import Image

from fishgen.clouds import export_cloud, fill_cloud, light_cloud, load_cubes
from fishgen.clouds.scene import cloud_scene, cube_file_scene
from fishgen.errors import FishgenError

SKY = PARAMS / "sky.awa"
TEXTURES = PARAMS.parents[1] / "textures" / "clouds"


@pytest.fixture
def folder(tmp_path):
    """A folder with a .awa file's neighbours: a PNG beside it and one in textures/ beside that."""
    (tmp_path / "sky").mkdir()
    (tmp_path / "textures").mkdir()
    puff = np.zeros((16, 16, 4), np.uint8)
    puff[4:12, 4:12] = 255
    Image.fromarray(puff, "RGBA").save(tmp_path / "sky" / "near.png")
    Image.fromarray(puff, "RGBA").save(tmp_path / "textures" / "far.png")
    return tmp_path


def write(folder, text: str, name: str = "sky/test.awa"):
    path = folder / name
    path.write_text(text)
    return path


def test_the_shipped_example_reads_like_the_reports_tables():
    cubes = load_cubes(SKY)
    assert cubes.total == cubes.declared_total == 60 and len(cubes.cubes) == 6
    used = {os.path.basename(c.texture) for c in cubes.cubes}
    assert used == {"billow.png", "cumulus.png", "wisp.png"}
    assert all(os.path.dirname(c.texture) == str(TEXTURES) for c in cubes.cubes)
    first = cubes.cubes[0]
    assert ((first.particles, first.size, first.centre, first.max_radius)
            == (14, (7.4, 1.1, 2.9), (-3.4, -3.3, -0.6), 3.6))


def test_textures_resolve_beside_the_file_and_in_textures_beside_it(folder):
    path = write(folder, "3\n2\n1, 1, 1, 1, 0, 0, 0, 1, near.png\n2, 1, 1, 1, 2, 0, 0, 1, far.png\n")
    a, b = load_cubes(path).cubes
    assert a.texture == str((folder / "sky" / "near.png").resolve())
    assert b.texture == str((folder / "textures" / "far.png").resolve())
    elsewhere = folder / "elsewhere"
    elsewhere.mkdir()
    (folder / "sky" / "near.png").rename(elsewhere / "near.png")
    only = write(folder, "1\n1\n1, 1, 1, 1, 0, 0, 0, 1, near.png\n", "sky/only.awa")
    cubes = load_cubes(only, textures_dir=elsewhere)     # --textures DIR: that folder only
    assert cubes.cubes[0].texture == str((elsewhere / "near.png").resolve())
    with pytest.raises(FishgenError, match="found 'far.png' missing from"):
        load_cubes(path, textures_dir=elsewhere)


@pytest.mark.parametrize("line,message", [
    ("1, 1, 1, 1, 0, 0, 0, 1", "expected 9 fields (billboards, x y z size, centre x y z, maximum radius, "
                               "texture), found 8 fields"),
    ("1, 1, 1, 1, 0, 0, 0, 1, near.jpg", "expected a texture file name ending in .png, found 'near.jpg'"),
    ("1, 1, 1, 1, 0, 0, 0, 1, gone.png", "expected an existing texture file, found 'gone.png' missing from"),
    ("1, 1, 1, 1, 0, 0, 0, 1, ../../secret.png", "expected a texture path inside"),
    ("1, 1, 1, 1, 0, 0, 0, 1, /etc/passwd.png", "expected a texture path inside"),
    ("x, 1, 1, 1, 0, 0, 0, 1, near.png", "expected a whole number for the billboard count, found 'x'"),
    ("1, 0, 1, 1, 0, 0, 0, 1, near.png", "expected an x size greater than 0, found '0'"),
])
def test_a_bad_cube_line_is_one_line_naming_file_and_line(folder, line, message):
    path = write(folder, f"1\n1\n\n{line}\n")
    with pytest.raises(FishgenError) as err:
        load_cubes(path)
    assert str(err.value).startswith(f"{path}:4: {message}") and "\n" not in str(err.value)


def test_a_link_out_of_the_folders_is_refused(folder, tmp_path_factory):
    outside = tmp_path_factory.mktemp("outside")
    Image.new("RGBA", (4, 4)).save(outside / "x.png")
    (folder / "sky" / "link.png").symlink_to(outside / "x.png")
    with pytest.raises(FishgenError, match="texture paths may not leave"):
        load_cubes(write(folder, "1\n1\n1, 1, 1, 1, 0, 0, 0, 1, link.png\n"))


def test_a_texture_that_is_not_an_image_is_refused(folder):
    (folder / "sky" / "fake.png").write_bytes(b"not a png")
    with pytest.raises(FishgenError,
                       match=r"test.awa:3: expected a texture image .* found 'fake.png' unreadable"):
        load_cubes(write(folder, "1\n1\n1, 1, 1, 1, 0, 0, 0, 1, fake.png\n"))


def test_a_texture_cut_off_after_its_header_is_refused(folder):
    """200 bytes of a PNG: its header read well, so a sky embedded it, and fishgen's own preview of
    that sky refused it (QA)."""
    import io

    data = io.BytesIO()
    Image.new("RGBA", (64, 64), (200, 200, 255, 128)).save(data, "PNG")
    (folder / "sky" / "cut.png").write_bytes(data.getvalue()[:60])
    with pytest.raises(FishgenError,
                       match=r"test.awa:3: expected a readable texture image, found 'cut.png' damaged"):
        load_cubes(write(folder, "1\n1\n1, 1, 1, 1, 0, 0, 0, 1, cut.png\n"))


def test_header_counts_say_billboards(folder):
    with pytest.raises(FishgenError,
                       match=r"test.awa:1: expected a whole number for the total billboard count"):
        load_cubes(write(folder, "many\n1\n1, 1, 1, 1, 0, 0, 0, 1, near.png\n"))


def test_each_cubes_billboards_are_placed_by_the_fill_inside_it():
    cubes = load_cubes(SKY)
    cloud = fill_cloud(cubes, seed=4)
    counts = np.bincount(cloud.cube_index, minlength=len(cubes.cubes))
    assert counts.tolist() == [c.particles for c in cubes.cubes]
    lo, hi = cloud.cube_bounds[cloud.cube_index, 0], cloud.cube_bounds[cloud.cube_index, 1]
    assert ((cloud.centers >= lo) & (cloud.centers <= hi)).all()
    assert cloud.textures == tuple(c.texture for c in cubes.cubes)


def test_export_makes_textured_lit_billboards(tmp_path, gltf_validator):
    cloud = light_cloud(fill_cloud(load_cubes(SKY), seed=0))
    path = tmp_path / "sky.glb"
    export_cloud(cloud, path, billboards=True)
    gltf_validator(path)
    scene = cloud_scene(cloud, billboards=True)
    (mesh,) = scene.meshes
    assert [scene.images[scene.materials[p.material].texture].name for p in mesh.primitives] == \
        ["billow.png", "cumulus.png", "wisp.png"]
    for prim in mesh.primitives:
        image = scene.images[scene.materials[prim.material].texture]
        assert image.data == (TEXTURES / image.name).read_bytes()      # the PNG as it is
        assert scene.materials[prim.material].alpha_mode == "BLEND" and "_LIGHT" in prim.attributes
    assert sum(p.vertex_count for p in mesh.primitives) == 12 * len(cloud)
    again = tmp_path / "again.glb"
    export_cloud(cloud, again, billboards=True)
    assert again.read_bytes() == path.read_bytes()


def test_the_preview_reader_takes_awa(gl_available):
    from fishgen.preview.pipeline import frame_scene
    from fishgen.preview.render import Renderer

    scene = cube_file_scene(SKY)
    assert scene.counts()["triangles"] == 6 * 60 and len(scene.images) == 3
    renderer = Renderer(200, 150)
    try:
        image = renderer.render(scene, frame_scene(scene, "front", 4 / 3), None,
                                (0, 0, 0, 0))
    finally:
        renderer.release()
    assert (image[..., 3] > 128).mean() > 0.01


@pytest.mark.parametrize("kind,mime", [("JPEG", "image/jpeg"), ("GIF", "image/png")])
def test_a_texture_goes_into_gltf_as_what_its_bytes_are(folder, kind, mime, gltf_validator):
    """A JPEG named .png was declared image/png (the validator's IMAGE_MIME_TYPE_INVALID); a GIF,
    which glTF does not take, is written as PNG."""
    Image.new("RGB", (16, 16), (200, 210, 230)).save(folder / "sky" / "near.png", format=kind)
    cloud = light_cloud(fill_cloud(load_cubes(write(folder, "4\n1\n4, 1, 1, 1, 0, 0, 0, 1, near.png\n")),
                                   seed=0))
    path = folder / "out.glb"
    export_cloud(cloud, path, billboards=True)
    gltf_validator(path)
    scene = cloud_scene(cloud, billboards=True)
    (image,) = scene.images
    assert image.mime_type == mime
    assert Image.open(io.BytesIO(image.encoded())).format == mime.split("/")[1].upper()
