"""USD writer (``.usda``, ``.usdc``, ``.usdz``): a fish as a skinned UsdSkel mesh, a school as a
UsdGeom PointInstancer of such fish. Needs usd-core (``pip install 'fishgen[usd]'``).

A scene's nodes become one Skeleton under a SkelRoot: every node a joint (parents first), its
meshes bound to it rigidly (a part of a fish) or through its skin (``--merge``), morph targets as
BlendShapes, and the swim clip (else the first) as one SkelAnimation keyed every frame at the
scene's frame rate; other clips and coarser levels of detail are left out.
A scene's :class:`~fishgen.scene.model.Instancer` becomes a PointInstancer whose prototypes are
such SkelRoots, its copies keyed every frame: positions, half-precision orientations and extents.
Metres, +Y up, glTF's axes; a time code is a frame. Textures are PNG files beside the file (inside
the package for ``.usdz``).
"""
from __future__ import annotations

import os
import re
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from fishgen.file_names import name_text
from fishgen.scene.model import Image, Instancer, Material, Scene
from fishgen.scene.pose import dequantized, pose, sample_many, trs_matrix

PACKAGE_TIME = (2000, 1, 1, 0, 0, 0, 0, 0, -1)
"""The local time recorded for every file in a ``.usdz`` (whatever the time zone), so that packages
are reproducible."""
DEFAULT_FPS = 30.0
"""Frames per second of a scene that does not say its own (:attr:`Scene.fps`)."""


def write_usd(scene: Scene, path: str | os.PathLike) -> list[Path]:
    """Write ``scene`` as USD in the encoding its extension names; returns the files written."""
    from fishgen.atomic import write_files
    from fishgen.errors import describe, expected
    from fishgen.exchange.sidefiles import check_shared

    path = Path(path)
    suffix = path.suffix.lower()
    try:
        name_text(path.name).encode("utf-8")
    except UnicodeEncodeError:
        raise expected("a file name whose bytes are UTF-8 (USD names its files in UTF-8)",
                       describe(path.name), path) from None
    pictures = _Pictures(path.stem)
    with tempfile.TemporaryDirectory(prefix="fishgen-usd-") as work:
        # ASCII names in the work folder: usd-core takes paths as UTF-8 text, which a name the
        # locale does not spell in UTF-8 (its bytes kept as surrogates) is not
        folder = Path(work)
        inner = folder / ("layer" + (".usdc" if suffix == ".usdz" else suffix))
        stage = _stage(scene, pictures)   # held: the layer is the stage's, a weak handle
        stage.GetRootLayer().Export(str(inner))
        if suffix == ".usdz":
            from pxr import Sdf

            package = folder / ("package" + suffix)
            writer = Sdf.ZipFileWriter.CreateNew(str(package))
            # the layer first: usdz's default layer
            entries = [(inner, path.stem + ".usdc")]
            for k, (name, data) in enumerate(pictures.files.items()):
                local = folder / f"picture{k}.png"
                local.write_bytes(data)
                entries.append((local, name))
            for local, name in entries:
                # the archive records each file's local time: a fixed one keeps packages identical
                stamp = time.mktime(PACKAGE_TIME)
                os.utime(local, (stamp, stamp))
                writer.AddFile(str(local), name_text(name))
            writer.Save()
            files = {path: package.read_bytes()}
        else:
            files = {path: inner.read_bytes(),
                     **{path.parent / name: data for name, data in pictures.files.items()}}
    check_shared(path, files)
    write_files(files)
    return list(files)


@dataclass
class _Pictures:
    """The texture files: one per distinct picture, named after the USD file and the image (as
    the file system spells them; the layer names them by ``name_text``)."""

    stem: str
    files: dict[str, bytes] = field(default_factory=dict)
    named: dict[bytes, str] = field(default_factory=dict)

    def name(self, image: Image) -> str:
        data = image.encoded()
        if data not in self.named:
            from fishgen.exchange.sidefiles import image_stem

            base = f"{self.stem}_{_identifier(image_stem(image.name or 'texture'))}"
            name, k = f"{base}.png", 1
            while name in self.files:
                k += 1
                name = f"{base}_{k}.png"
            self.named[data], self.files[name] = name, data
        return self.named[data]


