"""The USD writer: a fish is a skinned UsdSkel mesh that poses as fishgen poses it, a school a
PointInstancer whose copies follow the tracks the glb keys; usd-core reads both back, its
validators find nothing, the same seed writes the same bytes, and Blender 5's importer loads them
(skipped without a Python that has bpy)."""
from __future__ import annotations

import importlib.util
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from fishgen.school.scene_file import MAX_FISH, MAX_FRAMES
from tests.assembly.engine_clients import BPY
from tests.cli_runner import run_cli

pxr = pytest.importorskip("pxr")
from pxr import Usd, UsdGeom, UsdSkel, UsdValidation  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
BONYBREAM = ROOT / "params" / "bonybream.txt"
BLENDER_SCRIPT = Path(__file__).resolve().parent / "usd" / "blender_usd.py"
SCHOOL = ("--count", "12", "--frames", "45", "--seed", "3")


def _school(tmp_path: Path, name: str, *extra: str) -> Path:
    out = tmp_path / name
    made = run_cli("school", BONYBREAM, "-o", out, *SCHOOL, "-q", *extra)
    assert made.returncode == 0, made.stderr
    return out


def _fish(tmp_path: Path, name: str, *extra: str) -> Path:
    out = tmp_path / name
    made = run_cli("build", BONYBREAM, "-o", out, "-q", *extra)
    assert made.returncode == 0, made.stderr
    return out


def _instancer(stage) -> UsdGeom.PointInstancer:
    return next(UsdGeom.PointInstancer(p) for p in stage.Traverse() if p.IsA(UsdGeom.PointInstancer))


def _validation_errors(path: Path) -> list[str]:
    validators = UsdValidation.ValidationRegistry().GetOrLoadAllValidators()
    errors = UsdValidation.ValidationContext(validators).Validate(Usd.Stage.Open(str(path)))
    return [f"{e.GetName()}: {e.GetMessage()}" for e in errors]


def _fish_scene(merge: bool):
    from fishgen.assembly.fish import build_fish
    from fishgen.species.parser import load_species

    return build_fish(load_species(BONYBREAM), merge=merge)


# -- one fish ------------------------------------------------------------------------------------

@pytest.mark.parametrize("merge", [False, True], ids=["parts", "merged"])
def test_a_fish_skins_in_usd_as_fishgen_poses_it(tmp_path, merge):
    """Every vertex usd-core's own skinning (UsdSkelBakeSkinning) puts at a frame is where
    fishgen's pose puts it: the parts' rigid joints, --merge's skin weights and the body wave's
    blend shapes all carried over."""
    from fishgen.scene.pose import deformed, pose

    path = _fish(tmp_path, "fish.usda", *(["--merge"] if merge else []))
    scene = _fish_scene(merge)
    stage = Usd.Stage.Open(str(path))
    assert stage.GetDefaultPrim().IsA(UsdSkel.Root)
    assert (stage.GetStartTimeCode(), stage.GetTimeCodesPerSecond()) == (0, 30)
    assert stage.GetEndTimeCode() == round(scene.clip("swim").duration * 30)
    anim = next(UsdSkel.Animation(p) for p in stage.Traverse() if p.IsA(UsdSkel.Animation))
    assert len(anim.GetRotationsAttr().GetTimeSamples()) == stage.GetEndTimeCode() + 1
    assert list(anim.GetBlendShapesAttr().Get()) == ["wave_sin_pos", "wave_sin_neg", "wave_cos_pos",
                                                     "wave_cos_neg"]
    UsdSkel.BakeSkinning(stage.Traverse())
    meshes = [UsdGeom.Mesh(p) for p in stage.Traverse() if p.IsA(UsdGeom.Mesh)]
    assert len(meshes) == len(scene.drawn())
    for frame in (0, 17, 50):
        posed = pose(scene, frame / 30, "swim")
        ours = np.concatenate([deformed(scene, n, p, posed)[0] for n, p in scene.drawn()])
        theirs = []
        for mesh in meshes:
            points = np.array(mesh.GetPointsAttr().Get(frame), float)
            world = np.array(mesh.ComputeLocalToWorldTransform(frame))
            theirs.append(points @ world[:3, :3] + world[3, :3])
        assert np.abs(np.concatenate(theirs) - ours).max() < 1e-6


