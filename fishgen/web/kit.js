// The page kit: the parts of three.js fishgen's pages use and the modules they share, bundled once
// (tools/bundle_viewer.py: fishgen/web/static/kit.min.js). Every page inlines it as a classic script
// before its own app, which takes what it needs from `window.fishgenKit`. THREE holds only the
// names the pages use, so the bundle leaves out the rest of three.js; the bundler refuses a page
// that uses a THREE name missing here.
import {
	AnimationMixer, ArrowHelper, AxesHelper, Box3, BoxGeometry, BufferAttribute, CatmullRomCurve3, Color,
	CustomBlending, DataTexture, DirectionalLight, DoubleSide, DynamicDrawUsage, EdgesGeometry, Frustum,
	GridHelper, Group, HemisphereLight, LineBasicMaterial, LineSegments, LoadingManager, MathUtils, Matrix4,
	Mesh, MeshBasicMaterial, MeshStandardMaterial, OneFactor, OneMinusSrcAlphaFactor, OrthographicCamera,
	PerspectiveCamera, PlaneGeometry, Points, PointsMaterial, Raycaster, SRGBColorSpace, Scene, ShaderMaterial,
	Sphere, TextureLoader, Timer, Vector2, Vector3, WebGLRenderTarget, WebGLRenderer,
} from 'three';

export const THREE = Object.freeze( {
	AnimationMixer, ArrowHelper, AxesHelper, Box3, BoxGeometry, BufferAttribute, CatmullRomCurve3, Color,
	CustomBlending, DataTexture, DirectionalLight, DoubleSide, DynamicDrawUsage, EdgesGeometry, Frustum,
	GridHelper, Group, HemisphereLight, LineBasicMaterial, LineSegments, LoadingManager, MathUtils, Matrix4,
	Mesh, MeshBasicMaterial, MeshStandardMaterial, OneFactor, OneMinusSrcAlphaFactor, OrthographicCamera,
	PerspectiveCamera, PlaneGeometry, Points, PointsMaterial, Raycaster, SRGBColorSpace, Scene, ShaderMaterial,
	Sphere, TextureLoader, Timer, Vector2, Vector3, WebGLRenderTarget, WebGLRenderer,
} );
export { OrbitControls } from 'three/addons/controls/OrbitControls.js';
export { TransformControls } from 'three/addons/controls/TransformControls.js';
export { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
export { MTLLoader } from 'three/addons/loaders/MTLLoader.js';
export { OBJLoader } from 'three/addons/loaders/OBJLoader.js';
export { PLYLoader } from 'three/addons/loaders/PLYLoader.js';
export * as cloudlight from './cloudlight.js';