def _identifier(name: str) -> str:
    """A valid USD prim name (and joint or blend-shape token) for ``name``."""
    out = re.sub(r"[^A-Za-z0-9_]", "_", name.replace("+", "_pos").replace("-", "_neg")) or "_"
    return "_" + out if out[0].isdigit() else out


def _unique(names: list[str]) -> list[str]:
    seen: set[str] = set()
    out = []
    for name in names:
        candidate, k = name, 1
        while candidate in seen:
            k += 1
            candidate = f"{name}_{k}"
        seen.add(candidate)
        out.append(candidate)
    return out


def _clip(scene: Scene):
    """The one clip USD keeps (a skeleton has one animation): ``swim``, else the first."""
    return scene.clip("swim") or scene.clip()


def _fps(scene: Scene) -> float:
    return float(scene.fps) if scene.fps else DEFAULT_FPS


def _stage(scene: Scene, pictures: _Pictures) -> Any:
    from pxr import Sdf, Usd, UsdGeom

    stage = Usd.Stage.CreateInMemory()
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    fps = _fps(scene)
    if scene.instancers:
        frames = len(scene.instancers[0].times)
    else:
        clip = _clip(scene)
        frames = int(np.floor(clip.duration * fps + 1e-6)) + 1 if clip is not None and clip.channels else 1
    stage.SetTimeCodesPerSecond(fps)
    stage.SetFramesPerSecond(fps)
    stage.SetStartTimeCode(0)
    stage.SetEndTimeCode(float(frames - 1))
    times = np.arange(frames) / fps
    root = Sdf.Path("/" + _identifier(scene.name or "scene"))
    if scene.instancers:
        UsdGeom.Xform.Define(stage, root)
        names = _unique([_identifier(i.name or "instancer") for i in scene.instancers])
        for name, inst in zip(names, scene.instancers, strict=True):
            _instancer(stage, root.AppendChild(name), inst, times, pictures)
        if scene.roots:
            _skel_root(stage, root.AppendChild("scene"), scene, times, pictures)
    else:
        _skel_root(stage, root, scene, times, pictures)
    stage.SetDefaultPrim(stage.GetPrimAtPath(root))
    return stage


def _instancer(stage, where, inst: Instancer, times: np.ndarray, pictures: _Pictures) -> None:
    """A PointInstancer of ``inst``: its prototypes beneath it, each copy keyed every frame."""
    from pxr import Sdf, UsdGeom, Vt

    points = UsdGeom.PointInstancer.Define(stage, where)
    holder = where.AppendChild("Prototypes")
    stage.DefinePrim(holder, "Scope")
    names = _unique([_identifier(p.name or "prototype") for p in inst.prototypes])
    boxes = []
    paths: list[Sdf.Path] = []
    for name, proto in zip(names, inst.prototypes, strict=True):
        paths.append(holder.AppendChild(name))
        boxes.append(_skel_root(stage, paths[-1], proto, times, pictures))
    points.CreatePrototypesRel().SetTargets(paths)
    index = np.asarray(inst.proto_indices, np.int32)
    points.CreateProtoIndicesAttr(Vt.IntArray.FromNumpy(index))
    scales = np.repeat(np.asarray(inst.scales, np.float32)[:, None], 3, axis=1)
    points.CreateScalesAttr(Vt.Vec3fArray.FromNumpy(np.ascontiguousarray(scales)))
    positions = np.asarray(inst.positions, np.float32)
    turns = np.asarray(inst.orientations, np.float64)
    turns = turns / np.linalg.norm(turns, axis=2, keepdims=True)
    halves = turns.astype(np.float16)
    # the box of what a reader draws: from the half-precision turns the file holds
    extents = _instance_extents(np.stack(boxes)[index], positions, halves.astype(np.float64), scales)
    position_attr, turn_attr = points.CreatePositionsAttr(), points.CreateOrientationsAttr()
    extent_attr = points.CreateExtentAttr()
    for f in range(len(positions)):  # one whole array per time sample
        position_attr.Set(Vt.Vec3fArray.FromNumpy(positions[f]), float(f))
        turn_attr.Set(Vt.QuathArray.FromNumpy(halves[f]), float(f))
        extent_attr.Set(Vt.Vec3fArray.FromNumpy(extents[f]), float(f))


