// Loads one fishgen file with the stock three.js loader a web app would use and
// summarises what the loader produced (objects, counts, materials, textures, clips).
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { OBJLoader } from 'three/addons/loaders/OBJLoader.js';
import { MTLLoader } from 'three/addons/loaders/MTLLoader.js';
import { PLYLoader } from 'three/addons/loaders/PLYLoader.js';

const TEXTURE_WAIT_MS = 5000;

function textureInfo(tex) {
  if (!tex) return null;
  const img = tex.image;
  return { name: tex.name || '', arrived: !!(img && img.width > 0 && img.height > 0),
           width: img ? img.width || 0 : 0, height: img ? img.height || 0 : 0,
           src: img && img.src ? img.src : '' };
}

function materialInfo(m) {
  return { type: m.type, name: m.name, map: textureInfo(m.map), alphaMap: textureInfo(m.alphaMap),
           transparent: m.transparent, alphaTest: m.alphaTest, side: m.side,
           vertexColors: m.vertexColors };
}

function geometryInfo(obj) {
  const geo = obj.geometry;
  const attrs = {};
  for (const [name, a] of Object.entries(geo.attributes)) attrs[name] = { count: a.count, itemSize: a.itemSize };
  const positions = geo.attributes.position ? geo.attributes.position.count : 0;
  const info = { name: obj.name, type: obj.isPoints ? 'Points' : obj.isMesh ? 'Mesh' : obj.type,
                 positions, indexed: !!geo.index, attributes: attrs,
                 materials: (Array.isArray(obj.material) ? obj.material : [obj.material]).filter(Boolean).map(materialInfo),
                 groups: geo.groups.length };
  if (obj.isMesh) {
    info.triangles = geo.index ? geo.index.count / 3 : positions / 3;
  }
  // the engine rows: the skin, the blend shapes by name, and the box at rest in the file's space
  info.bones = obj.isSkinnedMesh && obj.skeleton ? obj.skeleton.bones.map((b) => b.name) : null;
  info.morphTargets = obj.morphTargetInfluences ? obj.morphTargetInfluences.length : 0;
  info.morphNames = obj.morphTargetDictionary
    ? Object.entries(obj.morphTargetDictionary).sort((a, b) => a[1] - b[1]).map((e) => e[0]) : [];
  if (geo.attributes.position && positions > 0) {
    // the file's positions through the node's matrix (not skinned: a skin's bind pose is the engine's)
    const box = new THREE.Box3();
    const v = new THREE.Vector3();
    for (let i = 0; i < positions; i++) box.expandByPoint(v.fromBufferAttribute(geo.attributes.position, i).applyMatrix4(obj.matrixWorld));
    info.world = [box.min.toArray(), box.max.toArray()];
  }
  return info;
}

function summarise(root, extra) {
  root.updateMatrixWorld(true);
  const objects = [];
  root.traverse((o) => { if (o.isMesh || o.isPoints || o.isLine) objects.push(geometryInfo(o)); });
  return Object.assign({ objects }, extra);
}

function allTextures(root) {
  const out = [];
  root.traverse((o) => {
    if (!o.material) return;
    for (const m of (Array.isArray(o.material) ? o.material : [o.material])) {
      for (const key of ['map', 'alphaMap']) if (m[key]) out.push(m[key]);
    }
  });
  return out;
}

// Loads under way: three.js's loaders (TextureLoader's ImageLoader among them) tell the default
// LoadingManager when each starts and when it ends, loaded or failed; an image is handed to its
// texture before its end is told.
let pending = 0;
const manager = THREE.DefaultLoadingManager;
const itemStart = manager.itemStart, itemEnd = manager.itemEnd;
manager.itemStart = (url) => { pending += 1; itemStart(url); };
manager.itemEnd = (url) => { pending -= 1; itemEnd(url); };

