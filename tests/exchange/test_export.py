"""Exports: every format loads in trimesh and pygltflib; glTF validates clean; output is
byte-identical run to run."""
from __future__ import annotations

import numpy as np
import pygltflib
import pytest
import trimesh

from fishgen.assembly.fish import build_fish
from fishgen.errors import FishgenError
from fishgen.exchange import export
from fishgen.exchange.gltf import glb_bytes
from fishgen.species.parser import load_species
from tests.conftest import PARAMS, assert_valid_gltf

SPECIES = sorted(PARAMS.glob("*.txt"))


def primitives(scene):
    return {n.name: scene.meshes[n.mesh].primitives[0] for n in scene.nodes if n.mesh is not None}


@pytest.fixture(scope="module")
def assets():
    return {p.stem: build_fish(load_species(p)) for p in SPECIES}


def test_every_species_and_fin_mode_validates_clean(tmp_path):
    files = []
    for path in SPECIES:
        sp = load_species(path)
        for mode in ("blend", "mask", "opaque"):
            out = tmp_path / f"{path.stem}_{mode}.glb"
            export(build_fish(sp, fins=mode), out)
            files.append(out)
        files += export(build_fish(sp), tmp_path / f"{path.stem}.gltf")[:1]
    assert_valid_gltf(*files)


def test_glb_round_trips_through_pygltflib(assets, tmp_path):
    out = tmp_path / "bony.glb"
    export(assets["bonybream"], out)
    doc = pygltflib.GLTF2().load(str(out))
    names = [n.name for n in doc.nodes]
    assert (doc.scenes[0].nodes == [0] and names[0] == "bonybream"
            and doc.nodes[0].children == list(range(1, 10)))
    assert "caudal_fin" in names and "pelvic_fin_right" in names
    (anim,) = doc.animations
    assert (anim.name == "swim"
            and sorted(c.target.path for c in anim.channels) == ["rotation"] * 4 + ["weights"] * 9)
    assert {m.alphaMode for m in doc.materials} == {"OPAQUE", "MASK"}
    assert doc.materials[1].doubleSided


def test_glb_round_trips_through_trimesh(assets, tmp_path):
    from fishgen.scene.pose import bounds
    asset = assets["centroberyx"]
    out = tmp_path / "c.glb"
    export(asset, out)
    scene = trimesh.load(out)
    prims = primitives(asset)
    assert len(scene.geometry) == len(prims)
    body = scene.geometry["body"]
    assert len(body.vertices) == prims["body"].vertex_count
    assert body.visual.uv is not None and np.allclose(body.visual.uv[:, 0],
                                                      prims["body"].attributes["TEXCOORD_0"][:, 0], atol=1e-6)
    assert np.allclose(scene.bounds, bounds(asset), atol=1e-5)


def test_gltf_writes_buffer_and_texture_beside_it(assets, tmp_path):
    files = export(assets["pineapplefish"], tmp_path / "p.gltf")
    assert sorted(f.name for f in files) == ["p.bin", "p.gltf", "p_skin.png"]
    assert len(trimesh.load(tmp_path / "p.gltf").geometry) == len(primitives(assets["pineapplefish"]))


def test_obj_with_mtl_and_texture(assets, tmp_path):
    files = export(assets["bonybream"], tmp_path / "b.obj")
    assert sorted(f.name for f in files) == ["b.mtl", "b.obj", "b_skin.png", "b_skin_mask.png"]
    mtl = (tmp_path / "b.mtl").read_text()
    assert "map_Kd b_skin.png" in mtl and "map_d b_skin_mask.png" in mtl and "-imfchan" not in mtl
    from io import BytesIO

    from PIL import Image
    skin = Image.open(BytesIO((tmp_path / "b_skin.png").read_bytes()))
    mask = Image.open(BytesIO((tmp_path / "b_skin_mask.png").read_bytes()))
    assert mask.mode == "L" and np.array_equal(np.asarray(mask), np.asarray(skin)[..., 3])
    scene = trimesh.load(tmp_path / "b.obj")
    total = sum(len(g.faces) for g in scene.geometry.values())
    assert total == assets["bonybream"].counts()["triangles"]


def test_ply_rest_pose_with_normals_and_uvs(assets, tmp_path):
    export(assets["threadfingoldie"], tmp_path / "t.ply")
    mesh = trimesh.load(tmp_path / "t.ply", process=False)
    asset = assets["threadfingoldie"]
    assert len(mesh.vertices) == asset.counts()["vertices"]
    assert mesh.visual.uv is not None and mesh.visual.uv.shape == (len(mesh.vertices), 2)
    header = (tmp_path / "t.ply").read_bytes().split(b"end_header")[0].decode()
    assert "binary_little_endian" in header and "property float nx" in header and "property float s" in header