def _instance_extents(boxes: np.ndarray, positions: np.ndarray, turns: np.ndarray,
                      scales: np.ndarray) -> np.ndarray:
    """(F, 2, 3) per frame, the box around every copy's prototype box (N, 2, 3) scaled, turned and
    moved: what UsdGeomPointInstancer::ComputeExtentAtTime gives (a turned box's corners reach
    its turned centre plus or minus |R| times its half size). ``turns`` as the file holds them."""
    from fishgen.scene.pose import quat_matrices

    centre = 0.5 * (boxes[:, 0] + boxes[:, 1]) * scales                             # (N, 3)
    half = 0.5 * (boxes[:, 1] - boxes[:, 0]) * scales
    turn = quat_matrices(turns, normalize=False)    # (F, N, 3, 3), as usd-core turns the file's halves
    middle = np.einsum("fnij,nj->fni", turn, centre) + positions
    reach = np.einsum("fnij,nj->fni", np.abs(turn), half)
    return np.stack([(middle - reach).min(axis=1), (middle + reach).max(axis=1)], axis=1).astype(np.float32)


def _skel_root(stage, where, scene: Scene, times: np.ndarray, pictures: _Pictures) -> np.ndarray:
    """``scene``'s drawn nodes as a SkelRoot at ``where``: one Skeleton, its meshes and
    materials, and its clip (:func:`_clip`) sampled at ``times``. Returns the root's extent (2, 3),
    over every frame."""
    from pxr import Gf, UsdSkel, Vt

    skel_root = UsdSkel.Root.Define(stage, where)
    order = scene.reachable()
    slot = {node: k for k, node in enumerate(order)}
    tokens = _joint_tokens(scene, order)
    idents = [t.rsplit("/", 1)[-1] for t in tokens]
    rest = pose(scene)
    local = [_local_trs(scene, i) for i in order]
    binds = [rest.world[i] for i in order]
    for node in order:  # a skin's joints bind where its inverse bind matrices say
        skin = scene.nodes[node].skin
        if skin is not None:
            for joint, inverse in zip(scene.skins[skin].joints, scene.skins[skin].inverse_bind_matrices,
                                      strict=False):
                if joint in slot:
                    binds[slot[joint]] = np.linalg.inv(np.asarray(inverse, np.float64))
    skeleton = UsdSkel.Skeleton.Define(stage, where.AppendChild("Skeleton"))
    skeleton.CreateJointsAttr(tokens)
    skeleton.CreateBindTransformsAttr(Vt.Matrix4dArray([Gf.Matrix4d(m.T.tolist()) for m in binds]))
    rest_matrices = [trs_matrix(*trs) for trs in local]
    skeleton.CreateRestTransformsAttr(Vt.Matrix4dArray([Gf.Matrix4d(m.T.tolist()) for m in rest_matrices]))
    UsdSkel.BindingAPI.Apply(skel_root.GetPrim()).CreateSkeletonRel().SetTargets([skeleton.GetPath()])

    looks = where.AppendChild("Looks")
    stage.DefinePrim(looks, "Scope")
    material_paths = {m: _material(stage, looks, scene, m, pictures)
                      for m in sorted({p.material for _, p in scene.drawn() if p.material is not None})}
    shapes = _shape_channels(scene, order, idents)
    mesh_names: set[str] = set()
    for k, node in enumerate(order):
        mesh_index = scene.nodes[node].mesh
        if mesh_index is None:
            continue
        mesh = scene.meshes[mesh_index]
        triangles = [p for p in mesh.primitives if p.mode == "TRIANGLES" and p.indices is not None]
        for j, prim in enumerate(triangles):
            name = idents[k] if len(triangles) == 1 else f"{idents[k]}_{j}"
            while name in mesh_names or name in ("Skeleton", "Looks"):
                name += "_"
            mesh_names.add(name)
            _mesh(stage, where.AppendChild(name), scene, node, prim, slot, skeleton.GetPath(),
                  rest.world[node],
                  shapes.get(node, ([], None))[0], mesh.target_names,
                  None if prim.material is None else material_paths[prim.material])

    clip = _clip(scene)
    animated = clip is not None and bool(clip.channels)
    motion = _motion(scene, order, local, shapes, times if animated else times[:1])
    if animated:
        anim = UsdSkel.Animation.Define(stage, skeleton.GetPath().AppendChild("Animation"))
        UsdSkel.BindingAPI.Apply(skeleton.GetPrim()).CreateAnimationSourceRel().SetTargets([anim.GetPath()])
        _animation(anim, motion, tokens)
    box = _extent(scene, order, motion)
    skel_root.CreateExtentAttr(Vt.Vec3fArray.FromNumpy(box.astype(np.float32)))
    return box


