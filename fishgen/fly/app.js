// fishgen fly: Pakawan's fly-through of a sky (RekAwan user manual, chapter 4), measured honestly.
// Keys as Pakawan's: W/S forward/back, A/D left/right, arrows look up/down and turn, 1/2/3 speed;
// the mouse (drag) looks around. The upper left shows the window size, the time and the FPS.
// State for tests and the headless driver: window.fishgenFly = {loaded, error, camera, frames, done, report}.
// `loaded` turns true once the assets are in and the first frame is drawn: from then on modes(),
// inspect(), drawn and camera describe a frame (before it no cloud has a place, a level or a mode).
const { THREE, GLTFLoader, cloudlight, drawing, schools } = window.fishgenKit;   // fishgen/web/kit.js
import { Impostors } from './impostors.js';
const { PREMULTIPLIED, billboardMaterial: cloudBillboardMaterial, cloudUniforms, particleMaterial: cloudParticleMaterial, readCloudLight } = cloudlight;

const config = JSON.parse( document.getElementById( 'fishgen-fly' ).textContent );
const token = new URLSearchParams( location.search ).get( 'token' ) || '';
const $ = ( id ) => document.getElementById( id );
const state = window.fishgenFly = {
	loaded: false, error: null, done: false, report: null, frames: 0, fps: 0, time: 0, speed: 2,
	camera: { position: [ 0, 0, 0 ], yaw: 0, pitch: 0 }, counts: null, sorts: 0, impostors: null,
};
const fail = ( err ) => {
	state.error = String( err && err.message || err );
	$( 'hud' ).textContent = 'could not fly: ' + state.error;
	console.error( err );
};

// -- renderer, camera ------------------------------------------------------------------------
const canvas = $( 'view' );
const renderer = drawing.webglRenderer( { canvas, antialias: false, powerPreference: 'high-performance' }, fail );
if ( renderer === null ) throw new Error( state.error );   // said on the page and to a headless driver
renderer.setPixelRatio( 1 );   // the report's window size is the drawn size
const gl = renderer.getContext();
const scene = new THREE.Scene();
scene.background = new THREE.Color( config.background );
const camera = new THREE.PerspectiveCamera( 60, 1, 0.1, 1000 );
camera.rotation.order = 'YXZ';   // yaw about +Y, then pitch: an aeroplane's view
scene.add( new THREE.HemisphereLight( 0xc4cdd8, 0x3a3530, 1.6 ) );   // for meshes (a fish school)
const sunLight = new THREE.DirectionalLight( 0xfff8eb, 2.2 );
sunLight.position.set( 0.35, 1.0, 0.55 );
scene.add( sunLight );

function size() {
	return config.size ? config.size : [ Math.max( 1, window.innerWidth ), Math.max( 1, window.innerHeight ) ];
}

function resize() {
	const [ w, h ] = size();
	if ( canvas.width !== w || canvas.height !== h ) {
		renderer.setSize( w, h, ! config.size );
		if ( config.size ) { canvas.style.width = w + 'px'; canvas.style.height = h + 'px'; }
		camera.aspect = w / h;
		camera.updateProjectionMatrix();
	}
	const bw = Math.max( 1, Math.round( w * config.cloudScale ) ), bh = Math.max( 1, Math.round( h * config.cloudScale ) );
	if ( cloudBuffer && ( cloudBuffer.width !== bw || cloudBuffer.height !== bh ) ) cloudBuffer.setSize( bw, bh );
	bufferSize = cloudBuffer ? [ bw, bh ] : [ w, h ];
	pixelScale();
}
let bufferSize = [ 1, 1 ];
function pixelScale( viewportHeight = bufferSize[ 1 ], fadeHeight = bufferSize[ 1 ] ) {
	particleMaterial.uniforms.viewportHeight.value = viewportHeight;
	particleMaterial.uniforms.fadeHeight.value = fadeHeight;
}

function draw() {
	renderer.autoClear = true;
	camera.layers.set( 0 );
	renderer.setRenderTarget( null );
	renderer.render( scene, camera );   // the sky's colour and any meshes
	const background = scene.background;
	scene.background = null;
	camera.layers.set( CLOUDS );
	renderer.autoClear = false;
	if ( cloudBuffer ) {
		renderer.setRenderTarget( cloudBuffer );
		renderer.setClearColor( 0x000000, 0 );
		renderer.clear();
		if ( depthTested ) {   // the meshes' depth, so that a mesh hides the particles behind it
			camera.layers.set( 0 );
			drawMeshDepth();
			camera.layers.set( CLOUDS );
		}
		renderer.render( scene, camera );
		renderer.setRenderTarget( null );
		renderer.render( overlayScene, overlayCamera );
	} else {
		renderer.render( scene, camera );
	}
	scene.background = background;
	camera.layers.set( 0 );
}

// -- Harris's second pass, from each particle's baked _LIGHT (fishgen/web/cloudlight.js) ----------
function readLight( extras ) {   // the sun lights the page's meshes too
	const sun = readCloudLight( extras );
	if ( sun ) sunLight.position.copy( sun );
	return sun !== null;
}

// Particles and billboards as fishgen view draws them, but faded near the eye and written
// premultiplied, to be drawn into the clouds' own buffer (`cloudBuffer`, below).
const particleMaterial = cloudParticleMaterial( { flying: true } );
const billboardMaterial = ( source ) => cloudBillboardMaterial( source, { flying: true } );

// The chapter 5 baseline (benchmarks/fly.py): the same particles as three.js Points, one colour
// each, unsorted, unculled, no second pass.
const plainMaterial = new THREE.PointsMaterial( { size: 1, vertexColors: true, sizeAttenuation: true } );