def test_a_fish_keeps_its_materials_and_texture(tmp_path):
    path = _fish(tmp_path, "fish.usdc")
    assert (tmp_path / "fish_skin.png").is_file()
    stage = Usd.Stage.Open(str(path))
    from pxr import UsdShade

    bound = {UsdShade.MaterialBindingAPI(p).ComputeBoundMaterial()[0].GetPrim().GetName()
             for p in stage.Traverse() if p.IsA(UsdGeom.Mesh)}
    assert bound == {"bonybream_body", "bonybream_fins"}
    fins = stage.GetPrimAtPath("/bonybream/Looks/bonybream_fins/Surface")
    assert UsdShade.Shader(fins).GetInput("opacityThreshold").Get() == pytest.approx(0.5)
    texture = UsdShade.Shader(stage.GetPrimAtPath("/bonybream/Looks/bonybream_body/BaseColor"))
    assert texture.GetInput("file").Get().resolvedPath.endswith("fish_skin.png")


def test_a_fish_keeps_its_swim_clip_and_says_what_usd_leaves_out(tmp_path):
    """One animation a skeleton: the swim clip, wherever --clips lists it; the finest level only."""
    out = tmp_path / "fish.usda"
    made = run_cli("build", BONYBREAM, "-o", out, "--clips", "idle,swim", "--lods", "32x24,8x6")
    assert made.returncode == 0, made.stderr
    assert "swim loop 3.20 s" in made.stdout and "clips idle" not in made.stdout
    assert "(USDA holds no levels of detail or more than one clip)" in made.stdout
    stage = Usd.Stage.Open(str(out))
    assert stage.GetEndTimeCode() == 96
    assert len([p for p in stage.Traverse() if p.IsA(UsdGeom.Mesh)]) == 9      # 32x24's parts alone


def test_usdz_packages_the_texture_and_needs_nothing_beside_it(tmp_path):
    path = _fish(tmp_path, "fish.usdz")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fish.usdz"]
    import zipfile

    with zipfile.ZipFile(path) as package:
        assert package.namelist() == ["fish.usdc", "fish_skin.png"]


# -- a school -------------------------------------------------------------------------------------

def test_a_school_is_one_point_instancer_keyed_every_frame(tmp_path):
    path = _school(tmp_path, "school.usdc", "--prototypes", "3")
    stage = Usd.Stage.Open(str(path))
    assert (stage.GetStartTimeCode(), stage.GetEndTimeCode(), stage.GetTimeCodesPerSecond()) == (0, 44, 30)
    points = _instancer(stage)
    index = np.array(points.GetProtoIndicesAttr().Get())
    prototypes = points.GetPrototypesRel().GetTargets()
    assert len(index) == 12 and len(prototypes) == 3 and set(index) <= {0, 1, 2}
    assert all(stage.GetPrimAtPath(p).IsA(UsdSkel.Root) for p in prototypes)
    for attr in (points.GetPositionsAttr(), points.GetOrientationsAttr(), points.GetExtentAttr()):
        assert attr.GetTimeSamples() == [float(f) for f in range(45)]
    for frame in (0, 22, 44):
        # the extent written is the one usd-core computes from the prototypes' own extents
        ours = np.array(points.GetExtentAttr().Get(frame))
        theirs = np.array(points.ComputeExtentAtTime(frame, frame))
        assert np.abs(ours - theirs).max() < 1e-5
        assert (np.array(points.GetPositionsAttr().Get(frame)) >= ours[0]).all()


def test_the_prototypes_swim_phase_shifted(tmp_path):
    """Prototype k's swim starts k/4 of a loop in: its pose at frame 0 is prototype 0's a quarter
    loop later."""
    path = _school(tmp_path, "school.usda")
    stage = Usd.Stage.Open(str(path))
    prototypes = _instancer(stage).GetPrototypesRel().GetTargets()
    assert len(prototypes) == 4
    loop = _fish_scene(False).clip("swim").duration * 30   # frames
    anims = [UsdSkel.Animation(stage.GetPrimAtPath(f"{p}/Skeleton/Animation")) for p in prototypes]
    first = np.array(anims[1].GetBlendShapeWeightsAttr().Get(0))
    later = np.array(anims[0].GetBlendShapeWeightsAttr().Get(round(loop / 4)))
    assert np.abs(first - later).max() < 0.05
    assert np.abs(np.array(anims[0].GetBlendShapeWeightsAttr().Get(0)) - first).max() > 0.5