def _shape_channels(scene: Scene, order: list[int], idents: list[str]) -> dict[int, tuple[list[str], Any]]:
    """Per node whose mesh has morph targets, its blend-shape channel names and the clip's weights
    channel driving them (None: the mesh's default weights). Nodes driven by one sampler share
    channels (a fish's parts all follow one body wave): the first such group is named by its targets
    alone, the others by their node too."""
    clip = _clip(scene)
    driver = {c.node: c for c in (clip.channels if clip else []) if c.path == "weights"}
    out: dict[int, tuple[list[str], Any]] = {}
    groups: dict[tuple[int, tuple[str, ...]], list[str]] = {}
    for k, node in enumerate(order):
        mesh_index = scene.nodes[node].mesh
        if mesh_index is None:
            continue
        mesh = scene.meshes[mesh_index]
        count = max((len(p.targets) for p in mesh.primitives if p.mode == "TRIANGLES"), default=0)
        if not count:
            continue
        targets = tuple(_unique([_identifier(n) for n in _target_names(mesh.target_names, count)]))
        channel = driver.get(node)
        key = (id(channel.sampler) if channel is not None else -1 - node, targets)
        if key not in groups:
            groups[key] = list(targets) if not groups else [f"{idents[k]}_{t}" for t in targets]
        out[node] = (groups[key], channel)
    return out


def _target_names(names: list[str], count: int) -> list[str]:
    return [names[t] if t < len(names) and names[t] else f"target{t}" for t in range(count)]


def _local_trs(scene: Scene, node: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    n = scene.nodes[node]
    if n.matrix is None:
        return (np.asarray(n.translation, float), np.asarray(n.rotation, float), np.asarray(n.scale, float))
    from pxr import Gf, UsdSkel

    t, r, s = UsdSkel.DecomposeTransform(Gf.Matrix4d(np.asarray(n.matrix, float).T.tolist()))
    return (np.array(t, float), np.array([*r.GetImaginary(), r.GetReal()], float), np.array(s, float))


def _mesh(stage, where, scene: Scene, node: int, prim, slot: dict[int, int], skeleton, rest_world: np.ndarray,
          channel_names: list[str], target_names: list[str], material) -> None:
    """One primitive as a Mesh bound to the skeleton: through its node's skin, else rigidly to
    its node's joint; its morph targets as BlendShapes beneath it."""
    from pxr import Gf, UsdGeom, UsdShade, UsdSkel, Vt

    mesh = UsdGeom.Mesh.Define(stage, where)
    positions = np.ascontiguousarray(prim.attributes["POSITION"], np.float32)
    indices = np.asarray(prim.indices, np.int32).reshape(-1, 3)
    mesh.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(positions))
    mesh.CreateFaceVertexCountsAttr(Vt.IntArray.FromNumpy(np.full(len(indices), 3, np.int32)))
    mesh.CreateFaceVertexIndicesAttr(Vt.IntArray.FromNumpy(np.ascontiguousarray(indices.ravel())))
    mesh.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.none)
    mesh.CreateExtentAttr(Vt.Vec3fArray.FromNumpy(np.stack([positions.min(axis=0), positions.max(axis=0)])))
    if "NORMAL" in prim.attributes:
        mesh.CreateNormalsAttr(Vt.Vec3fArray.FromNumpy(np.ascontiguousarray(prim.attributes["NORMAL"],
                                                                            np.float32)))
        mesh.SetNormalsInterpolation(UsdGeom.Tokens.vertex)
    if "TEXCOORD_0" in prim.attributes:
        uv = np.asarray(prim.attributes["TEXCOORD_0"], np.float32).copy()
        uv[:, 1] = 1.0 - uv[:, 1]   # glTF's UV origin is top-left, USD's bottom-left
        st = UsdGeom.PrimvarsAPI(mesh).CreatePrimvar("st", _type("TexCoord2fArray"), UsdGeom.Tokens.vertex)
        st.Set(Vt.Vec2fArray.FromNumpy(uv))
    materials = scene.materials
    if prim.material is not None and materials[prim.material].double_sided:
        mesh.CreateDoubleSidedAttr(True)
    binding = UsdSkel.BindingAPI.Apply(mesh.GetPrim())
    binding.CreateSkeletonRel().SetTargets([skeleton])
    skin_index = scene.nodes[node].skin
    if skin_index is not None and "JOINTS_0" in prim.attributes and "WEIGHTS_0" in prim.attributes:
        joints = np.asarray([slot.get(j, 0) for j in scene.skins[skin_index].joints], np.int32)
        which = joints[np.asarray(prim.attributes["JOINTS_0"], np.int64)]
        weights = dequantized(prim.attributes["WEIGHTS_0"]).astype(np.float32)
        width = which.shape[1]
        binding.CreateJointIndicesPrimvar(False, width).Set(Vt.IntArray.FromNumpy(which.ravel()))
        binding.CreateJointWeightsPrimvar(False, width).Set(Vt.FloatArray.FromNumpy(weights.ravel()))
        binding.CreateGeomBindTransformAttr(Gf.Matrix4d(1.0))
    else:
        binding.CreateJointIndicesPrimvar(True, 1).Set(Vt.IntArray([slot[node]]))
        binding.CreateJointWeightsPrimvar(True, 1).Set(Vt.FloatArray([1.0]))
        binding.CreateGeomBindTransformAttr(Gf.Matrix4d(rest_world.T.tolist()))
    if channel_names and prim.targets:
        names = _unique([_identifier(n) for n in _target_names(target_names, len(prim.targets))])
        targets = []
        for t, target in enumerate(prim.targets):
            shape = UsdSkel.BlendShape.Define(stage, where.AppendChild(names[t]))
            offsets = target.get("POSITION", np.zeros_like(positions))
            shape.CreateOffsetsAttr(Vt.Vec3fArray.FromNumpy(np.ascontiguousarray(offsets, np.float32)))
            if "NORMAL" in target:
                shape.CreateNormalOffsetsAttr(Vt.Vec3fArray.FromNumpy(np.ascontiguousarray(target["NORMAL"],
                                                                                           np.float32)))
            targets.append(shape.GetPath())
        binding.CreateBlendShapesAttr(channel_names[:len(prim.targets)])
        binding.CreateBlendShapeTargetsRel().SetTargets(targets)
    if material is not None:
        UsdShade.MaterialBindingAPI.Apply(mesh.GetPrim()).Bind(UsdShade.Material(stage.GetPrimAtPath(material)))