@pytest.mark.parametrize("ext", [".glb", ".gltf", ".obj", ".ply"])
def test_same_input_same_bytes(tmp_path, ext):
    sp = load_species(PARAMS / "bonybream.txt")
    a = export(build_fish(sp), tmp_path / "a" / f"fish{ext}")
    b = export(build_fish(load_species(PARAMS / "bonybream.txt")), tmp_path / "b" / f"fish{ext}")
    for fa, fb in zip(a, b, strict=True):
        assert fa.read_bytes() == fb.read_bytes(), fa.name


def test_animation_pose_matches_fin_motion(assets):
    """Sample the glb's own keys: a pectoral fin is at +movement angle a quarter period in."""
    import io
    doc = pygltflib.GLTF2.load_from_bytes(glb_bytes(assets["bonybream"]))
    blob = doc.binary_blob()
    anim = doc.animations[0]
    node_names = [n.name for n in doc.nodes]
    ch = next(c for c in anim.channels if node_names[c.target.node] == "pectoral_fin_left")
    sampler = anim.samplers[ch.sampler]

    def read(index, width):
        acc = doc.accessors[index]
        view = doc.bufferViews[acc.bufferView]
        return np.frombuffer(io.BytesIO(blob[view.byteOffset:view.byteOffset + view.byteLength]).read(),
                             dtype=np.float32).reshape(-1, width)
    times, quats = read(sampler.input, 1)[:, 0], read(sampler.output, 4)
    k = np.searchsorted(times, 4 / 30)                   # 4 degrees at 1 degree a frame
    assert times[k] == pytest.approx(4 / 30)
    assert np.degrees(2 * np.arcsin(np.linalg.norm(quats[k, :3]))) == pytest.approx(4.0, abs=1e-4)


def test_unknown_extension(assets, tmp_path):
    with pytest.raises(FishgenError,
                       match="expected an output ending in .glb, .gltf, .obj, .ply, .csv, .npy"):
        export(assets["bonybream"], tmp_path / "fish.fbx")
    with pytest.raises(FishgenError, match="holds node animation, found .obj .* use .glb or .gltf or "
                                             ".usdc or .usda or .usdz instead"):
        export(assets["bonybream"], tmp_path / "fish.obj", require=["node animation"])
    assert list(tmp_path.iterdir()) == []


def test_a_read_obj_exports_to_glb_with_its_texture(assets, tmp_path):
    """The OBJ reader keeps decoded pixels only; writers encode them rather than write an empty image."""
    from fishgen.preview.inputs import load_input

    export(assets["bonybream"], tmp_path / "b.obj")
    scene = load_input(tmp_path / "b.obj")
    assert scene.images and all(image.data == b"" for image in scene.images)
    export(scene, tmp_path / "again.glb")
    assert_valid_gltf(tmp_path / "again.glb")
    doc = pygltflib.GLTF2().load(str(tmp_path / "again.glb"))
    view = doc.bufferViews[doc.images[0].bufferView]
    assert doc.images[0].mimeType == "image/png" and view.byteLength > 1000


def test_images_named_by_their_files_get_one_extension_beside_a_gltf_and_never_share_a_file(tmp_path):
    """A texture cloud's images are named 'billow.png': side files were x_billow.png.png, and two
    different images of one name went to one file."""
    from fishgen.exchange.sidefiles import image_side_stems
    from fishgen.scene.model import Image, Material, Scene

    assert image_side_stems("x", ["billow.png", "skin", "Wisp.JPEG", "billow.png", "billow"]) == \
        ["x_billow", "x_skin", "x_Wisp", "x_billow_2", "x_billow_3"]
    assert image_side_stems("my fish", ["gaussian sprite", "sky/é  x.png", "gaussian_sprite"]) == \
        ["my fish_gaussian_sprite", "my fish_sky_x", "my fish_gaussian_sprite_2"]
    scene = Scene("two billows")
    first, second = (np.zeros((2, 2, 4), np.uint8), np.full((2, 2, 4), 255, np.uint8))
    for k, pixels in enumerate((first, second)):
        texture = scene.add_image(Image("billow.png", b"", pixels=pixels))
        scene.add_material(Material(f"m{k}", texture=texture))
    written = export(scene, tmp_path / "x.gltf")
    assert sorted(p.name for p in written) == ["x.bin", "x.gltf", "x_billow.png", "x_billow_2.png"]


def test_a_textured_ply_reads_back_at_the_textures_own_colour(tmp_path):
    """PLY names a texture and no colour: trimesh's default grey (102) multiplied the texture, and a
    PLY fish previewed 2.5x darker than the same fish as OBJ or glTF (QA)."""
    from fishgen.exchange.mesh_reader import read_mesh_file

    fish = build_fish(load_species(PARAMS / "bonybream.txt"))
    export(fish, tmp_path / "bb.ply")
    export(fish, tmp_path / "bb.obj")
    ply, obj = (read_mesh_file(tmp_path / name) for name in ("bb.ply", "bb.obj"))
    textured = [m for m in ply.materials if m.texture is not None]
    assert textured and all(m.base_color[:3] == (1.0, 1.0, 1.0) for m in textured)
    assert [m.base_color for m in obj.materials if m.texture is not None][0][:3] == (1.0, 1.0, 1.0)