// The clouds' own buffer (GPU Gems 3, ch. 23, "High-Speed, Off-Screen Particles"): particles are
// drawn into a buffer of config.cloudScale of the window's width and height (a quarter of the
// pixels at 0.5), then laid over the view, bilinearly scaled up. Their pixels are what a software
// renderer pays for; soft clouds lose little detail. At 1 they are drawn on the view itself.
const CLOUDS = 1;   // the layer of everything drawn as a cloud; meshes stay on layer 0
const IMPOSTOR_DRAWS = 2;   // the layer a cloud is put on alone while it is drawn into its impostor
// With meshes in the scene (a school, any glb), the clouds test the meshes' depth: on the window,
// the depth they left; in the cloud buffer, their depth drawn into it first (colour untouched).
let depthTested = false;
// The meshes' depth is drawn with their own materials, colour writes off: an instanced school's fish
// are placed by its own vertex shader (fishgen/web/schools.js), which an override material would lose.
function drawMeshDepth() {
	const materials = new Set( meshes.flatMap( ( m ) => [].concat( m.material ) ) );
	const writes = new Map( [ ...materials ].map( ( m ) => [ m, m.colorWrite ] ) );
	for ( const m of materials ) m.colorWrite = false;
	renderer.render( scene, camera );
	for ( const [ m, on ] of writes ) m.colorWrite = on;
}
const cloudBuffer = config.cloudScale < 1 ? new THREE.WebGLRenderTarget( 1, 1, { depthBuffer: true } ) : null;
const overlay = new THREE.Mesh( new THREE.PlaneGeometry( 2, 2 ), new THREE.ShaderMaterial( {
	uniforms: { map: { value: cloudBuffer ? cloudBuffer.texture : null } }, transparent: true, depthTest: false, depthWrite: false,
	...PREMULTIPLIED,
	vertexShader: 'varying vec2 vUv; void main() { vUv = uv; gl_Position = vec4( position.xy, 0.0, 1.0 ); }',
	fragmentShader: 'uniform sampler2D map; varying vec2 vUv; void main() { gl_FragColor = texture2D( map, vUv ); }',
} ) );
overlay.frustumCulled = false;
const overlayScene = new THREE.Scene();
overlayScene.add( overlay );
const overlayCamera = new THREE.OrthographicCamera();

// -- clouds: the units that are culled, levelled and sorted ------------------------------------
const CLOUD_MATERIAL = 'cloud particle', CLOUD_SPRITE = 'gaussian sprite', CLOUD_TEXTURE = 'cloud texture ';
const isBillboards = ( o ) => o.isMesh && [].concat( o.material ).some( ( m ) => m && ( m.name === CLOUD_MATERIAL
	|| m.name.startsWith( CLOUD_TEXTURE ) || ( m.map && m.map.name === CLOUD_SPRITE ) ) );

const units = [];   // {levels: [{object, sorters, particles, billboards}], coverage, centre, radius, level, parent}
const counts = { particles: 0, billboards: 0, distantParticles: 0, distantBillboards: 0, clouds: 0, meshes: 0 };

// Sort one drawable's particles back to front: counting sort of quantised depths along the view (O(n)).
const BUCKETS = 4096;
function sorter( object, size ) {
	const g = object.geometry, { index, centroids, n } = drawing.centroids( g, size );
	if ( ! g.index || ! ( g.index.array instanceof Uint32Array ) ) g.setIndex( new THREE.BufferAttribute( new Uint32Array( index ), 1 ) );
	g.index.setUsage( THREE.DynamicDrawUsage );
	return { object, centroids, index, size, n, keys: new Uint16Array( n ), depth: new Float32Array( n ), start: new Uint32Array( BUCKETS + 1 ),
		dir: new THREE.Vector3( 0, 0, 0 ), from: new THREE.Vector3( Infinity, 0, 0 ) };
}

const _dir = new THREE.Vector3(), _local = new THREE.Vector3(), _inv = new THREE.Matrix4();
// `along`: the direction to sort along (an impostor's, from the eye to the cloud); the view's if none.
function sortNow( s, along = null ) {
	if ( along ) _dir.copy( along ); else camera.getWorldDirection( _dir );
	_inv.copy( s.object.matrixWorld ).invert();
	_local.copy( _dir ).transformDirection( _inv );   // the view direction in the cloud's frame
	const dx = _local.x, dy = _local.y, dz = _local.z, c = s.centroids, n = s.n;
	let lo = Infinity, hi = - Infinity;
	const depth = s.depth;
	for ( let k = 0; k < n; k ++ ) {
		const d = c[ 3 * k ] * dx + c[ 3 * k + 1 ] * dy + c[ 3 * k + 2 ] * dz;
		depth[ k ] = d; if ( d < lo ) lo = d; if ( d > hi ) hi = d;
	}
	const scale = hi > lo ? ( BUCKETS - 1 ) / ( hi - lo ) : 0, start = s.start.fill( 0 ), keys = s.keys;
	for ( let k = 0; k < n; k ++ ) { const b = BUCKETS - 1 - ( ( depth[ k ] - lo ) * scale | 0 ); keys[ k ] = b; start[ b + 1 ] ++; }
	for ( let b = 0; b < BUCKETS; b ++ ) start[ b + 1 ] += start[ b ];   // farthest bucket (largest depth) first
	const out = s.object.geometry.index.array, size = s.size, index = s.index;
	for ( let k = 0; k < n; k ++ ) {
		const at = start[ keys[ k ] ] ++ * size;
		for ( let j = 0; j < size; j ++ ) out[ at + j ] = index[ k * size + j ];
	}
	s.object.geometry.index.needsUpdate = true;
	s.dir.copy( _dir );
	s.from.copy( camera.position );
	state.sorts ++;
}