def test_orientations_are_unit_half_quaternions_that_match_the_glb(tmp_path):
    """Same seed, two files: every fish's USD position and orientation at a frame is the glb's
    thinned keys evaluated there, within the bake's tolerance and half precision."""
    from fishgen.exchange.gltf_reader import read_gltf
    from fishgen.scene.pose import sample

    usd = Usd.Stage.Open(str(_school(tmp_path, "school.usdc")))
    glb = read_gltf(_school(tmp_path, "school.glb"))
    clip = glb.clip()
    keys = {(c.node, c.path): c for c in clip.channels}
    points = _instancer(usd)
    assert points.GetOrientationsAttr().GetTypeName() == "quath[]"
    for frame in (0, 13, 44):
        turns = np.array([[*q.GetImaginary(), q.GetReal()] for q in points.GetOrientationsAttr().Get(frame)])
        places = np.array(points.GetPositionsAttr().Get(frame))
        assert np.abs(np.linalg.norm(turns, axis=1) - 1).max() < 2e-3
        for fish, root in enumerate(glb.roots):
            q = sample(keys[(root, "rotation")], frame / 30)
            p = sample(keys[(root, "translation")], frame / 30)
            assert min(np.abs(turns[fish] - q).max(), np.abs(turns[fish] + q).max()) < 5e-3
            assert np.abs(places[fish] - p).max() < 3e-3
    scales = np.array(points.GetScalesAttr().Get())
    assert np.allclose(scales[:, 0], [glb.nodes[r].scale[0] for r in glb.roots])


@pytest.mark.parametrize("suffix", [".usda", ".usdc", ".usdz"])
def test_the_same_seed_writes_the_same_bytes(tmp_path, monkeypatch, suffix):
    first = _school(tmp_path, "a" + suffix).read_bytes()
    fish = _fish(tmp_path, "f" + suffix).read_bytes()
    monkeypatch.setenv("TZ", "Pacific/Auckland")   # a package records local file times
    time.tzset()
    try:
        (tmp_path / "b").mkdir()
        assert _school(tmp_path, "b/a" + suffix).read_bytes() == first
        assert _fish(tmp_path, "b/f" + suffix).read_bytes() == fish
    finally:
        monkeypatch.undo()
        time.tzset()


@pytest.mark.parametrize("which", ["fish.usdz", "school.usdc"])
def test_usd_validators_find_nothing(tmp_path, which):
    path = _fish(tmp_path, which) if which.startswith("fish") else _school(tmp_path, which)
    assert _validation_errors(path) == []


def test_a_batch_manifest_writes_usd_and_sets_the_prototypes(tmp_path):
    manifest = tmp_path / "m.toml"
    manifest.write_text(f"""[[school]]
input = "{BONYBREAM.as_posix()}"
output = "s.usdc"
count = 6
frames = 10
prototypes = 2
""")
    made = run_cli("batch", manifest, "-j", "1", "--out", tmp_path / "out")
    assert made.returncode == 0, made.stderr
    stage = Usd.Stage.Open(str(tmp_path / "out" / "s.usdc"))
    assert len(_instancer(stage).GetPrototypesRel().GetTargets()) == 2


# -- refusals -------------------------------------------------------------------------------------

def test_without_usd_core_the_command_says_so_before_any_work(tmp_path, monkeypatch):
    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec",
                        lambda name, *a: None if name == "pxr" else real(name, *a))
    # a school too big to simulate: the missing package is said first, before the size is judged
    for args in (("build", BONYBREAM), ("school", BONYBREAM, "--count", str(MAX_FISH), "--frames",
                                        str(MAX_FRAMES))):
        made = run_cli(*args, "-o", tmp_path / "x.usdc")
        assert made.returncode == 1
        assert made.stderr.strip().splitlines() == [
            "fishgen: writing .usdc needs usd-core (pxr), which is not installed; install it with "
            "pip install 'fishgen[usd]'"]
    assert list(tmp_path.iterdir()) == []


