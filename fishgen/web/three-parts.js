// The parts of three.js fishgen's pages use: window.fishgenKit.THREE (fishgen/web/kit.js). The bundler
// refuses a page that uses a THREE name missing here.
export {
	AnimationMixer, ArrowHelper, AxesHelper, Box3, BoxGeometry, BufferAttribute, CatmullRomCurve3, Color,
	CustomBlending, DataTexture, DirectionalLight, DoubleSide, DynamicDrawUsage, EdgesGeometry, Frustum,
	GridHelper, Group, HemisphereLight, LineBasicMaterial, LineSegments, LoadingManager, MathUtils, Matrix4,
	Mesh, MeshBasicMaterial, MeshStandardMaterial, OneFactor, OneMinusSrcAlphaFactor, OrthographicCamera,
	PerspectiveCamera, PlaneGeometry, Points, PointsMaterial, Raycaster, SRGBColorSpace, Scene, ShaderMaterial,
	Sphere, TextureLoader, Timer, Vector2, Vector3, WebGLRenderTarget, WebGLRenderer,
} from 'three';