// A drawable is sorted again once the view has turned SORT_TURN or moved SORT_MOVE of its distance
// since its last sort (the order along the view barely changes in between), at most SORT_BUDGET
// particles a frame, the stalest first; nothing is drawn unsorted the first time.
const SORT_TURN = Math.cos( THREE.MathUtils.degToRad( 4 ) ), SORT_MOVE = 0.05, SORT_BUDGET = 200000;

function stale( s, distance ) {
	if ( s.from.x === Infinity ) return Infinity;
	camera.getWorldDirection( _dir );
	const turn = 1 - _dir.dot( s.dir ), moved = s.from.distanceTo( camera.position ) / Math.max( distance, 1e-6 );
	return Math.max( turn / ( 1 - SORT_TURN ), moved / SORT_MOVE );
}

function addUnit( levels, coverage ) {
	const level0 = levels[ 0 ];
	level0.object.geometry.computeBoundingSphere();
	const sphere = level0.object.geometry.boundingSphere.clone();
	units.push( { levels, coverage, sphere, world: new THREE.Sphere(), level: 0, distance: 0, visible: false,
		mode: null, holds: false, renderOrder: 0, impostor: null } );
	counts.clouds ++;
}

function drawable( object ) {
	const g = object.geometry, n = g.getAttribute( 'position' ).count;
	const quads = isBillboards( object );
	if ( config.baseline && object.isPoints ) {
		object.material = plainMaterial;
		const r = g.getAttribute( '_radius' );
		// three's Points size is in units of half the view's height at distance 1: a world diameter
		// 2r is 2r / tan(fov / 2) of them (the fov is set before any asset loads)
		if ( r ) plainMaterial.size = 2 * r.array.reduce( ( a, b ) => a + b, 0 ) / r.count / Math.tan( THREE.MathUtils.degToRad( camera.fov / 2 ) );
	} else if ( object.isPoints ) {
		if ( ! g.getAttribute( '_radius' ) ) { g.computeBoundingSphere(); g.setAttribute( '_radius', new THREE.BufferAttribute( new Float32Array( n ).fill( 0.004 * g.boundingSphere.radius ), 1 ) ); }
		if ( ! g.getAttribute( '_density' ) ) g.setAttribute( '_density', new THREE.BufferAttribute( new Float32Array( n ).fill( 1 ), 1 ) );
		if ( ! g.getAttribute( '_light' ) ) g.setAttribute( '_light', new THREE.BufferAttribute( new Float32Array( n ).fill( - 1 ), 1 ) );
		if ( ! g.getAttribute( 'color' ) ) g.setAttribute( 'color', new THREE.BufferAttribute( new Float32Array( n * 3 ).fill( 1 ), 3 ) );
		object.material = particleMaterial;
	} else {
		if ( ! g.getAttribute( '_light' ) ) g.setAttribute( '_light', new THREE.BufferAttribute( new Float32Array( n ).fill( - 1 ), 1 ) );
		if ( ! g.getAttribute( 'color' ) ) g.setAttribute( 'color', new THREE.BufferAttribute( new Float32Array( n * 4 ).fill( 1 ), 4 ) );
		object.material = billboardMaterial( object.material );
	}
	object.frustumCulled = false;   // culled as whole clouds below
	object.layers.set( CLOUDS );
	const sorters = config.baseline ? [] : [ sorter( object, quads ? 3 : 1 ) ];
	return { object, sorters, particles: quads ? 0 : n, billboards: quads ? n / 12 : 0 };
}

async function addAsset( gltf, root ) {
	readLight( gltf.scene.userData );
	const parser = gltf.parser, json = parser.json;
	root.updateMatrixWorld( true );
	const done = new Set();
	// a node with MSFT_lod: its own drawables are level 0, the nodes it names the lower levels
	for ( const [ index, def ] of ( json.nodes || [] ).entries() ) {
		const lod = def.extensions && def.extensions.MSFT_lod;
		if ( ! lod || ! Array.isArray( lod.ids ) ) continue;
		// from the parser's cache, not parser.associations: three.js empties its nodes when a file has
		// a second scene (where the lower levels stand)
		const top = await parser.getDependency( 'node', index );
		if ( ! top.parent ) continue;
		const levels = [];
		const collect = ( object ) => {
			const found = [];
			object.traverse( ( o ) => { if ( ( o.isPoints || isBillboards( o ) ) && ! done.has( o ) ) { done.add( o ); found.push( drawable( o ) ); } } );
			return found;
		};
		const first = collect( top );
		if ( first.length !== 1 ) continue;   // a level is one drawable: anything else is drawn as it is
		levels.push( first[ 0 ] );
		for ( const id of lod.ids ) {
			if ( ! Number.isInteger( id ) || id < 0 || id >= json.nodes.length ) break;
			const lower = await parser.getDependency( 'node', id );
			top.parent.add( lower );   // beside level 0, in its parent's frame
			lower.position.copy( top.position ); lower.quaternion.copy( top.quaternion ); lower.scale.copy( top.scale );
			const found = collect( lower );
			if ( found.length !== 1 ) break;
			levels.push( found[ 0 ] );
		}
		const cover = def.extras && def.extras.MSFT_screencoverage;
		const coverage = Array.isArray( cover ) ? cover.filter( Number.isFinite ) : [];
		addUnit( levels, coverage );
	}
	// every other point set or billboard mesh is a unit of its own (a cube file without levels, any glb)
	root.traverse( ( o ) => { if ( ( o.isPoints || isBillboards( o ) ) && ! done.has( o ) ) { done.add( o ); addUnit( [ drawable( o ) ], [] ); } } );
	root.traverse( ( o ) => { if ( o.isMesh && ! done.has( o ) ) counts.meshes ++; } );
	// a fishgen school: one instanced mesh a species and material (fishgen/web/schools.js), counted above
	// fish by fish as the file holds it
	const school = schools.instanceSchools( root, gltf.animations, instancing );
	for ( const key of Object.keys( instanced ) ) instanced[ key ] += school.info[ key ];
	// what is drawn with depth, after instancing: the instanced meshes in place of their fish
	root.traverse( ( o ) => { if ( o.isMesh && ! done.has( o ) ) meshes.push( o ); } );
	if ( school.clips.length ) {
		const mixer = new THREE.AnimationMixer( root );
		for ( const clip of school.clips ) mixer.clipAction( clip ).play();
		mixers.push( { update( dt ) { mixer.update( dt ); school.follow( mixer ); } } );
	}
}
const mixers = [];   // each with update( dt ): the assets' animations
const meshes = [];   // everything drawn with depth (a school, any glb's meshes)
// Unless the run said --no-instancing or the page's address ?instancing=0: then fish by fish, to compare.
const instancing = config.instancing !== false && new URLSearchParams( location.search ).get( 'instancing' ) !== '0';
const instanced = state.instanced = { species: 0, fish: 0, meshes: 0 };
// For tests and benchmarks: the draw calls of one frame of the meshes (layer 0), as three.js counts them.
state.meshCalls = () => {
	camera.layers.set( 0 );
	renderer.setRenderTarget( null );
	renderer.render( scene, camera );
	return renderer.info.render.calls;
};