def _type(name: str):
    from pxr import Sdf

    return getattr(Sdf.ValueTypeNames, name)


def _material(stage, looks, scene: Scene, index: int, pictures: _Pictures):
    """A UsdPreviewSurface material for ``scene.materials[index]``; its path."""
    from pxr import Gf, Sdf, UsdShade

    m: Material = scene.materials[index]
    material = UsdShade.Material.Define(stage, looks.AppendChild(_identifier(m.name or f"material{index}")))
    surface = UsdShade.Shader.Define(stage, material.GetPath().AppendChild("Surface"))
    surface.CreateIdAttr("UsdPreviewSurface")
    r, g, b, a = (float(v) for v in m.base_color)
    surface.CreateInput("metallic", Sdf.ValueTypeNames.Float).Set(float(m.metallic))
    surface.CreateInput("roughness", Sdf.ValueTypeNames.Float).Set(float(m.roughness))
    if m.texture is not None:
        reader = UsdShade.Shader.Define(stage, material.GetPath().AppendChild("UV"))
        reader.CreateIdAttr("UsdPrimvarReader_float2")
        reader.CreateInput("varname", Sdf.ValueTypeNames.String).Set("st")
        texture = UsdShade.Shader.Define(stage, material.GetPath().AppendChild("BaseColor"))
        texture.CreateIdAttr("UsdUVTexture")
        texture.CreateInput("file", Sdf.ValueTypeNames.Asset).Set(
            Sdf.AssetPath("./" + name_text(pictures.name(scene.images[m.texture]))))
        texture.CreateInput("sourceColorSpace", Sdf.ValueTypeNames.Token).Set("sRGB")
        texture.CreateInput("wrapS", Sdf.ValueTypeNames.Token).Set("repeat")
        texture.CreateInput("wrapT", Sdf.ValueTypeNames.Token).Set("repeat")
        texture.CreateInput("scale", Sdf.ValueTypeNames.Float4).Set(Gf.Vec4f(r, g, b, a))
        texture.CreateInput("st", Sdf.ValueTypeNames.Float2).ConnectToSource(
            reader.CreateOutput("result", Sdf.ValueTypeNames.Float2))
        surface.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).ConnectToSource(
            texture.CreateOutput("rgb", Sdf.ValueTypeNames.Float3))
        if m.alpha_mode != "OPAQUE":
            surface.CreateInput("opacity", Sdf.ValueTypeNames.Float).ConnectToSource(
                texture.CreateOutput("a", Sdf.ValueTypeNames.Float))
    else:
        surface.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).Set(Gf.Vec3f(r, g, b))
        if m.alpha_mode != "OPAQUE":
            surface.CreateInput("opacity", Sdf.ValueTypeNames.Float).Set(a)
    if m.alpha_mode == "MASK":
        cutoff = 0.5 if m.alpha_cutoff is None else float(m.alpha_cutoff)
        surface.CreateInput("opacityThreshold", Sdf.ValueTypeNames.Float).Set(cutoff)
    material.CreateSurfaceOutput().ConnectToSource(surface.ConnectableAPI(), "surface")
    return material.GetPath()


