// Loads one fishgen file with Babylon.js's own loaders (LoadAssetContainerAsync: glTF, OBJ, and
// PLY through the splat loader), adds it to a fresh scene, renders a frame, and summarises what
// Babylon made of it: meshes and counts, bounds (of the vertices and of every morph target),
// materials and their textures, and animation groups with every key and the values Babylon
// plays at SAMPLES times. tests/clients/babylon.py compares that with what fishgen made.
/* global BABYLON */
'use strict';

const SAMPLES = 32;
const TEXTURE_WAIT_MS = 5000;
const engine = new BABYLON.Engine(document.getElementById('view'), true, { preserveDrawingBuffer: true });
let scene = null;
let camera = null;

// A node's path of names below the loader's root (glTF's __root__, which turns the right-handed
// file into Babylon's left-handed world), as the file names it.
function pathOf(node) {
  const names = [];
  for (let n = node; n && n.name !== '__root__'; n = n.parent) names.unshift(n.name);
  return names.join('/');
}

function rootOf(node) {
  let n = node;
  while (n.parent) n = n.parent;
  return n.name === '__root__' ? n : null;
}

// Positions through `matrix`, as [[min], [max]].
function boxOf(positions, matrix) {
  if (!positions || positions.length === 0) return null;
  const lo = [Infinity, Infinity, Infinity];
  const hi = [-Infinity, -Infinity, -Infinity];
  const v = new BABYLON.Vector3();
  for (let i = 0; i < positions.length; i += 3) {
    v.set(positions[i], positions[i + 1], positions[i + 2]);
    if (matrix) BABYLON.Vector3.TransformCoordinatesToRef(v, matrix, v);
    lo[0] = Math.min(lo[0], v.x); lo[1] = Math.min(lo[1], v.y); lo[2] = Math.min(lo[2], v.z);
    hi[0] = Math.max(hi[0], v.x); hi[1] = Math.max(hi[1], v.y); hi[2] = Math.max(hi[2], v.z);
  }
  return [lo, hi];
}

function textureInfo(tex) {
  if (!tex) return null;
  const size = tex.getSize ? tex.getSize() : { width: 0, height: 0 };
  return { name: tex.name || '', url: tex.url || '', ready: tex.isReady(), width: size.width, height: size.height };
}

function materialInfo(m) {
  if (!m) return null;
  return {
    class: m.getClassName(), name: m.name,
    albedo: textureInfo(m.albedoTexture || m.diffuseTexture || null),
    opacity: textureInfo(m.opacityTexture || null),
    transparencyMode: m.transparencyMode === undefined ? null : m.transparencyMode,
    alphaCutOff: m.alphaCutOff === undefined ? null : m.alphaCutOff,
    useAlphaFromAlbedo: !!(m.useAlphaFromAlbedoTexture || (m.diffuseTexture && m.diffuseTexture.hasAlpha)),
    backFaceCulling: m.backFaceCulling,
    points: m.fillMode === BABYLON.Material.PointFillMode || !!m.pointsCloud,
    unlit: !!m.unlit || !!m.disableLighting,
  };
}

function meshInfo(mesh) {
  mesh.computeWorldMatrix(true);
  const root = rootOf(mesh);
  // world relative to the loader's root: the file's own world space
  const world = root
    ? mesh.getWorldMatrix().multiply(BABYLON.Matrix.Invert(root.computeWorldMatrix(true)))
    : mesh.getWorldMatrix();
  const source = mesh.sourceMesh || mesh;   // an InstancedMesh draws its source's geometry
  const positions = source.getVerticesData(BABYLON.VertexBuffer.PositionKind);
  const mtm = source.morphTargetManager;
  const targets = [];
  if (mtm) {
    for (let i = 0; i < mtm.numTargets; i++) targets.push(boxOf(mtm.getTarget(i).getPositions(), null));
  }
  return {
    name: mesh.name, path: pathOf(mesh), class: mesh.getClassName(), root: !!root,
    instance: mesh !== source, geometry: source.geometry ? source.geometry.uniqueId : null,
    vertices: source.getTotalVertices(), indices: source.getTotalIndices(),
    kinds: source.getVerticesDataKinds(), useVertexColors: source.useVertexColors,
    enabled: mesh.isEnabled(), visible: mesh.isVisible,
    world: boxOf(positions, world), local: boxOf(positions, null), targets,
    morphManager: mtm ? mtm.uniqueId : null,
    targetNames: mtm ? Array.from({ length: mtm.numTargets }, (_, i) => mtm.getTarget(i).name) : [],
    bones: source.skeleton ? source.skeleton.bones.map((b) => (b.getTransformNode() || b).name) : null,
    material: materialInfo(mesh.material),
  };
}