// -- the frame: cull whole clouds, pick each one's level, sort the stalest, draw -----------------
const frustum = new THREE.Frustum(), _m = new THREE.Matrix4();
const drawn = { particles: 0, billboards: 0, clouds: 0, distant: 0, impostors: 0, redraws: 0, redrawn: 0 };
const impostors = config.impostors && config.impostors.on ? new Impostors( renderer, scene, {
	angle: config.impostors.angle, budget: config.impostors.budget, near: config.impostors.near, layer: CLOUDS,
	draws: IMPOSTOR_DRAWS, twin, sort: ( s, along ) => sortNow( s, along ), uniforms: pixelScale } ) : null;

canvas.addEventListener( 'webglcontextrestored', () => { if ( impostors ) impostors.forget(); } );

// A level's drawable as the impostors draw it: its attributes and material shared, its own index
// (sorted along the line from the eye to the cloud, drawn a slice a frame), seen by their camera only.
function twin( level ) {
	const object = level.object, s = level.sorters[ 0 ], g = new object.geometry.constructor();   // a BufferGeometry
	for ( const [ name, attribute ] of Object.entries( object.geometry.attributes ) ) g.setAttribute( name, attribute );
	g.setIndex( new THREE.BufferAttribute( new Uint32Array( s.index ), 1 ) );
	const copy = object.isPoints ? new THREE.Points( g, object.material ) : new THREE.Mesh( g, object.material );
	copy.position.copy( object.position ); copy.quaternion.copy( object.quaternion ); copy.scale.copy( object.scale );
	copy.frustumCulled = false;
	copy.visible = false;   // shown only while drawn into its impostor
	copy.layers.set( IMPOSTOR_DRAWS );
	object.parent.add( copy );
	copy.updateMatrixWorld( true );
	const sorter = { ...s, object: copy, keys: new Uint16Array( s.n ), depth: new Float32Array( s.n ), start: new Uint32Array( BUCKETS + 1 ),
		dir: new THREE.Vector3(), from: new THREE.Vector3( Infinity, 0, 0 ) };
	return { object: copy, sorter, size: s.size, n: s.n };
}

// Which clouds hold a mesh (their particles must be cut by its depth, so they are drawn directly):
// looked at again every HOLD_FRAMES frames, since a school swims.
const HOLD_FRAMES = 30, _box = new THREE.Box3();
let holdAge = Infinity;
function findHolds() {
	if ( ++ holdAge < HOLD_FRAMES ) return;
	holdAge = 0;
	for ( const u of units ) u.holds = false;
	for ( const mesh of meshes ) {
		_box.setFromObject( mesh );
		if ( _box.isEmpty() ) continue;
		for ( const u of units ) if ( ! u.holds && _box.intersectsSphere( u.world ) ) u.holds = true;
	}
}

// The sun's uniforms as a key: the impostors are all redrawn when it changes.
const sunKey = () => [ cloudUniforms.cloudLit.value, ...cloudUniforms.cloudSun.value.toArray(), ...cloudUniforms.sunColor.value.toArray(),
	...cloudUniforms.skyColor.value.toArray(), cloudUniforms.albedo.value, cloudUniforms.g.value ].join( ',' );
let redrawMs = 0;

