"""Many fish of one species in one scene, sharing its meshes: what a school's bake builds on.

:func:`add_species` copies a built fish's meshes, materials and images into the target scene once;
:func:`add_fish` then adds one fish: a copy of the built fish's nodes (and skins, whose joints are
the fish's own) pointing at the shared meshes, its levels of detail included. The returned
:class:`FishNodes` says what to animate: the node(s) a school moves, each fin that swings with the
built fish's swim channel to copy (phase-shifted as the school likes), and the nodes whose morph
weights the school drives (keys as wide as :attr:`SpeciesTemplate.targets`, the wave's four first).

Works for both layouts of :mod:`fishgen.assembly.fish`: a node per part (the fish's root, and each
coarser level's root, move) or one skinned mesh (the root joint moves; the mesh nodes stay at the
scene's root, as glTF wants skinned meshes).
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from fishgen.scene.model import Channel, Scene, Skin


@dataclass(frozen=True)
class SpeciesTemplate:
    fish: Scene                 # the built fish
    mesh_base: int              # where its meshes start in the target scene
    targets: tuple[str, ...]    # the morph targets its meshes carry (names, file order)


@dataclass(frozen=True)
class FishNodes:
    movers: tuple[int, ...]                       # nodes to give the fish's translation, rotation, scale
    fins: tuple[tuple[int, Channel], ...]         # (node, the built fish's swim rotation channel for it)
    waving: tuple[int, ...]                       # nodes whose mesh carries morph targets

    @property
    def root(self) -> int:
        return self.movers[0]


def add_species(target: Scene, fish: Scene) -> SpeciesTemplate:
    """Add ``fish``'s meshes, materials and images to ``target`` once (materials and meshes re-indexed)."""
    image_base, material_base, mesh_base = len(target.images), len(target.materials), len(target.meshes)
    target.images += fish.images
    for material in fish.materials:
        texture = None if material.texture is None else material.texture + image_base
        target.materials.append(replace(material, texture=texture))
    for mesh in fish.meshes:
        prims = [replace(p, material=None if p.material is None else p.material + material_base)
                 for p in mesh.primitives]
        target.meshes.append(replace(mesh, primitives=prims))
    names = next((tuple(m.target_names) for m in fish.meshes if m.target_names), ())
    return SpeciesTemplate(fish, mesh_base, names)


def add_fish(target: Scene, template: SpeciesTemplate, name: str, clip: str = "swim") -> FishNodes:
    """One fish of ``template`` in ``target``: its nodes copied, its root(s) renamed ``name`` (and
    ``name_LODk``), its meshes shared. Nothing is animated yet (see :class:`FishNodes`)."""
    fish = template.fish
    base = len(target.nodes)
    kept = fish.reachable() + [i for r in fish.hidden_roots for i in _subtree(fish, r)]
    order = list(dict.fromkeys(kept))
    where = {old: base + k for k, old in enumerate(order)}
    skins: dict[int, int] = {}
    for old in order:
        node = fish.nodes[old]
        skin = None
        if node.skin is not None:
            if node.skin not in skins:
                s = fish.skins[node.skin]
                skeleton = None if s.skeleton is None else where[s.skeleton]
                target.skins.append(Skin(f"{name}_armature", [where[j] for j in s.joints],
                                         s.inverse_bind_matrices, skeleton))
                skins[node.skin] = len(target.skins) - 1
            skin = skins[node.skin]
        mesh = None if node.mesh is None else node.mesh + template.mesh_base
        children = [where[c] for c in node.children]
        lods = node.lods and replace(node.lods, nodes=tuple(where[i] for i in node.lods.nodes))
        target.nodes.append(replace(node, name=_renamed(fish, old, name), children=children,
                                    mesh=mesh, skin=skin, lods=lods))
    target.roots += [where[r] for r in fish.roots]
    target.hidden_roots += [where[r] for r in fish.hidden_roots if where[r] not in target.hidden_roots]
    tops = list(dict.fromkeys([*fish.roots, *fish.hidden_roots]))
    movers = tuple(where[r] for r in tops if fish.nodes[r].mesh is None)
    swim = fish.clip(clip)
    fins = tuple((where[c.node], c) for c in (swim.channels if swim else []) if c.path == "rotation")
    waving = tuple(where[i] for i in order if _morphed(fish, i))
    return FishNodes(movers, fins, waving)


def pad_weights(wave: np.ndarray, targets: tuple[str, ...]) -> np.ndarray:
    """The wave's (keys, 4) weights widened with zeros for the other targets a mesh carries."""
    out = np.zeros((len(wave), max(len(targets), 4)), np.float32)
    out[:, :4] = wave
    return out


def _morphed(scene: Scene, node: int) -> bool:
    mesh = scene.nodes[node].mesh
    return mesh is not None and bool(scene.meshes[mesh].weights)


def _subtree(scene: Scene, root: int) -> list[int]:
    out, stack = [], [root]
    while stack:
        i = stack.pop()
        out.append(i)
        stack.extend(reversed(scene.nodes[i].children))
    return out


def _renamed(fish: Scene, old: int, name: str) -> str:
    """A fish's top nodes take the fish's name (``species_LODk`` -> ``name_LODk``); parts keep theirs."""
    original = fish.nodes[old].name
    if old in fish.roots or old in fish.hidden_roots:
        species = fish.name
        if original == species or original.startswith(species + "_"):
            return name + original[len(species):]
    return original