@dataclass
class _Motion:
    """A skeleton's joints and blend shapes over its frames: what the animation says and the extent
    is measured from."""

    trs: list[np.ndarray]             # (T, J, 3), (T, J, 4), (T, J, 3): local translation, rotation, scale
    moved: list[bool]                 # whether the clip moves each of the three
    channels: list[str]               # blend-shape channel names
    weights: np.ndarray               # (T, channels)
    keyed: bool                       # whether the clip drives any weights
    of_node: dict[int, np.ndarray]    # per morphed node, its targets' weights (T, K)


def _motion(scene: Scene, order: list[int], local: list, shapes: dict[int, tuple[list[str], Any]],
            times: np.ndarray) -> _Motion:
    """The clip at ``times``: the joints' local transforms and the blend-shape weights."""
    clip = _clip(scene)
    slot = {node: k for k, node in enumerate(order)}
    trs = [np.repeat(np.stack([part[j] for part in local])[None], len(times), axis=0) for j in range(3)]
    moved = [False, False, False]
    paths = ("translation", "rotation", "scale")
    driven: dict[int, Any] = {}
    for channel in clip.channels if clip is not None else []:
        if channel.path == "weights":
            continue
        if channel.node in slot and scene.nodes[channel.node].matrix is None:
            j = paths.index(channel.path)
            trs[j][:, slot[channel.node]] = sample_many(channel, times)[:, :3 if j != 1 else 4]
            moved[j] = True
    groups: dict[int, tuple[list[str], Any, int]] = {}   # by id of the names: names, driver, a node
    for node, (names, channel) in shapes.items():
        groups.setdefault(id(names), (names, channel, node))
    columns, of_group = [], {}
    for key, (names, channel, node) in groups.items():
        if channel is not None:
            given = sample_many(channel, times)
        else:
            mesh = scene.meshes[scene.nodes[node].mesh]  # type: ignore[index]
            given = np.repeat(np.asarray(mesh.weights, float).reshape(1, -1), len(times), axis=0)
        block = np.zeros((len(times), len(names)))
        width = min(len(names), given.shape[1])
        block[:, :width] = given[:, :width]
        columns.append(block)
        of_group[key] = block
        driven[key] = channel is not None
    weights = np.concatenate(columns, axis=1) if columns else np.zeros((len(times), 0))
    return _Motion(trs, moved, [n for names, _, _ in groups.values() for n in names], weights,
                   any(driven.values()), {node: of_group[id(names)] for node, (names, _) in shapes.items()})


def _animation(anim, motion: _Motion, tokens: list[str]) -> None:
    """The motion as joint transforms and blend-shape weights, one array per frame; what the clip
    does not move is written once, unkeyed."""
    from pxr import Vt

    anim.CreateJointsAttr(tokens)
    attrs = (anim.CreateTranslationsAttr(), anim.CreateRotationsAttr(), anim.CreateScalesAttr())
    kinds = (Vt.Vec3fArray, Vt.QuatfArray, Vt.Vec3hArray)
    dtypes = (np.float32, np.float32, np.float16)
    for j in range(3):
        values = np.ascontiguousarray(motion.trs[j].astype(dtypes[j]))
        if motion.moved[j]:
            for f in range(len(values)):  # one whole array per time sample
                attrs[j].Set(kinds[j].FromNumpy(values[f]), float(f))
        else:
            attrs[j].Set(kinds[j].FromNumpy(values[0]))
    if not motion.channels:
        return
    weights = np.ascontiguousarray(motion.weights.astype(np.float32))
    anim.CreateBlendShapesAttr(motion.channels)
    attr = anim.CreateBlendShapeWeightsAttr()
    if motion.keyed:
        for f in range(len(weights)):
            attr.Set(Vt.FloatArray.FromNumpy(weights[f]), float(f))
    else:
        attr.Set(Vt.FloatArray.FromNumpy(weights[0]))