function update() {
	camera.updateMatrixWorld();
	_m.multiplyMatrices( camera.projectionMatrix, camera.matrixWorldInverse );
	frustum.setFromProjectionMatrix( _m );
	const tanHalf = Math.tan( THREE.MathUtils.degToRad( camera.fov / 2 ) );
	drawn.particles = drawn.billboards = drawn.clouds = drawn.distant = drawn.impostors = drawn.redraws = drawn.redrawn = 0;
	const due = [];
	for ( const u of units ) {
		const object0 = u.levels[ 0 ].object;
		u.world.copy( u.sphere ).applyMatrix4( object0.matrixWorld );
		u.visible = config.baseline || frustum.intersectsSphere( u.world );
		u.distance = u.world.center.distanceTo( camera.position );
		u.renderOrder = - u.distance;   // clouds and impostors together, farthest first
		// MSFT_screencoverage: the share of the view's height the bounding sphere spans
		const cover = u.distance > u.world.radius ? u.world.radius / ( u.distance * tanHalf ) : 1;
		let level = 0;
		while ( ! config.baseline && level < u.levels.length - 1 && level < u.coverage.length && cover < u.coverage[ level ] ) level ++;
		u.level = level;
	}
	redrawMs = 0;
	if ( impostors ) {
		findHolds();
		const started = performance.now();
		const particles = impostors.plan( units, camera, bufferSize[ 0 ], bufferSize[ 1 ], sunKey(), camera.near * 2 );
		if ( particles ) {
			renderer.setRenderTarget( null );
			pixelScale();
			gl.readPixels( 0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel );   // the redraws done: their share of the frame
			redrawMs = performance.now() - started;
		}
		drawn.redraws = impostors.last.redraws;
		drawn.redrawn = particles;
		state.impostors = { ...impostors.last, textures: impostors.stats.textures };
	}
	for ( const u of units ) {
		const direct = u.visible && u.mode !== 'impostor';
		u.levels.forEach( ( l, k ) => { l.object.visible = direct && k === u.level; l.object.renderOrder = u.renderOrder; } );
		if ( ! u.visible ) continue;
		const l = u.levels[ u.level ];
		drawn.clouds ++;
		if ( u.level > 0 ) drawn.distant ++;
		if ( ! direct ) { drawn.impostors ++; continue; }
		drawn.particles += l.particles; drawn.billboards += l.billboards;
		for ( const s of l.sorters ) { const age = stale( s, u.distance ); if ( age >= 1 ) due.push( [ age, s ] ); }
	}
	due.sort( ( a, b ) => b[ 0 ] - a[ 0 ] );
	let budget = SORT_BUDGET;
	for ( const [ age, s ] of due ) {
		if ( budget <= 0 && age !== Infinity ) break;
		sortNow( s );
		budget -= s.n;
	}
}

// For tests and people: each cloud as drawn now (its level, whether it is in view), and whether
// its particles are in back-to-front order along the view direction of its last sort, how far the
// view has turned (degrees) and moved (share of its distance) since.
state.inspect = () => units.map( ( u ) => {
	const l = u.levels[ u.level ], s = l.sorters[ 0 ];
	const out = { visible: u.visible, level: u.level, levels: u.levels.length, particles: l.particles,
		billboards: l.billboards, distance: u.distance, radius: u.world.radius };
	if ( ! s || s.from.x === Infinity ) return { ...out, sorted: false };
	_inv.copy( s.object.matrixWorld ).invert();
	_local.copy( s.dir ).transformDirection( _inv );
	const order = s.object.geometry.index.array, c = s.centroids, pos = s.object.geometry.getAttribute( 'position' );
	let worst = 0, previous = Infinity, lo = Infinity, hi = - Infinity;
	const particleOf = new Map();
	if ( s.size > 1 ) for ( let j = 0; j < s.n; j ++ ) particleOf.set( s.index[ j * s.size ], j );
	for ( let k = 0; k < s.n; k ++ ) {
		const v = order[ k * s.size ];
		let d = 0;
		if ( s.size === 1 ) d = pos.getX( v ) * _local.x + pos.getY( v ) * _local.y + pos.getZ( v ) * _local.z;
		else { const j = particleOf.get( v ); d = c[ 3 * j ] * _local.x + c[ 3 * j + 1 ] * _local.y + c[ 3 * j + 2 ] * _local.z; }
		worst = Math.max( worst, d - previous ); previous = d; lo = Math.min( lo, d ); hi = Math.max( hi, d );
	}
	camera.getWorldDirection( _dir );
	return { ...out, sorted: true, disorder: hi > lo ? worst / ( hi - lo ) : 0,
		turn: THREE.MathUtils.radToDeg( Math.acos( Math.min( 1, _dir.dot( s.dir ) ) ) ),
		moved: s.from.distanceTo( camera.position ) / Math.max( u.distance, 1e-6 ) };
} );

// For tests and benchmarks/fly.py's pictures: look from `position` at `target`. `how`: 'direct'
// (every cloud drawn directly), 'impostors' (every picture redrawn for this view at once), 'flying'
// (pictures dropped, the budget as configured) or 'keep' (pictures and budget as they are). The
// seeded path must be "still" (nothing else moves the camera).
state.look = ( position, target, how = 'keep' ) => {
	camera.position.fromArray( position );
	camera.lookAt( new THREE.Vector3().fromArray( target ) );
	eye.yaw = camera.rotation.y; eye.pitch = camera.rotation.x;
	camera.updateMatrixWorld();
	if ( ! impostors || how === 'keep' ) return;
	impostors.dropAll( units );
	impostors.budget = { direct: 0, impostors: Infinity, flying: config.impostors.budget }[ how ];
};
// How each cloud is drawn now: 'impostor', 'direct', or null (out of view); and whether it holds a mesh.
state.modes = () => units.map( ( u ) => ( { mode: u.visible ? ( u.mode || 'direct' ) : null, holds: u.holds,
	distance: u.distance, radius: u.world.radius, centre: u.world.center.toArray(),
	side: u.impostor && u.impostor.shown ? u.impostor.shown.side : 0, redraws: u.impostor ? u.impostor.redraws : 0 } ) );
state.view = () => camera;
// Change the sun the clouds are lit by (every impostor is redrawn under it).
state.setSun = ( direction ) => { cloudUniforms.cloudSun.value.fromArray( direction ).normalize(); };
// The picture drawn now, as a PNG data URL (drawn again and read in one task, so it is whole).
state.capture = () => { resize(); update(); draw(); return canvas.toDataURL( 'image/png' ); };
// Hold the page's own loop (true) or let it run again: a caller that draws each frame it reads with
// capture() (the tests' impostor pages) keeps the software renderer from drawing the scene meanwhile.
let held = false;
state.hold = ( on ) => { held = !! on; };

// -- moving: Pakawan's keys, the mouse, or a seeded path ----------------------------------------
const keys = new Set();
const SPEEDS = [ 0.01, 0.04, 0.12 ];   // share of the scene's size flown per second, keys 1/2/3
const TURN = THREE.MathUtils.degToRad( 60 );   // degrees per second, arrows
let extent = 1, home = new THREE.Vector3(), homeYaw = 0;
const eye = { yaw: 0, pitch: 0 };