def test_a_cloud_as_usd_is_refused_for_its_format_first_not_for_a_missing_package(tmp_path, monkeypatch):
    """Without usd-core, `clouds -o x.usdc` said to install it, and once installed refused the format."""
    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec",
                        lambda name, *a: None if name == "pxr" else real(name, *a))
    made = run_cli("clouds", ROOT / "params" / "clouds" / "table_4_3.awn", "-o", tmp_path / "c.usdc")
    assert made.returncode == 2 and "expected a format that holds points" in made.stderr, made.stderr


def test_colour_variants_are_prototypes_that_each_fish_wears_as_in_the_glb(tmp_path):
    """--tints 2: a species' prototypes come in both colours, and each fish wears in USD the body
    colour it wears in the glb of the same seed."""
    from pxr import UsdShade

    from fishgen.exchange.gltf_reader import read_gltf

    usd = Usd.Stage.Open(str(_school(tmp_path, "school.usda", "--tints", "2", "--tint", "0.5")))
    glb = read_gltf(_school(tmp_path, "school.glb", "--tints", "2", "--tint", "0.5"))
    points = _instancer(usd)
    prototypes = points.GetPrototypesRel().GetTargets()
    index = points.GetProtoIndicesAttr().Get()
    assert len(prototypes) == len(set(index)) <= 2 * 4    # only the prototypes some fish is
    assert {p.name.rsplit("_", 1)[0] for p in prototypes} == {"bonybream", "bonybream_tint1"}
    colours = set()
    for fish, root in enumerate(glb.roots):
        body = next(c for c in glb.nodes[root].children if glb.nodes[c].name == "body")
        material = glb.materials[glb.meshes[glb.nodes[body].mesh].primitives[0].material]
        looks = usd.GetPrimAtPath(prototypes[index[fish]].AppendPath("Looks"))
        texture = next(UsdShade.Shader(p) for p in Usd.PrimRange(looks)
                       if p.GetName() == "BaseColor" and "body" in p.GetParent().GetName())
        assert np.allclose(texture.GetInput("scale").Get(), material.base_color, atol=1e-6)
        colours.add(tuple(round(c, 4) for c in material.base_color))
    assert len(colours) == 2


def test_clouds_cannot_be_written_as_usd(tmp_path):
    made = run_cli("clouds", ROOT / "params" / "clouds" / "table_4_3.awn", "-o", tmp_path / "c.usdc")
    assert made.returncode == 2 and "points" in made.stderr


# -- Blender 5 ------------------------------------------------------------------------------------

def _blender(path: Path, *frames: int) -> dict:
    run = subprocess.run([BPY, str(BLENDER_SCRIPT), str(path), *map(str, frames)], capture_output=True,
                         text=True, timeout=600)
    assert run.returncode == 0, run.stderr[-2000:]
    return json.loads(next(line for line in run.stdout.splitlines() if line.startswith("{")))


def _from_blender(low: list[float], high: list[float]) -> np.ndarray:
    """A box in Blender's Z-up axes back in the file's Y-up ones (the importer turns +Y into +Z)."""
    return np.array([[low[0], low[2], -high[1]], [high[0], high[2], -low[1]]])


@pytest.mark.skipif(BPY is None, reason="no Python with bpy ($FISHGEN_BPY_PYTHON)")
def test_blender_imports_a_fish_that_swims_as_fishgen_poses_it(tmp_path):
    from fishgen.scene.pose import bounds

    path = _fish(tmp_path, "fish.usdz")
    scene = _fish_scene(False)
    report = _blender(path, 0, 20, 50)
    assert (report["frame_start"], report["frame_end"]) == (0, round(scene.clip("swim").duration * 30))
    for frame in (0, 20, 50):
        seen = report["frames"][str(frame)]
        box = _from_blender(seen["low"], seen["high"])
        assert np.abs(box - bounds(scene, frame / 30, "swim")).max() < 1e-6


