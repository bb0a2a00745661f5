// A fishgen cloud glb as a web app loads it (stock GLTFLoader, its materials untouched), drawn
// from fixed sides with a perspective camera, beside the same particles as opaque spheres.
// Returns, per side, the share of the frame each covers (mean alpha of the render target),
// and optionally the pixels as base64 RGBA for a look.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';

const SIDES = {
  front: { dir: [0, 0, 1], up: [0, 1, 0] },
  side: { dir: [1, 0, 0], up: [0, 1, 0] },
  above: { dir: [0, 1, 0], up: [0, 0, -1] },
  'three-quarter': { dir: [1, 0.45, 0.7], up: [0, 1, 0] },
  'towards-sun': { dir: [-0.35, -1, -0.55], up: [0, 1, 0] },
};

function cameraFor(box, side, aspect) {
  const { dir, up } = SIDES[side];
  const d = new THREE.Vector3(...dir).normalize();
  const centre = box.getCenter(new THREE.Vector3());
  const radius = box.getSize(new THREE.Vector3()).length() / 2;
  // perspective, as a viewer shows it: 30 degrees, the bounding sphere filling the frame's height
  const distance = radius * 1.05 / Math.tan(THREE.MathUtils.degToRad(15));
  const cam = new THREE.PerspectiveCamera(30, aspect, distance - radius * 1.5, distance + radius * 1.5);
  cam.position.copy(centre).addScaledVector(d, distance);
  cam.up.set(...up);
  cam.lookAt(centre);
  cam.updateProjectionMatrix();
  return cam;
}

function draw(renderer, scene, camera, target, w, h, background) {
  renderer.setRenderTarget(target);
  renderer.setClearColor(background ? new THREE.Color(...background) : 0x000000, background ? 1 : 0);
  renderer.clear();
  renderer.render(scene, camera);
  const pixels = new Uint8Array(w * h * 4);
  renderer.readRenderTargetPixels(target, 0, 0, w, h, pixels);
  renderer.setRenderTarget(null);
  return pixels;
}

// the share of the frame covered: mean alpha, and the share of pixels at least 10 % opaque
function share(pixels) {
  let sum = 0, seen = 0;
  for (let i = 3; i < pixels.length; i += 4) {
    sum += pixels[i];
    seen += pixels[i] >= 26;
  }
  return { alpha: sum / (255 * pixels.length / 4), pixels: seen / (pixels.length / 4) };
}

function b64(pixels) {
  let s = '';
  for (let i = 0; i < pixels.length; i += 0x8000) s += String.fromCharCode.apply(null, pixels.subarray(i, i + 0x8000));
  return btoa(s);
}

// centres and radii: the points of a fishgen points glb (the same cloud), as spheres of 0.7 radius
async function spheresOf(url) {
  const gltf = await new GLTFLoader().loadAsync(url);
  let geo = null;
  gltf.scene.traverse((o) => { if (o.isPoints) geo = o.geometry; });
  const pos = geo.getAttribute('position'), rad = geo.getAttribute('_radius');
  const mesh = new THREE.InstancedMesh(new THREE.SphereGeometry(1, 24, 16),
    new THREE.MeshBasicMaterial({ color: 0xffffff }), pos.count);
  const m = new THREE.Matrix4();
  for (let i = 0; i < pos.count; i++) {
    const r = 0.7 * rad.getX(i);
    m.makeScale(r, r, r).setPosition(pos.getX(i), pos.getY(i), pos.getZ(i));
    mesh.setMatrixAt(i, m);
  }
  mesh.instanceMatrix.needsUpdate = true;
  mesh.computeBoundingBox();
  const root = new THREE.Group();
  root.add(mesh);
  return root;
}

window.coverage = async (billboardsUrl, pointsUrl, sides, options = {}) => {
  try {
    const w = options.width || 400, h = options.height || 300;
    const renderer = new THREE.WebGLRenderer({ antialias: false, preserveDrawingBuffer: true });
    renderer.setSize(w, h);
    // 4x multisampled, sRGB-encoded as a canvas would show it (alpha is unaffected)
    const target = new THREE.WebGLRenderTarget(w, h, { samples: 4, colorSpace: THREE.SRGBColorSpace });
    const bb = new THREE.Scene();
    const gltf = await new GLTFLoader().loadAsync(billboardsUrl);
    bb.add(gltf.scene);
    const spheres = new THREE.Scene();
    spheres.add(await spheresOf(pointsUrl));
    const box = new THREE.Box3().setFromObject(spheres);
    box.union(new THREE.Box3().setFromObject(gltf.scene));
    const materials = [];
    gltf.scene.traverse((o) => { if (o.isMesh) materials.push(...[].concat(o.material)); });
    const out = { materials: materials.map((m) => ({ type: m.type, transparent: m.transparent,
      depthWrite: m.depthWrite, vertexColors: m.vertexColors, side: m.side, map: !!m.map })) };
    for (const side of sides) {
      const cam = cameraFor(box, side, w / h);
      const b = draw(renderer, bb, cam, target, w, h, null);
      const s = draw(renderer, spheres, cam, target, w, h, null);
      out[side] = { billboards: share(b), spheres: share(s) };
      if (options.pixels) {
        out[side].pixels = b64(draw(renderer, bb, cam, target, w, h, options.background || [0.55, 0.68, 0.8]));
      }
    }
    renderer.dispose();
    return out;
  } catch (e) {
    return { error: String(e && e.stack ? e.stack : e) };
  }
};
window.coveragePageReady = true;