window.addEventListener( 'keydown', ( e ) => {
	if ( [ '1', '2', '3' ].includes( e.key ) ) state.speed = Number( e.key );
	keys.add( e.code );
	if ( e.code.startsWith( 'Arrow' ) ) e.preventDefault();
} );
window.addEventListener( 'keyup', ( e ) => keys.delete( e.code ) );
window.addEventListener( 'blur', () => keys.clear() );
let dragging = null;
canvas.addEventListener( 'pointerdown', ( e ) => { dragging = [ e.clientX, e.clientY ]; canvas.setPointerCapture( e.pointerId ); } );
canvas.addEventListener( 'pointerup', () => { dragging = null; } );
canvas.addEventListener( 'pointermove', ( e ) => {
	if ( ! dragging ) return;
	eye.yaw -= ( e.clientX - dragging[ 0 ] ) * 0.004;
	eye.pitch -= ( e.clientY - dragging[ 1 ] ) * 0.004;
	dragging = [ e.clientX, e.clientY ];
} );

const _forward = new THREE.Vector3(), _right = new THREE.Vector3();
function steer( dt ) {
	if ( keys.has( 'ArrowLeft' ) ) eye.yaw += TURN * dt;
	if ( keys.has( 'ArrowRight' ) ) eye.yaw -= TURN * dt;
	if ( keys.has( 'ArrowUp' ) ) eye.pitch += TURN * dt;
	if ( keys.has( 'ArrowDown' ) ) eye.pitch -= TURN * dt;
	eye.pitch = THREE.MathUtils.clamp( eye.pitch, - 1.5, 1.5 );
	camera.rotation.set( eye.pitch, eye.yaw, 0 );
	camera.updateMatrixWorld();
	camera.getWorldDirection( _forward );
	_right.crossVectors( _forward, camera.up ).normalize();
	const step = SPEEDS[ state.speed - 1 ] * extent * dt;
	if ( keys.has( 'KeyW' ) ) camera.position.addScaledVector( _forward, step );
	if ( keys.has( 'KeyS' ) ) camera.position.addScaledVector( _forward, - step );
	if ( keys.has( 'KeyD' ) ) camera.position.addScaledVector( _right, step );
	if ( keys.has( 'KeyA' ) ) camera.position.addScaledVector( _right, - step );
}

function random( seed ) {   // mulberry32: the path's numbers, the same for a seed in every browser
	let a = seed >>> 0;
	return () => {
		a = ( a + 0x6D2B79F5 ) >>> 0;
		let t = Math.imul( a ^ ( a >>> 15 ), a | 1 );
		t = ( t + Math.imul( t ^ ( t >>> 7 ), t | 61 ) ) ^ t;
		return ( ( t ^ ( t >>> 14 ) ) >>> 0 ) / 4294967296;
	};
}

let path = null, orbit = null;
function plan( box ) {
	const centre = box.getCenter( new THREE.Vector3() ), span = box.getSize( new THREE.Vector3() );
	if ( config.path === 'orbit' ) {   // chapter 5's test: the cloud held in view, turning about it
		const sphere = box.getBoundingSphere( new THREE.Sphere() );
		orbit = { centre: sphere.center, distance: sphere.radius / Math.sin( THREE.MathUtils.degToRad( camera.fov / 2 ) ) * 1.1 };
		return;
	}
	if ( config.path === 'still' ) {   // a picture: above the sky's edge, looking down across it
		camera.position.set( home.x, box.max.y + 0.05 * span.y, home.z + 0.1 * span.z );
		eye.pitch = - 0.2;
		camera.rotation.set( eye.pitch, eye.yaw, 0 );
		orbit = { still: true };
		return;
	}
	if ( config.path === 'around' ) {   // one cloud: a seeded loop round it, 2.2 to 4 radii out, looking at it
		const sphere = box.getBoundingSphere( new THREE.Sphere() ), rand = random( config.seed ), points = [];
		for ( let k = 0; k < 6; k ++ ) {
			const angle = ( k / 6 + 0.1 * ( rand() - 0.5 ) ) * Math.PI * 2, reach = sphere.radius * ( 2.2 + 1.8 * rand() );
			points.push( new THREE.Vector3( sphere.center.x + Math.cos( angle ) * reach, sphere.center.y + sphere.radius * ( rand() - 0.4 ),
				sphere.center.z + Math.sin( angle ) * reach ) );
		}
		path = new THREE.CatmullRomCurve3( points, true, 'centripetal' );
		orbit = { around: sphere };
		return;
	}
	if ( config.path !== 'fly' ) return;
	// a closed loop through seeded waypoints in the middle of the sky, at the clouds' heights
	const rand = random( config.seed );
	const points = [];
	for ( let k = 0; k < 6; k ++ ) {
		const angle = ( k / 6 + 0.1 * ( rand() - 0.5 ) ) * Math.PI * 2, reach = 0.25 + 0.2 * rand();
		points.push( new THREE.Vector3( centre.x + Math.cos( angle ) * span.x * reach, box.min.y + span.y * ( 0.3 + 0.4 * rand() ),
			centre.z + Math.sin( angle ) * span.z * reach ) );
	}
	path = new THREE.CatmullRomCurve3( points, true, 'centripetal' );
}

