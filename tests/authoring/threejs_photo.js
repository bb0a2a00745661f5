// Photograph a glb from its left side (+X) with an orthographic camera whose frustum the caller
// gives in world units, so the caller knows exactly where every vertex lands on the picture.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { RoomEnvironment } from 'three/addons/environments/RoomEnvironment.js';

window.photograph = async (url, cam) => {
  try {
    const gltf = await new GLTFLoader().loadAsync(url);
    const canvas = document.createElement('canvas');
    canvas.width = cam.width; canvas.height = cam.height;
    const renderer = new THREE.WebGLRenderer({ canvas, alpha: true, antialias: true,
                                               preserveDrawingBuffer: true, premultipliedAlpha: false });
    renderer.setPixelRatio(1);
    renderer.setSize(cam.width, cam.height, false);
    renderer.setClearColor(0x000000, 0);
    const scene = new THREE.Scene();
    scene.add(gltf.scene);
    scene.add(new THREE.AmbientLight(0xffffff, 1.2));
    const sun = new THREE.DirectionalLight(0xffffff, 2.0);
    sun.position.set(1, 1.5, 0.5);
    scene.add(sun);
    const camera = new THREE.OrthographicCamera(-cam.halfWidth, cam.halfWidth, cam.halfHeight, -cam.halfHeight,
                                                0.01, 1000);
    camera.position.set(cam.distance, cam.centreY, cam.centreZ);
    camera.up.set(0, 1, 0);
    camera.lookAt(0, cam.centreY, cam.centreZ);
    renderer.render(scene, camera);
    return { png: canvas.toDataURL('image/png') };
  } catch (e) {
    return { error: String(e && e.message ? e.message : e) };
  }
};

// A photo more like a photograph (issue 25): image-based light from three.js' RoomEnvironment, a
// strong sun casting the fish's shadow on a sandy floor, a textured backdrop, a perspective camera
// a little above the fish and the fish turned off side-on. Returns the photo, the fish alone (its
// alpha: the true silhouette) and where each given glTF point lands on the picture.
const loadTexture = (url) => new Promise((ok, fail) => new THREE.TextureLoader().load(url, ok, undefined, fail));

window.photographLit = async (url, cam) => {
  try {
    const gltf = await new GLTFLoader().loadAsync(url);
    const canvas = document.createElement('canvas');
    canvas.width = cam.width; canvas.height = cam.height;
    const renderer = new THREE.WebGLRenderer({ canvas, alpha: true, antialias: true,
                                               preserveDrawingBuffer: true, premultipliedAlpha: false });
    renderer.setPixelRatio(1);
    renderer.setSize(cam.width, cam.height, false);
    renderer.shadowMap.enabled = true;
    renderer.shadowMap.type = THREE.PCFSoftShadowMap;
    renderer.toneMapping = THREE.ACESFilmicToneMapping;
    const scene = new THREE.Scene();
    const pmrem = new THREE.PMREMGenerator(renderer);
    scene.environment = pmrem.fromScene(new RoomEnvironment(), 0.04).texture;
    const fish = gltf.scene;
    fish.rotation.y = THREE.MathUtils.degToRad(cam.yaw);
    fish.traverse((o) => { if (o.isMesh) { o.castShadow = true; } });
    scene.add(fish);
    const sun = new THREE.DirectionalLight(0xfff4e0, cam.sun);
    sun.position.set(-cam.size * 0.8, cam.size * 3.0, cam.size * 0.4);   // behind: the shadow falls towards us
    sun.castShadow = true;
    sun.shadow.mapSize.set(2048, 2048);
    const s = cam.size * 2;
    Object.assign(sun.shadow.camera, { left: -s, right: s, top: s, bottom: -s, near: 0.01, far: cam.size * 10 });
    scene.add(sun);
    let floor = null;
    if (cam.floor) {
      const sand = await loadTexture(cam.floor);
      sand.colorSpace = THREE.SRGBColorSpace;
      sand.wrapS = sand.wrapT = THREE.RepeatWrapping;
      sand.repeat.set(4, 4);
      floor = new THREE.Mesh(new THREE.PlaneGeometry(cam.size * 12, cam.size * 12),
                             new THREE.MeshStandardMaterial({ map: sand, roughness: 0.95 }));
      floor.rotation.x = -Math.PI / 2;
      floor.position.y = cam.floorY;
      floor.receiveShadow = true;
      scene.add(floor);
    }
    const camera = new THREE.PerspectiveCamera(cam.fov, cam.width / cam.height, cam.size * 0.05, cam.size * 100);
    camera.position.set(...cam.eye);
    camera.lookAt(...cam.target);
    camera.updateMatrixWorld();
    const shots = {};
    if (cam.background) {
      const back = await loadTexture(cam.background);
      back.colorSpace = THREE.SRGBColorSpace;
      scene.background = back;
    }
    renderer.setClearColor(0x000000, 0);
    renderer.render(scene, camera);
    shots.png = canvas.toDataURL('image/png');
    // the fish alone: no backdrop, no floor, nothing but its own (blended) pixels in the alpha
    scene.background = null;
    if (floor) floor.visible = false;
    renderer.render(scene, camera);
    shots.alpha = canvas.toDataURL('image/png');
    fish.updateMatrixWorld(true);
    const v = new THREE.Vector3();
    shots.points = cam.points.map(([x, y, z]) => {
      v.set(x, y, z).applyMatrix4(fish.matrixWorld).project(camera);
      return [(v.x + 1) / 2 * cam.width, (1 - v.y) / 2 * cam.height];
    });
    return shots;
  } catch (e) {
    return { error: String(e && e.message ? e.message : e) };
  }
};
window.pageReady = true;