def _joint_tokens(scene: Scene, order: list[int]) -> list[str]:
    """Each node's joint path (its ancestors' names and its own), nodes named uniquely."""
    parent = {c: i for i in order for c in scene.nodes[i].children}
    idents = _unique([_identifier(scene.nodes[i].name or f"node{i}") for i in order])
    slot = {node: k for k, node in enumerate(order)}
    tokens: list[str] = []
    for k, node in enumerate(order):
        up = parent.get(node)
        tokens.append(idents[k] if up is None else f"{tokens[slot[up]]}/{idents[k]}")
    return tokens


def _extent(scene: Scene, order: list[int], motion: _Motion) -> np.ndarray:
    """(2, 3) around every drawn vertex in every frame of ``motion``, posed as glTF poses it
    (:func:`fishgen.scene.pose.deformed`, for all frames at once)."""
    from fishgen.scene.pose import quat_matrices

    t, r, s = motion.trs
    local = np.zeros(t.shape[:2] + (4, 4))
    local[..., :3, :3] = quat_matrices(r) * s[..., None, :]
    local[..., :3, 3], local[..., 3, 3] = t, 1.0
    slot = {node: k for k, node in enumerate(order)}
    for k, node in enumerate(order):
        if scene.nodes[node].matrix is not None:
            local[:, k] = np.asarray(scene.nodes[node].matrix, float)
    world = local.copy()
    parent = {c: i for i in order for c in scene.nodes[i].children}
    for k, node in enumerate(order):  # parents first
        if node in parent:
            world[:, k] = world[:, slot[parent[node]]] @ local[:, k]
    low, high = np.full(3, np.inf), np.full(3, -np.inf)
    for node, prim in scene.drawn():
        if prim.mode != "TRIANGLES" or not prim.vertex_count:
            continue
        points = np.asarray(prim.positions, float)[None]                            # (1|T, n, 3)
        weights = motion.of_node.get(node)
        if weights is not None and prim.targets:
            offsets = np.stack([np.asarray(tg.get("POSITION", np.zeros(prim.positions.shape)), float)
                                for tg in prim.targets])                             # (K, n, 3)
            k = min(len(offsets), weights.shape[1])
            points = points + np.einsum("tk,knc->tnc", weights[:, :k], offsets[:k])
        skin = scene.nodes[node].skin
        if skin is not None and "JOINTS_0" in prim.attributes and "WEIGHTS_0" in prim.attributes:
            joints = np.asarray([slot.get(j, 0) for j in scene.skins[skin].joints])
            mats = world[:, joints] @ np.asarray(scene.skins[skin].inverse_bind_matrices, float)
            which = np.asarray(prim.attributes["JOINTS_0"], np.int64)
            share = dequantized(prim.attributes["WEIGHTS_0"])
            moved = np.zeros((len(world),) + prim.positions.shape)
            for c in range(which.shape[1]):  # each of a vertex's (four) joints, every frame at once
                m = mats[:, which[:, c]]                                             # (T, n, 4, 4)
                moved += share[None, :, c, None] * (np.einsum("tnij,tnj->tni", m[..., :3, :3], points
                                                              * np.ones((len(world), 1, 1)))
                                                    + m[..., :3, 3])
        else:
            m = world[:, slot[node]]
            moved = np.einsum("tij,tnj->tni", m[:, :3, :3], points * np.ones((len(world), 1, 1))) \
                + m[:, None, :3, 3]
        low = np.minimum(low, moved.min(axis=(0, 1)))
        high = np.maximum(high, moved.max(axis=(0, 1)))
    if not np.isfinite(low).all():
        return np.zeros((2, 3))
    return np.stack([low, high])