function texturesOf(meshes) {
  const out = [];
  for (const m of meshes) {
    const mat = m.material;
    if (!mat) continue;
    for (const key of ['albedoTexture', 'diffuseTexture', 'opacityTexture']) if (mat[key]) out.push(mat[key]);
  }
  return out;
}

async function texturesSettled(meshes) {
  const start = performance.now();
  while (performance.now() - start < TEXTURE_WAIT_MS) {
    if (texturesOf(meshes).every((t) => t.isReady())) return true;
    await new Promise((r) => setTimeout(r, 20));
  }
  return false;
}

// A key as [t, x, y, z, qx, qy, qz, qw, sx, sy, sz] (null where the track does not hold it), or [t, w].
function keyOf(property, t, v) {
  if (property === 'influence') return [t, v];
  const none = [null, null, null];
  if (property === 'position') return [t, v.x, v.y, v.z, null, null, null, null, ...none];
  if (property === 'rotationQuaternion') return [t, ...none, v.x, v.y, v.z, v.w, ...none];
  if (property === 'scaling') return [t, ...none, null, null, null, null, v.x, v.y, v.z];
  return null;
}

function groupInfo(group, morphOwner) {
  const tracks = [];
  const inScene = new Set(scene.getNodes());
  for (const ta of group.targetedAnimations) {
    const a = ta.animation;
    const property = a.targetProperty;
    const fps = a.framePerSecond;
    let node = ta.target;
    let target = null;
    if (property === 'influence') {  // a MorphTarget: name the mesh whose manager holds it
      const owner = morphOwner.get(ta.target.uniqueId);
      node = owner ? owner.mesh : null;
      target = owner ? owner.index : null;
    }
    tracks.push({
      node: node ? pathOf(node) : null, property, target, inScene: !!(node && inScene.has(node)),
      keys: a.getKeys().map((k) => keyOf(property, k.frame / fps, k.value)),
      handle: ta,
    });
  }
  // as Babylon plays it: go to SAMPLES + 1 times of the group and read each target
  const fps = group.targetedAnimations.length ? group.targetedAnimations[0].animation.framePerSecond : 60;
  group.start(false);
  group.pause();
  for (const tr of tracks) tr.played = [];
  for (let i = 0; i <= SAMPLES; i++) {
    const frame = group.from + (group.to - group.from) * i / SAMPLES;
    group.goToFrame(frame);
    for (const tr of tracks) {
      const v = tr.handle.target[tr.property];
      tr.played.push(keyOf(tr.property, frame / fps, v && v.clone ? v.clone() : v));
    }
  }
  group.stop();
  for (const tr of tracks) delete tr.handle;
  return { name: group.name, from: group.from, to: group.to, fps, loop: group.loopAnimation, tracks };
}

