// Plays a fishgen glb with three.js's stock loader and mixer and reports what three.js computes:
// every vertex's posed position (Mesh.getVertexPosition: three.js's own morph and skinning code) and
// posed normal (the same formulas as its morphnormal/skinnormal shader chunks), per clip and time.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';

function meshesOf(root) {
  const out = [];
  root.traverse((o) => { if (o.isMesh) out.push(o); });
  return out;
}

// objectNormal = normal + sum(influence_i * morphNormal_i) (relative targets, as glTF's), then the
// skin's blended matrix (skinnormal_vertex), then the object's world matrix: what the GPU shades with.
function posedNormal(mesh, i, out) {
  const geo = mesh.geometry;
  const n = new THREE.Vector3().fromBufferAttribute(geo.attributes.normal, i);
  const morphs = geo.morphAttributes.normal;
  if (morphs && mesh.morphTargetInfluences) {
    const d = new THREE.Vector3();
    for (let k = 0; k < morphs.length; k++) {
      const w = mesh.morphTargetInfluences[k];
      if (w !== 0) n.addScaledVector(d.fromBufferAttribute(morphs[k], i), w);
    }
  }
  if (mesh.isSkinnedMesh) {
    // the blended bone matrix applied to a direction: the difference of two transformed points
    const p = new THREE.Vector3().fromBufferAttribute(geo.attributes.position, i);
    const q = p.clone().add(n);
    mesh.applyBoneTransform(i, p);
    mesh.applyBoneTransform(i, q);
    n.subVectors(q, p);
  }
  return out.copy(n).transformDirection(mesh.matrixWorld);
}

window.poseTracks = async (url, clipName, times) => {
  try {
    const gltf = await new GLTFLoader().loadAsync(url);
    const root = gltf.scene;
    const clip = gltf.animations.find((c) => c.name === clipName);
    if (!clip) return { error: `no clip ${clipName}: ${gltf.animations.map((c) => c.name)}` };
    const meshes = meshesOf(root);
    const v = new THREE.Vector3();
    root.updateMatrixWorld(true);
    const out = meshes.map((m) => {
      if (m.isSkinnedMesh) m.skeleton.update();
      const count = m.geometry.attributes.position.count;
      const rest = new Array(3 * count);   // before the mixer touches anything: the rest pose
      for (let i = 0; i < count; i++) {
        m.getVertexPosition(i, v).applyMatrix4(m.matrixWorld);
        rest[3 * i] = v.x; rest[3 * i + 1] = v.y; rest[3 * i + 2] = v.z;
      }
      return { name: m.name, parent: m.parent ? m.parent.name : '', rest,
        index: Array.from(m.geometry.index.array), count,
        influences: m.morphTargetInfluences ? m.morphTargetInfluences.length : 0,
        morphNormals: !!m.geometry.morphAttributes.normal, positions: [], normals: [] };
    });
    const mixer = new THREE.AnimationMixer(root);
    const action = mixer.clipAction(clip);
    action.setLoop(THREE.LoopOnce, 1);   // sample the clip itself: no wrap at its end
    action.clampWhenFinished = true;
    action.play();
    for (const t of times) {
      mixer.setTime(t);
      root.updateMatrixWorld(true);
      meshes.forEach((m, k) => {
        if (m.isSkinnedMesh) m.skeleton.update();
        const pos = new Array(3 * out[k].count);
        const nrm = new Array(3 * out[k].count);
        for (let i = 0; i < out[k].count; i++) {
          m.getVertexPosition(i, v).applyMatrix4(m.matrixWorld);
          pos[3 * i] = v.x; pos[3 * i + 1] = v.y; pos[3 * i + 2] = v.z;
          posedNormal(m, i, v);
          nrm[3 * i] = v.x; nrm[3 * i + 1] = v.y; nrm[3 * i + 2] = v.z;
        }
        out[k].positions.push(pos);
        out[k].normals.push(nrm);
      });
    }
    return { meshes: out, clips: gltf.animations.map((c) => ({ name: c.name, duration: c.duration,
      tracks: c.tracks.length })), scenes: gltf.scenes.length };
  } catch (e) {
    return { error: String(e && e.stack ? e.stack : e) };
  }
};

// Frame rate of a whole animated scene (a school) played and drawn as a game would: every frame
// the mixer advances and the renderer draws; gl.finish() waits for the (CPU) GPU, so the time is real.
window.schoolFrameRate = async (url, frames, width, height) => {
  try {
    const renderer = new THREE.WebGLRenderer({ antialias: false });
    renderer.setSize(width, height);
    document.body.appendChild(renderer.domElement);
    const gltf = await new GLTFLoader().loadAsync(url);
    const scene = new THREE.Scene();
    scene.add(gltf.scene);
    scene.add(new THREE.HemisphereLight(0xffffff, 0x335577, 2.0));
    let draws = 0;
    // a skinned mesh's bounds are its bind pose's: a school's fish swim away from them, so culling is
    // off for every fish in both layouts (the same work for each)
    gltf.scene.traverse((o) => { if (o.isMesh) { o.frustumCulled = false; draws += 1; } });
    const box = new THREE.Box3().setFromObject(gltf.scene);
    const centre = box.getCenter(new THREE.Vector3());
    const size = box.getSize(new THREE.Vector3()).length();
    const camera = new THREE.PerspectiveCamera(50, width / height, size / 100, size * 10);
    camera.position.copy(centre).add(new THREE.Vector3(0, size * 0.3, size * 0.8));
    camera.lookAt(centre);
    const mixer = new THREE.AnimationMixer(gltf.scene);
    for (const clip of gltf.animations) mixer.clipAction(clip).play();
    const gl = renderer.getContext();
    const warm = 3;
    const stamps = [];
    const animating = [];   // the mixer's share: every track of every fish
    for (let f = 0; f < frames + warm; f++) {
      const start = performance.now();
      mixer.update(1 / 30);
      const animated = performance.now();
      renderer.render(scene, camera);
      gl.finish();
      if (f >= warm) { stamps.push(performance.now() - start); animating.push(animated - start); }
    }
    const median = (a) => a.slice().sort((x, y) => x - y)[a.length >> 1];
    const info = renderer.info.render;
    const calls = info.calls;
    const triangles = info.triangles;
    renderer.dispose();
    renderer.forceContextLoss();
    renderer.domElement.remove();
    return { frames: stamps.length, medianMs: median(stamps), mixerMs: median(animating),
             drawCalls: calls, triangles, meshes: draws };
  } catch (e) {
    return { error: String(e && e.stack ? e.stack : e) };
  }
};
window.harnessReady = true;
