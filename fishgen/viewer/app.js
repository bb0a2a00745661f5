// fishgen viewer: shows one embedded asset with three.js; nothing is fetched from the network.
// State for people and tests alike: window.fishgenViewer = {loaded, error, time, clip, clips, playing, counts,
// instanced, calls}.
const { THREE, OrbitControls, GLTFLoader, PLYLoader, OBJLoader, MTLLoader, cloudlight, drawing, schools } = window.fishgenKit;   // fishgen/web/kit.js
const { billboardMaterial, particleMaterial: makeParticleMaterial, readCloudLight } = cloudlight;

const state = window.fishgenViewer = {
	loaded: false, error: null, time: 0, clip: null, clips: [], playing: false,
	counts: { vertices: 0, triangles: 0, particles: 0 }, cloudLight: null,
	instanced: { species: 0, fish: 0, meshes: 0 }, calls: 0,
};
const $ = ( id ) => document.getElementById( id );
const fail = ( err ) => {
	state.error = String( err && err.message || err );
	$( 'status' ).textContent = 'could not show the asset: ' + state.error;
	console.error( err );
};

// The asset and its side files (buffers, textures, MTL) are embedded as base64 and
// handed to the loaders as blob: URLs under a fake folder, via the URL modifier.
const embedded = JSON.parse( $( 'fishgen-asset' ).textContent );
// A school is drawn one instanced mesh a species and material (fishgen/web/schools.js) unless the
// page was written with --no-instancing or opened with ?instancing=0: fish by fish, to compare.
const instancing = embedded.instancing !== false && new URLSearchParams( location.search ).get( 'instancing' ) !== '0';
const blobs = {};
for ( const [ name, b64 ] of Object.entries( embedded.files ) ) {
	const bytes = Uint8Array.from( atob( b64 ), ( c ) => c.charCodeAt( 0 ) );
	blobs[ name ] = URL.createObjectURL( new Blob( [ bytes ] ) );
}
const FOLDER = 'fishgen-asset/';
const manager = new THREE.LoadingManager();
manager.setURLModifier( ( url ) => {
	const at = url.lastIndexOf( FOLDER );
	if ( at < 0 ) return url;
	// A name may hold spaces ("my fish_skin.png", as fishgen.exchange.sidefiles reads it); MTL map
	// options ("-imfchan m skin.png") reach us glued to the name, and then the file is the last word.
	const whole = decodeURIComponent( url.slice( at + FOLDER.length ) ).trim().replace( /^\.\//, '' );
	const last = whole.split( /\s+/ ).pop().replace( /^\.\//, '' );
	for ( const name of [ whole, last ] ) {
		const found = blobs[ name ] || blobs[ name.split( '/' ).pop() ];
		if ( found ) return found;
	}
	return url;
} );

const canvas = $( 'view' );
const renderer = drawing.webglRenderer( { canvas, antialias: true }, fail );
if ( renderer === null ) throw new Error( state.error );   // said on the page: nothing else can run
renderer.setPixelRatio( window.devicePixelRatio );
const scene = new THREE.Scene();
scene.background = new THREE.Color( embedded.background );
const camera = new THREE.PerspectiveCamera( 30, 1, 0.01, 1000 );
const controls = new OrbitControls( camera, canvas );
controls.enableDamping = true;
// from the keyboard too, once the view has the focus: arrows pan, Shift+arrows orbit (three's own),
// + and - zoom (QA pass 22: the camera had no keys and the canvas took no focus)
controls.listenToKeyEvents( canvas );
canvas.addEventListener( 'keydown', ( e ) => {
	const near = { '+': 0.8, '=': 0.8, '-': 1.25, '_': 1.25 }[ e.key ];
	if ( near === undefined || e.ctrlKey || e.metaKey || e.altKey ) return;
	e.preventDefault();
	camera.position.sub( controls.target ).multiplyScalar( near ).add( controls.target );
	controls.update();
	redraw();
} );
// Same light rig as `fishgen preview`: sun from above-front, weak fill, sky/ground hemisphere.
scene.add( new THREE.HemisphereLight( 0xc4cdd8, 0x3a3530, 1.6 ) );
const sun = new THREE.DirectionalLight( 0xfff8eb, 2.2 );
sun.position.set( 0.35, 1.0, 0.55 );
scene.add( sun );
const fill = new THREE.DirectionalLight( 0x6b7f95, 0.7 );
fill.position.set( - 0.6, 0.1, - 0.4 );
scene.add( fill );

// A fishgen cloud's sunlight is baked into the file; the viewer does Harris's second pass
// (fishgen/web/cloudlight.js).
function readLight( extras ) {
	const sun = readCloudLight( extras );
	return sun ? { sun: sun.toArray() } : null;
}

// Particles and billboards as fishgen edit draws them too (fishgen/web/cloudlight.js); drawn
// farthest first.
const particleMaterial = makeParticleMaterial();

const sorted = [];   // drawing.DepthSorted: each drawn object's primitives

const _dir = new THREE.Vector3();
function sortAll() {
	camera.getWorldDirection( _dir );
	for ( const s of sorted ) s.sort( _dir );
}

function prepareParticles( points, diagonal ) {
	const g = points.geometry;
	const n = g.getAttribute( 'position' ).count;
	if ( ! g.getAttribute( '_radius' ) ) g.setAttribute( '_radius', new THREE.BufferAttribute( new Float32Array( n ).fill( 0.004 * diagonal ), 1 ) );
	if ( ! g.getAttribute( '_density' ) ) g.setAttribute( '_density', new THREE.BufferAttribute( new Float32Array( n ).fill( 1 ), 1 ) );
	if ( ! g.getAttribute( '_light' ) ) g.setAttribute( '_light', new THREE.BufferAttribute( new Float32Array( n ).fill( - 1 ), 1 ) );
	if ( ! g.getAttribute( 'color' ) ) g.setAttribute( 'color', new THREE.BufferAttribute( new Float32Array( n * 3 ).fill( 1 ), 3 ) );
	points.material = particleMaterial;
	sorted.push( new drawing.DepthSorted( points, 1 ) );
}

function prepareBillboards( mesh ) {
	const g = mesh.geometry, n = g.getAttribute( 'position' ).count;
	if ( ! g.getAttribute( '_light' ) ) g.setAttribute( '_light', new THREE.BufferAttribute( new Float32Array( n ).fill( - 1 ), 1 ) );
	if ( ! g.getAttribute( 'color' ) ) g.setAttribute( 'color', new THREE.BufferAttribute( new Float32Array( n * 4 ).fill( 1 ), 4 ) );
	mesh.material = billboardMaterial( mesh.material );
	sorted.push( new drawing.DepthSorted( mesh, 3 ) );
}

async function load() {
	const url = FOLDER + encodeURIComponent( embedded.main );
	const kind = embedded.kind;
	if ( kind === 'glb' || kind === 'gltf' ) {
		const gltf = await new GLTFLoader( manager ).loadAsync( url );
		state.cloudLight = readLight( gltf.scene.userData );   // GLTFLoader: the scene's extras
		return { root: gltf.scene, clips: gltf.animations };
	}
	if ( kind === 'ply' ) {
		const loader = new PLYLoader( manager );
		loader.setCustomPropertyNameMapping( { _radius: [ 'radius' ], _density: [ 'density' ], _light: [ 'light' ] } );
		const geometry = await loader.loadAsync( url );
		const root = new THREE.Group();
		if ( geometry.index ) {
			if ( ! geometry.getAttribute( 'normal' ) ) geometry.computeVertexNormals();
			root.add( new THREE.Mesh( geometry, new THREE.MeshStandardMaterial( {
				vertexColors: !! geometry.getAttribute( 'color' ), side: THREE.DoubleSide, roughness: 0.8 } ) ) );
		} else {
			root.add( new THREE.Points( geometry ) );
		}
		return { root, clips: [] };
	}
	const loader = new OBJLoader( manager );
	if ( embedded.mtl ) {
		const materials = await new MTLLoader( manager ).setResourcePath( FOLDER ).loadAsync( FOLDER + encodeURIComponent( embedded.mtl ) );
		materials.preload();
		loader.setMaterials( materials );
	}
	return { root: await loader.loadAsync( url ), clips: [] };
}

// `fishgen clouds --billboards` writes a cloud as meshes of three crossed quads per particle
// (12 vertices, 6 triangles), with the material "cloud particle" (texture "gaussian sprite") or,
// for a texture cloud, "cloud texture NAME". Such a mesh is counted as particles, one per three
// quads, and not as vertices and triangles: the same cloud then reads the same exported as points
// or as billboards. Anything that does not have exactly that shape is counted as an ordinary mesh.
const CLOUD_MATERIAL = 'cloud particle', CLOUD_SPRITE = 'gaussian sprite', CLOUD_TEXTURE = 'cloud texture ';

function isBillboards( o ) {
	return [].concat( o.material ).some( ( m ) => m && ( m.name === CLOUD_MATERIAL || m.name.startsWith( CLOUD_TEXTURE )
		|| ( m.map && m.map.name === CLOUD_SPRITE ) ) );
}

function billboardQuads( o, g, n ) {
	if ( ! o.userData.fishgenBillboards || n === 0 || n % 12 !== 0 || ! g.index || g.index.count !== n / 12 * 18 ) return 0;
	return n / 12;
}

function count( root ) {
	const c = { vertices: 0, triangles: 0, particles: 0 };
	root.traverse( ( o ) => {
		const g = o.geometry;
		if ( ! g || ! g.getAttribute( 'position' ) ) return;
		const n = g.getAttribute( 'position' ).count;
		const quads = o.isMesh ? billboardQuads( o, g, n ) : 0;
		if ( o.isPoints ) c.particles += n;
		else if ( quads ) c.particles += quads;
		else if ( o.isMesh ) {
			c.vertices += n;
			c.triangles += ( g.index ? g.index.count : n ) / 3;
		}
	} );
	return c;
}

function frameCamera( root ) {
	const box = new THREE.Box3().setFromObject( root );
	const size = box.getSize( new THREE.Vector3() ).length() || 1;
	const centre = box.getCenter( new THREE.Vector3() );
	// Three-quarter view, as `fishgen preview` defaults to: a fish faces left, slightly toward us.
	const dir = new THREE.Vector3( 1, 0.45, 0.7 ).normalize();
	camera.position.copy( centre ).addScaledVector( dir, size * 2.0 );
	camera.near = size / 100;
	camera.far = size * 100;
	camera.updateProjectionMatrix();
	controls.target.copy( centre );
	controls.update();
	return size;
}

let mixer = null;
let school = schools.instanceSchools( new THREE.Group(), [] );   // the instanced schools, once loaded
let clipObjects = [];
let action = null;
let duration = 0;
const timer = new THREE.Timer();
const slider = $( 'time' );

function choose( index ) {
	if ( ! mixer ) return;
	mixer.stopAllAction();
	const clip = clipObjects[ index ];
	action = mixer.clipAction( clip );
	action.play();
	school.follow( mixer );
	duration = clip.duration;
	state.clip = clip.name;
	slider.max = String( duration );
	setPlaying( true );
}

function setPlaying( on ) {
	state.playing = on && !! action;
	$( 'play' ).textContent = state.playing ? 'Pause' : 'Play';
}

// A frame is drawn only when something changed (the camera, the size, the clip's time, the
// wireframe): a big cloud on a software renderer takes seconds a frame.
let dirty = true;
const redraw = () => { dirty = true; };

function resize() {
	if ( drawing.fitCanvas( renderer, camera, canvas ) ) dirty = true;
	particleMaterial.uniforms.viewportHeight.value = canvas.clientHeight * renderer.getPixelRatio();
}

function tick( now ) {
	timer.update( now );
	const dt = timer.getDelta();
	resize();
	if ( mixer && state.playing ) {
		mixer.update( dt );
		school.follow( mixer );
		state.time = duration > 0 ? mixer.time % duration : 0;
		slider.value = String( state.time );
		dirty = true;
	}
	$( 'clock' ).textContent = mixer ? `${ state.time.toFixed( 2 ) } / ${ duration.toFixed( 2 ) } s` : '';
	controls.update();
	if ( dirty ) {
		dirty = false;
		renderer.render( scene, camera );
		state.calls = renderer.info.render.calls;
	}
	requestAnimationFrame( tick );
}

load().then( ( { root, clips } ) => {
	scene.add( root );
	const diagonal = frameCamera( root );
	root.updateMatrixWorld( true );
	root.traverse( ( o ) => {
		if ( o.isPoints ) prepareParticles( o, diagonal );
		else if ( o.isMesh && isBillboards( o ) ) {
			o.userData.fishgenBillboards = true;
			prepareBillboards( o );
		}
	} );
	sortAll();
	controls.addEventListener( 'change', () => { sortAll(); redraw(); } );
	redraw();
	state.counts = count( root );
	const c = state.counts;
	const n = ( v ) => v.toLocaleString( 'en' );
	$( 'counts' ).textContent = `${ n( c.vertices ) } vertices · ${ n( c.triangles ) } triangles · ${ n( c.particles ) } particles`;
	school = schools.instanceSchools( root, clips, instancing );   // counted above as the file holds them
	state.instanced = school.info;
	state.instances = () => schools.instancePositions( school );
	clips = school.clips;
	const select = $( 'clip' );
	clipObjects = clips;
	state.clips = clips.map( ( clip ) => clip.name );
	clips.forEach( ( clip, i ) => select.add( new Option( clip.name || `clip ${ i }`, String( i ) ) ) );
	const animated = clips.length > 0;
	for ( const id of [ 'clip', 'play', 'time' ] ) $( id ).disabled = ! animated;
	if ( animated ) {
		mixer = new THREE.AnimationMixer( root );
		choose( 0 );
	}
	$( 'status' ).textContent = embedded.main;
	state.loaded = true;
} ).catch( fail );

$( 'clip' ).addEventListener( 'change', ( e ) => choose( Number( e.target.value ) ) );
$( 'play' ).addEventListener( 'click', () => setPlaying( ! state.playing ) );
slider.addEventListener( 'input', () => {
	if ( ! mixer ) return;
	setPlaying( false );
	mixer.setTime( Number( slider.value ) );
	school.follow( mixer );
	state.time = Number( slider.value );
	redraw();
} );
$( 'wireframe' ).addEventListener( 'change', ( e ) => {
	scene.traverse( ( o ) => {
		if ( o.isMesh ) for ( const m of [].concat( o.material ) ) m.wireframe = e.target.checked;
	} );
	redraw();
} );
requestAnimationFrame( tick );