window.inspectAsset = async (url, options = {}) => {
  try {
    if (scene) scene.dispose();
    scene = new BABYLON.Scene(engine);
    camera = new BABYLON.ArcRotateCamera('camera', 1, 1.2, 2, BABYLON.Vector3.Zero(), scene);
    new BABYLON.HemisphericLight('light', new BABYLON.Vector3(0, 1, 0), scene);
    const container = await BABYLON.LoadAssetContainerAsync(url, scene, options);
    container.addAllToScene();
    for (const g of container.animationGroups) g.stop();
    const meshes = scene.meshes.filter((m) => m.getTotalVertices() > 0 || (m.sourceMesh && m.sourceMesh.getTotalVertices() > 0));
    const settled = await texturesSettled(meshes);
    await scene.whenReadyAsync();
    // frame it and draw once: shaders compile, textures upload
    const box = BABYLON.Mesh.MinMax(meshes);
    camera.setTarget(box.min.add(box.max).scale(0.5));
    camera.radius = Math.max(0.1, box.max.subtract(box.min).length() * 1.2);
    camera.minZ = camera.radius / 100;   // the default near plane (1 m) would cut a fish away
    scene.render();
    const morphOwner = new Map();
    for (const m of meshes) {
      const mtm = m.morphTargetManager;
      if (mtm) for (let i = 0; i < mtm.numTargets; i++) morphOwner.set(mtm.getTarget(i).uniqueId, { mesh: m, index: i });
    }
    const infos = meshes.map(meshInfo);
    const groups = container.animationGroups.map((g) => groupInfo(g, morphOwner));
    return {
      version: BABYLON.Engine.Version, settled,
      meshes: infos,
      groups,
      morphManagers: new Set(meshes.filter((m) => m.morphTargetManager).map((m) => m.morphTargetManager.uniqueId)).size,
    };
  } catch (e) {
    return { error: String(e && e.message ? e.message : e) };
  }
};
// Look at the last asset from (alpha, beta) radians around its centre, for a screenshot.
window.viewFrom = (alpha, beta) => {
  camera.alpha = alpha;
  camera.beta = beta;
  scene.render();
};
// The way a scene is loaded whole: AppendSceneAsync into a fresh scene; each mesh and its material.
window.appendAsset = async (url) => {
  try {
    if (scene) scene.dispose();
    scene = new BABYLON.Scene(engine);
    await BABYLON.AppendSceneAsync(url, scene);
    const meshes = scene.meshes.filter((m) => m.getTotalVertices() > 0);
    const settled = await texturesSettled(meshes);
    return { settled, meshes: meshes.map((m) => ({ name: m.name, path: pathOf(m), material: materialInfo(m.material) })) };
  } catch (e) {
    return { error: String(e && e.message ? e.message : e) };
  }
};
// Plays clip `clipName` of a whole scene (AppendSceneAsync, every level of detail loaded) and reports,
// for each drawn mesh at each of `times` (seconds), the posed positions and normals Babylon computes
// on the CPU (getPositionData / getNormalsData with skeleton and morph targets: the same sums as its
// shaders), in the mesh's own space, with its triangles.
window.poseMeshes = async (url, clipName, times) => {
  try {
    if (scene) scene.dispose();
    scene = new BABYLON.Scene(engine);
    camera = new BABYLON.ArcRotateCamera('camera', 1, 1.2, 2, BABYLON.Vector3.Zero(), scene);
    // MSFT_lod: the promise resolves on the coarsest level; the loader completes on the finest
    const complete = new Promise((resolve) => {
      BABYLON.SceneLoader.OnPluginActivatedObservable.addOnce((plugin) => {
        if (plugin.onCompleteObservable) plugin.onCompleteObservable.addOnce(() => resolve());
        else resolve();
      });
    });
    await BABYLON.AppendSceneAsync(url, scene);
    await complete;
    const group = scene.animationGroups.find((g) => g.name === clipName);
    if (!group) return { error: `no animation group ${clipName}: ${scene.animationGroups.map((g) => g.name)}` };
    for (const g of scene.animationGroups) g.stop();
    const meshes = scene.meshes.filter((m) => m.getTotalVertices() > 0 && m.isEnabled());
    const out = meshes.map((m) => ({ name: m.name, path: pathOf(m), index: Array.from(m.getIndices()),
      morphTargets: m.morphTargetManager ? m.morphTargetManager.numTargets : 0,
      skinned: !!m.skeleton, positions: [], normals: [] }));
    const fps = group.targetedAnimations[0].animation.framePerSecond;
    group.start(false);
    group.pause();
    for (const t of times) {
      group.goToFrame(group.from + t * fps);
      // bones follow their linked nodes: world matrices first, then the skeletons' matrices
      for (const n of scene.transformNodes) n.computeWorldMatrix(true);
      for (const m of scene.meshes) m.computeWorldMatrix(true);
      for (const s of scene.skeletons) s.prepare(true);
      meshes.forEach((m, k) => {
        out[k].positions.push(Array.from(m.getPositionData(true, true)));
        out[k].normals.push(Array.from(m.getNormalsData(true, true)));
      });
    }
    group.stop();
    return { meshes: out, fps };
  } catch (e) {
    return { error: String(e && e.stack ? e.stack : e) };
  }
};
window.harnessReady = true;