const _at = new THREE.Vector3(), _ahead = new THREE.Vector3();
function follow( seconds ) {
	if ( orbit && orbit.still ) return;
	if ( orbit && orbit.around ) {   // along the loop, the view wandering over the cloud
		path.getPointAt( ( seconds / Math.max( 20, ( config.timeout || 0 ) + config.warmup ) ) % 1, camera.position );
		const r = orbit.around.radius, w = seconds * Math.PI * 2 / 7;
		camera.lookAt( _at.copy( orbit.around.center ).add( _ahead.set( Math.sin( w ) * 0.3 * r, Math.sin( 1.3 * w ) * 0.15 * r, 0 ) ) );
		return;
	}
	if ( orbit ) {
		const a = seconds * Math.PI * 2 / 30;   // once round in 30 s
		camera.position.set( orbit.centre.x + Math.sin( a ) * orbit.distance, orbit.centre.y + orbit.distance * 0.15, orbit.centre.z + Math.cos( a ) * orbit.distance );
		camera.lookAt( orbit.centre );
		return;
	}
	const loop = Math.max( 20, ( config.timeout || 0 ) + config.warmup );   // once round in the time flown
	const t = ( seconds / loop ) % 1;
	path.getPointAt( t, _at );
	path.getPointAt( ( t + 0.01 ) % 1, _ahead );
	camera.position.copy( _at );
	camera.lookAt( _ahead );
	eye.yaw = camera.rotation.y; eye.pitch = camera.rotation.x;
}

// -- timing: one pixel read back a frame, warm-up, a fixed wall time -----------------------------
const pixel = new Uint8Array( 4 );
let started = null, measuring = null, last = null;
const frames = [];   // [ms since measuring began, frame interval ms, particles, billboards, clouds]
let hudAt = 0;

function frame() {
	if ( held ) { last = null; requestAnimationFrame( frame ); return; }
	const now = performance.now();
	if ( started === null ) started = now;
	const dt = last === null ? 0 : Math.min( 0.1, ( now - last ) / 1000 );
	resize();
	if ( path || orbit ) follow( ( now - started ) / 1000 ); else steer( dt );
	for ( const mixer of mixers ) mixer.update( dt );
	update();
	const updated = performance.now();
	draw();
	const submitted = performance.now();
	gl.readPixels( 0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel );   // wait for the frame to be drawn
	const end = performance.now();
	if ( measuring === null && ( end - started ) / 1000 >= config.warmup ) measuring = end;
	else if ( measuring !== null && last !== null ) {
		frames.push( [ end - measuring, end - last, drawn.particles, drawn.billboards, drawn.clouds,
			updated - now, submitted - updated, end - submitted, drawn.redraws, redrawMs, drawn.impostors, drawn.redrawn,
			impostors ? impostors.last.error : 0 ] );
		state.frames = frames.length;
	}
	last = end;
	state.time = ( end - started ) / 1000;
	state.camera = { position: camera.position.toArray(), yaw: eye.yaw, pitch: eye.pitch };
	state.drawn = { ...drawn };
	if ( end - hudAt > 250 ) { hudAt = end; hud( end ); }
	if ( config.timeout && measuring !== null && ( end - measuring ) / 1000 >= config.timeout ) return finish( end );
	requestAnimationFrame( frame );
}

function median( values ) {
	const v = Float64Array.from( values ).sort();
	return v.length ? ( v.length % 2 ? v[ v.length >> 1 ] : ( v[ v.length / 2 - 1 ] + v[ v.length / 2 ] ) / 2 ) : 0;
}
function percentile( values, p ) {
	const v = Float64Array.from( values ).sort();
	return v.length ? v[ Math.min( v.length - 1, Math.max( 0, Math.ceil( p / 100 * v.length ) - 1 ) ) ] : 0;
}

function hud( now ) {
	const recent = frames.slice( - 30 ).map( ( f ) => f[ 1 ] );
	state.fps = recent.length ? 1000 / median( recent ) : 0;
	const [ w, h ] = size();
	$( 'hud' ).textContent = `${ w } × ${ h }   ${ state.time.toFixed( 1 ) } s   ${ state.fps.toFixed( 1 ) } FPS`
		+ ( measuring === null ? '   (warming up)' : '' );
	// particles drawn directly this frame; a cloud shown as an impostor is a picture of its particles
	$( 'detail' ).textContent = `${ drawn.particles.toLocaleString( 'en' ) } of ${ counts.particles.toLocaleString( 'en' ) } particles drawn`
		+ ( counts.billboards ? `, ${ drawn.billboards.toLocaleString( 'en' ) } of ${ counts.billboards.toLocaleString( 'en' ) } billboards` : '' )
		+ ` · ${ drawn.clouds } of ${ counts.clouds } clouds (${ drawn.distant } distant`
		+ ( impostors ? `, ${ impostors.last.impostors } as impostors` : '' ) + `) · speed ${ state.speed }`;
}

function rendererName() {
	const info = gl.getExtension( 'WEBGL_debug_renderer_info' );
	return info ? String( gl.getParameter( info.UNMASKED_RENDERER_WEBGL ) ) : String( gl.getParameter( gl.RENDERER ) );
}