@pytest.mark.skipif(BPY is None, reason="no Python with bpy ($FISHGEN_BPY_PYTHON)")
def test_blender_imports_the_school_with_its_instances_frame_range_and_bounds(tmp_path):
    """Blender's importer places one copy of a prototype per fish (as many of each as protoIndices
    names), takes the frame range, and at each frame draws the fish inside the box fishgen's own
    pose of each prototype, moved by the tracks, gives."""
    from fishgen.scene.pose import deformed, pose, quat_matrices
    from fishgen.school.run import run_school
    from fishgen.school.scene_file import SceneFile, SpeciesEntry

    run = run_school(SceneFile(species=(SpeciesEntry(BONYBREAM, 12),), frames=45, seed=3), prototypes=4)
    (crowd,) = run.scene.instancers
    path = tmp_path / "school.usdc"
    from fishgen.exchange.usd import write_usd

    write_usd(run.scene, path)
    report = _blender(path, 0, 30, 44)
    assert (report["frame_start"], report["frame_end"]) == (0, 44)
    counts = np.bincount(crowd.proto_indices, minlength=4)
    for frame in (0, 30, 44):
        seen = report["frames"][str(frame)]
        assert seen["points"] == 12 and seen["direct"] == 0       # the prototypes are drawn only as copies
        assert {name: n for name, n in seen["roots"].items() if name.startswith("bonybream")} == \
            {f"bonybream_{k}": int(counts[k]) for k in range(4) if counts[k]}
        posed = []
        for fish, proto in enumerate(crowd.proto_indices):
            scene = crowd.prototypes[proto]
            at = pose(scene, frame / 30, scene.clip())
            points = np.concatenate([deformed(scene, n, p, at)[0] for n, p in scene.drawn()])
            turn = quat_matrices(crowd.orientations[frame, fish])
            posed.append(points * crowd.scales[fish] @ turn.T + crowd.positions[frame, fish])
        every = np.concatenate(posed)
        expected = np.stack([every.min(axis=0), every.max(axis=0)])
        # fishgen turns by the float orientations, Blender by the file's halves
        assert np.abs(_from_blender(seen["low"], seen["high"]) - expected).max() < 1e-3




def test_an_image_named_by_its_file_keeps_one_extension_beside_a_usd_file(tmp_path):
    """An image named 'billow.png' (as a texture cloud names its images) was written x_billow_png.png
    beside a USD file, where glTF, OBJ and PLY write x_billow.png."""
    import dataclasses

    from fishgen.assembly.fish import make_fish
    from fishgen.exchange import export
    from fishgen.species.parser import load_species
    from tests.conftest import PARAMS

    scene = make_fish(load_species(PARAMS / "bonybream.txt")).scene
    scene.images[0] = dataclasses.replace(scene.images[0], name="billow.png")
    written = export(scene, tmp_path / "x.usda")
    assert sorted(p.name for p in written) == ["x.usda", "x_billow.png"]
    assert "@./x_billow.png@" in (tmp_path / "x.usda").read_text()


def test_a_school_to_usd_says_what_its_prototypes_leave_out(tmp_path):
    """`--lods` keeps the finest level in USD and `--compact` changes nothing there; `fishgen build`
    said so and `fishgen school` did not."""
    from tests.conftest import PARAMS

    args = ("school", PARAMS / "bonybream.txt", "--count", "3", "--frames", "10", "--lods", "16x12,8x6")
    usd = run_cli(*args, "--compact", "-o", tmp_path / "s.usdc")
    assert usd.returncode == 0, usd.stderr
    assert usd.stdout.splitlines()[0].endswith("(USDC holds no levels of detail or compact keys) (+1 file)")
    glb = run_cli(*args, "-o", tmp_path / "s.glb")
    assert glb.returncode == 0 and "holds no" not in glb.stdout


@pytest.mark.skipif(os.name != "posix" or sys.platform == "darwin", reason="a file name that is not UTF-8")
def test_a_name_whose_bytes_are_not_utf8_is_refused_in_one_line(tmp_path):
    """USD names its files in UTF-8 text; a latin-1 byte in the name (``caf\\xe9``) was a traceback
    inside usd-core."""
    out = tmp_path / "caf\udce9.usda"        # the byte 0xE9, as Python spells it
    result = run_cli("build", BONYBREAM, "-o", out)
    assert result.returncode == 2 and result.stderr.count("\n") == 1, result.stderr
    assert "expected a file name whose bytes are UTF-8" in result.stderr and list(tmp_path.iterdir()) == []
