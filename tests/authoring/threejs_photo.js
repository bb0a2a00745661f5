// Photograph a glb from its left side (+X) with an orthographic camera whose frustum the caller
// gives in world units, so the caller knows exactly where every vertex lands on the picture.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';

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
window.pageReady = true;
