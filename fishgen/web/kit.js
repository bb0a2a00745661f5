// The page kit: the parts of three.js fishgen's pages use and the modules they share, bundled once
// (tools/bundle_viewer.py: fishgen/web/static/kit.min.js). Every page inlines it as a classic script
// before its own app, which takes what it needs from `window.fishgenKit`. THREE holds only the
// names in three-parts.js, so the bundle leaves out the rest of three.js.
export * as THREE from './three-parts.js';
export { OrbitControls } from 'three/addons/controls/OrbitControls.js';
export { TransformControls } from 'three/addons/controls/TransformControls.js';
export { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
export { MTLLoader } from 'three/addons/loaders/MTLLoader.js';
export { OBJLoader } from 'three/addons/loaders/OBJLoader.js';
export { PLYLoader } from 'three/addons/loaders/PLYLoader.js';
export * as cloudlight from './cloudlight.js';
export * as drawing from './drawing.js';
export * as schools from './schools.js';