// MTLLoader/TextureLoader fill texture.image asynchronously: wait until every
// texture has arrived, or every load has ended with one still missing (a 404), or
// give up; the Python side reports a missing texture as a failure.
async function texturesSettled(root) {
  const start = performance.now();
  while (performance.now() - start < TEXTURE_WAIT_MS) {
    if (allTextures(root).every((t) => t.image && t.image.width > 0)) return true;
    if (pending === 0) return false;
    await new Promise((r) => setTimeout(r, 20));
  }
  return false;
}

async function loadGltf(url) {
  const gltf = await new GLTFLoader().loadAsync(url);
  await texturesSettled(gltf.scene);
  const clips = gltf.animations.map((c) => ({
    name: c.name, duration: c.duration,
    tracks: c.tracks.map((t) => ({ name: t.name, times: t.times.length,
      bound: !!THREE.PropertyBinding.findNode(gltf.scene, THREE.PropertyBinding.parseTrackName(t.name).nodeName) })),
  }));
  return summarise(gltf.scene, { clips });
}

async function loadObj(url) {
  const base = url.slice(0, url.lastIndexOf('/') + 1);
  const text = await (await fetch(url)).text();
  const lib = (text.match(/^mtllib\s+(.+)$/m) || [])[1];
  const objLoader = new OBJLoader();
  let mtl = null;
  if (lib) {
    const materials = await new MTLLoader().setPath(base).loadAsync(lib.trim());
    materials.preload();
    objLoader.setMaterials(materials);
    mtl = lib.trim();
  }
  const group = objLoader.parse(text);
  await texturesSettled(group);
  return summarise(group, { clips: [], mtllib: mtl });
}

async function loadPly(url, customProperties) {
  const loader = new PLYLoader();
  if (customProperties) loader.setCustomPropertyNameMapping(customProperties);
  const geo = await loader.loadAsync(url);
  const hasFaces = !!geo.index;
  let obj;
  if (hasFaces) {
    obj = new THREE.Mesh(geo, new THREE.MeshStandardMaterial({ vertexColors: !!geo.attributes.color }));
  } else {
    obj = new THREE.Points(geo, new THREE.PointsMaterial({ vertexColors: !!geo.attributes.color }));
  }
  const root = new THREE.Group();
  root.add(obj);
  return summarise(root, { clips: [] });
}

window.inspectAsset = async (loader, url, options = {}) => {
  try {
    if (loader === 'gltf') return await loadGltf(url);
    if (loader === 'obj') return await loadObj(url);
    if (loader === 'ply') return await loadPly(url, options.customProperties);
    return { error: `unknown loader ${loader}` };
  } catch (e) {
    return { error: String(e && e.message ? e.message : e) };
  }
};
// The tail tip's world position as three.js plays the first clip: the vertex furthest towards -Z
// at rest, moved by three.js's own morph and skin code (Mesh.getVertexPosition) and node matrices.
window.tailTrack = async (url, times) => {
  try {
    const gltf = await new GLTFLoader().loadAsync(url);
    const root = gltf.scene;
    const mixer = new THREE.AnimationMixer(root);
    mixer.clipAction(gltf.animations[0]).play();
    const v = new THREE.Vector3();
    const where = (mesh, i) => mesh.getVertexPosition(i, v).applyMatrix4(mesh.matrixWorld);
    root.updateMatrixWorld(true);
    let tip = null;
    let nose = -Infinity;
    root.traverse((o) => {
      if (!o.isMesh) return;
      for (let i = 0; i < o.geometry.attributes.position.count; i++) {
        const p = where(o, i);
        nose = Math.max(nose, p.z);
        if (!tip || p.z < tip.z) tip = { mesh: o, index: i, z: p.z };
      }
    });
    const track = [];
    for (const t of times) {
      mixer.setTime(t);
      root.updateMatrixWorld(true);
      const p = where(tip.mesh, tip.index);
      track.push([p.x, p.y, p.z]);
    }
    const influences = tip.mesh.morphTargetInfluences ? tip.mesh.morphTargetInfluences.length : 0;
    return { track, length: nose - tip.z, mesh: tip.mesh.name, influences };
  } catch (e) {
    return { error: String(e && e.message ? e.message : e) };
  }
};
window.harnessReady = true;