function finish( end ) {
	const intervals = frames.map( ( f ) => f[ 1 ] );
	const mean = ( k ) => frames.length ? frames.reduce( ( a, f ) => a + f[ k ], 0 ) / frames.length : 0;
	const seconds = [];
	for ( const f of frames ) {
		const s = Math.floor( f[ 0 ] / 1000 );
		while ( seconds.length <= s ) seconds.push( [] );
		seconds[ s ].push( f );
	}
	const [ w, h ] = size();
	state.report = {
		window: { width: w, height: h }, seconds: ( end - measuring ) / 1000, warmup: config.warmup, frames: frames.length,
		fps: { median: intervals.length ? 1000 / median( intervals ) : 0, p5: intervals.length ? 1000 / percentile( intervals, 95 ) : 0,
			min: intervals.length ? 1000 / intervals.reduce( ( a, b ) => Math.max( a, b ) ) : 0,
			max: intervals.length ? 1000 / intervals.reduce( ( a, b ) => Math.min( a, b ) ) : 0 },
		scene: { particles: counts.particles, billboards: counts.billboards, distant_particles: counts.distantParticles,
			distant_billboards: counts.distantBillboards, clouds: counts.clouds, meshes: counts.meshes },
		drawn: { particles: mean( 2 ), billboards: mean( 3 ), clouds: mean( 4 ) },
		// where a frame's time goes, medians in ms: culling, levels and sorting (JS); handing the draws
		// to WebGL; waiting for the drawing (the pixel read back)
		split: { update: median( frames.map( ( f ) => f[ 5 ] ) ), submit: median( frames.map( ( f ) => f[ 6 ] ) ),
			wait: median( frames.map( ( f ) => f[ 7 ] ) ) },
		renderer: rendererName(), path: config.path || 'keys', seed: config.seed, sorts: state.sorts,
		// means a frame: clouds shown as impostors, redraws finished, particles drawn into impostors,
		// how stale the pictures shown were (in units of the angle); and the redraws' share of the time
		// flown (each frame's timed to its pixel read back)
		impostors: { on: impostors !== null, angle: impostors ? config.impostors.angle : 0,
			budget: impostors ? config.impostors.budget : 0, shown: mean( 10 ), redraws: mean( 8 ), particles: mean( 11 ), error: mean( 12 ),
			redraw_share: frames.length ? frames.reduce( ( a, f ) => a + f[ 9 ], 0 ) / Math.max( 1e-9, frames.reduce( ( a, f ) => a + f[ 1 ], 0 ) ) : 0,
			textures: impostors ? impostors.stats.textures : 0 },
		per_second: seconds.map( ( fs, s ) => ( { second: s, frames: fs.length,
			fps: fs.length ? 1000 / median( fs.map( ( f ) => f[ 1 ] ) ) : 0,
			particles: fs.length ? fs.reduce( ( a, f ) => a + f[ 2 ], 0 ) / fs.length : 0,
			billboards: fs.length ? fs.reduce( ( a, f ) => a + f[ 3 ], 0 ) / fs.length : 0 } ) ),
	};
	const line = `${ w } × ${ h }   ${ state.report.seconds.toFixed( 1 ) } s   ${ state.report.fps.median.toFixed( 1 ) } FPS median`;
	$( 'hud' ).textContent = `${ line }   (time out)`;
	const post = config.report ? fetch( 'report', { method: 'POST', headers: { 'X-Fishgen-Token': token, 'Content-Type': 'application/json' },
		body: JSON.stringify( state.report ) } ).then( ( r ) => { if ( ! r.ok ) throw new Error( `the report was refused (${ r.status })` ); },
		() => { throw new Error( 'the report could not be sent: fishgen fly\'s server does not answer (was it stopped?)' ); } )
		: Promise.resolve();
	post.then( () => {
		state.done = true;
		$( 'hud' ).textContent = `${ line }   (time out: ${ config.report ? 'the figures are sent, and fishgen fly has stopped' : 'done' })`;
	} ).catch( fail );
}

// -- start ---------------------------------------------------------------------------------------
async function start() {
	resize();
	const loader = new GLTFLoader();
	const world = new THREE.Group();
	scene.add( world );
	let offset = null;
	for ( const asset of config.assets ) {
		const response = await fetch( asset.url, { headers: { 'X-Fishgen-Token': token } } );
		if ( ! response.ok ) throw new Error( `${ asset.name }: ${ response.status }` );
		const gltf = await loader.parseAsync( await response.arrayBuffer(), '' );
		const root = gltf.scene;
		// several inputs stand in a row along +x, each beside the last
		const box = new THREE.Box3().setFromObject( root );
		if ( offset !== null && ! box.isEmpty() ) {
			root.position.x += offset - box.min.x + 0.1 * ( box.max.x - box.min.x );
		}
		world.add( root );
		root.updateMatrixWorld( true );
		if ( ! box.isEmpty() ) offset = new THREE.Box3().setFromObject( root ).max.x;
		const sky = gltf.scene.userData && gltf.scene.userData.fishgen_sky;
		if ( sky && Array.isArray( sky.area ) && Array.isArray( sky.altitude ) && config.assets.length === 1 ) {
			home.set( 0, ( sky.altitude[ 0 ] + sky.altitude[ 1 ] ) / 2, sky.area[ 1 ] / 2 );
		}
		await addAsset( gltf, root );
	}
	for ( const u of units ) for ( const [ k, l ] of u.levels.entries() ) {
		if ( k === 0 ) { counts.particles += l.particles; counts.billboards += l.billboards; }
		else { counts.distantParticles += l.particles; counts.distantBillboards += l.billboards; }
	}
	const box = new THREE.Box3().setFromObject( world );
	const span = box.isEmpty() ? 1 : box.getSize( new THREE.Vector3() ).length();
	extent = span;
	camera.near = Math.max( span / 20000, 1e-3 );
	camera.far = span * 4;
	camera.updateProjectionMatrix();
	if ( home.lengthSq() === 0 && ! box.isEmpty() ) {   // not a sky: in front of it, looking at it
		const centre = box.getCenter( new THREE.Vector3() );
		home.copy( centre ).add( new THREE.Vector3( 0, 0, box.max.z - centre.z + span * 0.6 ) );
	}
	camera.position.copy( home );
	eye.yaw = homeYaw; eye.pitch = 0;
	camera.rotation.set( 0, 0, 0 );
	plan( box );
	depthTested = counts.meshes > 0;
	if ( depthTested ) {
		for ( const u of units ) for ( const l of u.levels ) l.object.material.depthTest = true;
		particleMaterial.depthTest = true;
		if ( impostors ) impostors.setDepthTest( true );
	}
	state.counts = { ...counts };
	// The first frame now (it asks for the next), not at the next animation frame: a test or driver that
	// reads modes() as soon as `loaded` is true would find every cloud unplaced (centre 0, radius -1).
	frame();
	state.loaded = true;
}

start().catch( fail );
