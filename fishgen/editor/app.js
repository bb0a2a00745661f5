// fishgen edit: RekAwan's cloud cube editor (report 004, Appendix A and its user manual) in a page.
// The page holds the cubes; the server parses, fills, lights and saves them with fishgen's own code.
// State for people and tests alike: window.fishgenEditor (see `state` below).
import { CloudView } from './cloudview.js';

const { THREE, OrbitControls, TransformControls, cloudlight, drawing } = window.fishgenKit;   // fishgen/web/kit.js

const $ = ( id ) => document.getElementById( id );
const TOKEN = new URLSearchParams( location.search ).get( 'token' ) || '';
const SUFFIX = { particles: '.awn', texture: '.awa' };
const HISTORY = 500;              // undo steps kept
const HANDLE_DIGITS = 1e4;        // values dragged by a handle are rounded to 0.0001 (no snapping)
const MIN_SIZE = 0.01;            // a handle never scales a cube below this
const LISTED = 5000;              // cubes named in the Cube list
// A sum or multiple of decimal steps without binary noise: 0.1 x 3 is 0.30000000000000004 in a
// double, which the fields showed and the file kept (QA pass 22); 12 digits hold any value typed.
const tidy = ( v ) => Number( v.toPrecision( 12 ) );

// -- the document ------------------------------------------------------------------------------------
const doc = { mode: 'particles', cubes: [] };   // what a file holds: cubes {particles, size, centre, radius, texture}
let name = '';                                 // the file the document was opened from or saved as
let selected = - 1;
// Fields holding text that is no valid value, each kept as typed (and marked) while the cube it was
// typed for is the one selected, also once it loses the focus: a click on Save had put the old
// value back and saved it without a word (QA pass 22); now Save refuses while one is shown. Keyed
// by the cube object, so a cube added, duplicated, deleted or undone is not shown another's typing.
const typedWrong = new Map();    // input -> the cube it was typed for
let fieldMessage = null;         // the message line as a field's error (or a save it stopped) left it
let conflicted = null;           // the name a save was refused under (409): the next Save there asks
let emptyNote = null;            // the message a new file's empty workspace left, until a cube is added
let saved = '';                                // the document as last opened or saved (JSON)
let stamp = null;                              // the file's bytes as last read or written (its hash), or null
let textures = [];                             // names a .awa file may use
let files = [];
let settings = { seed: 0, sun: [ 0.35, 1, 0.55 ], limits: {} };
let sun = null;                                // the page's sun, once the user moves it (else the server's)

const state = window.fishgenEditor = {
	ready: false, error: null, message: '', frames: 0,
	get name() { return name; }, get mode() { return doc.mode; }, get cubes() { return structuredClone( doc.cubes ); },
	get selected() { return selected; }, get dirty() { return isDirty(); },
	undoSteps: 0, redoSteps: 0,
	fill: { busy: false, since: 0, sent: 0, shown: 0, version: 0, ms: null, latency: null, particles: 0, note: null, error: null,
		steps: null },   // steps: ms from the edit to the request, the answer, the preview built, the frame drawn
	previewParticles: () => view.particles(),
	previewBillboards: () => view.billboardMeshes(),
	handlePoint: ( axis, along = 0.45 ) => handlePoint( axis, along ),
	cubePoint: ( index ) => cubePoint( index ),
	cubeColor: ( index ) => cubes.children[ index ] ? '#' + cubes.children[ index ].material.color.getHexString() : null,
	select: ( index ) => select( index ),
	drawMs: () => drawMs(),
	previewSize: () => [ previewBuffer.width, previewBuffer.height, canvas.width, canvas.height ],
};

const json = () => JSON.stringify( { mode: doc.mode, cubes: doc.cubes } );
const isDirty = () => json() !== saved;
const total = () => doc.cubes.reduce( ( sum, c ) => sum + c.particles, 0 );
const current = () => doc.cubes[ selected ] || null;

// -- history: every change is one step; typing into one field of one cube is one step ------------------
const undo = [], redo = [];
let lastKey = null;
let version = 0;
const changedAt = new Map();                   // document version -> when it changed (for the fill latency)

function snapshot() {
	return { mode: doc.mode, cubes: structuredClone( doc.cubes ), selected };
}

function restore( s ) {
	doc.mode = s.mode;
	doc.cubes = structuredClone( s.cubes );
	selected = Math.min( s.selected, doc.cubes.length - 1 );
}

// Apply `mutate` as one undoable step; consecutive changes with the same `key` (typing in a field) merge.
function change( mutate, key = null ) {
	const before = snapshot();
	if ( mutate() === false ) return;
	if ( key === null || key !== lastKey ) {
		undo.push( before );
		if ( undo.length > HISTORY ) undo.shift();
	}
	lastKey = key;
	redo.length = 0;
	changed();
}

// Back to the last state on ``from`` (undo or redo), this one kept on ``to`` to come back to.
function step( from, to ) {
	if ( ! from.length ) return;
	to.push( snapshot() );
	restore( from.pop() );
	lastKey = null;
	typedWrong.clear();
	changed();
}

const undoStep = () => step( undo, redo ), redoStep = () => step( redo, undo );

// -- three.js: the workspace ---------------------------------------------------------------------------
const canvas = $( 'view' );
// without WebGL the workspace draws nothing, but the cubes can still be edited by their numbers,
// filled and saved (the page says so, and keeps saying it: see `say`)
let noWebGL = '';
const renderer = drawing.webglRenderer( { canvas, antialias: true, preserveDrawingBuffer: true }, ( text ) => { noWebGL = text; } )
	|| drawing.noRenderer( canvas );
renderer.setPixelRatio( window.devicePixelRatio );
const scene = new THREE.Scene();
scene.background = new THREE.Color( 0x7ea3c9 );
const camera = new THREE.PerspectiveCamera( 40, 1, 0.05, 5000 );
const orbit = new OrbitControls( camera, canvas );
const grid = new THREE.GridHelper( 40, 40, 0x2c3e50, 0x56708c );
// drawn first and writing no depth: the cloud covers the grid where it is, never cut by its plane
Object.assign( grid.material, { transparent: true, opacity: 0.6, depthWrite: false } );
grid.renderOrder = - 1;
scene.add( grid );
scene.add( new THREE.AxesHelper( 6 ) );
const sunArrow = new THREE.ArrowHelper( new THREE.Vector3( 0, 1, 0 ), new THREE.Vector3(), 4, 0xffd54f, 0.8, 0.4 );
scene.add( sunArrow );
const view = new CloudView( scene );

const BOX = new THREE.BoxGeometry( 1, 1, 1 );
const EDGES = new THREE.EdgesGeometry( BOX );
const QUAD = new THREE.PlaneGeometry( 1, 1 );
const materials = {
	cube: new THREE.MeshBasicMaterial( { color: 0xe8eef5, transparent: true, opacity: 0.28, depthWrite: false } ),
	chosen: new THREE.MeshBasicMaterial( { color: 0xe53935, transparent: true, opacity: 0.5, depthWrite: false } ),
	edge: new THREE.LineBasicMaterial( { color: 0xf4f7fb, transparent: true, opacity: 0.4, depthWrite: false } ),
	chosenEdge: new THREE.LineBasicMaterial( { color: 0xff1744 } ),
};
const cubes = new THREE.Group();
scene.add( cubes );
const transform = new TransformControls( camera, canvas );
scene.add( transform.getHelper() );

const toggles = { cubes: true, quads: false, billboards: true, boxes: true, textures: true, particles: true };
const textureCache = new Map();

function texture( name ) {
	if ( ! textureCache.has( name ) ) {
		const t = new THREE.TextureLoader().load( textureUrl( name ), () => redraw() );
		t.colorSpace = THREE.SRGBColorSpace;
		textureCache.set( name, new THREE.MeshBasicMaterial( { map: t, transparent: true, depthWrite: false, side: THREE.DoubleSide } ) );
	}
	return textureCache.get( name );
}

const PLAIN_QUAD = new THREE.MeshBasicMaterial( { color: 0xffffff, transparent: true, opacity: 0.6, depthWrite: false, side: THREE.DoubleSide } );
const textureUrl = ( n ) => `/api/texture?name=${ encodeURIComponent( n ) }&token=${ encodeURIComponent( TOKEN ) }`;

// One mesh per cube (a unit box scaled to its size), with its edges and, in texture mode, its quad.
function syncCubes() {
	while ( cubes.children.length > doc.cubes.length ) cubes.remove( cubes.children[ cubes.children.length - 1 ] );
	while ( cubes.children.length < doc.cubes.length ) {
		const mesh = new THREE.Mesh( BOX, materials.cube );
		mesh.add( new THREE.LineSegments( EDGES, materials.edge ) );
		const quad = new THREE.Mesh( QUAD, PLAIN_QUAD );
		quad.name = 'quad';
		mesh.add( quad );
		cubes.add( mesh );
	}
	doc.cubes.forEach( ( c, i ) => {
		const mesh = cubes.children[ i ];
		mesh.userData.index = i;
		mesh.position.set( ...c.centre );
		mesh.scale.set( ...c.size );
		const chosen = i === selected;
		mesh.material = chosen ? materials.chosen : materials.cube;
		mesh.renderOrder = 1;
		const [ edges, quad ] = mesh.children;
		edges.material = chosen ? materials.chosenEdge : materials.edge;
		edges.visible = toggles.boxes;
		quad.visible = doc.mode === 'texture' && toggles.quads;
		quad.material = toggles.textures && c.texture ? texture( c.texture ) : PLAIN_QUAD;
	} );
	materials.cube.visible = materials.chosen.visible = toggles.cubes;
	const mesh = cubes.children[ selected ];
	if ( mesh && transform.object !== mesh ) transform.attach( mesh );
	if ( ! mesh ) transform.detach();
	redraw();
}

// -- the camera: orbit, zoom, reset --------------------------------------------------------------------
let home = { target: new THREE.Vector3(), distance: 30 };
const VIEW_DIRECTION = new THREE.Vector3( 0.35, 0.45, 1 ).normalize();

function bounds() {
	const box = new THREE.Box3();
	for ( const c of doc.cubes ) {
		box.expandByPoint( new THREE.Vector3( ...c.centre ).addScaledVector( new THREE.Vector3( ...c.size ), 0.5 ) );
		box.expandByPoint( new THREE.Vector3( ...c.centre ).addScaledVector( new THREE.Vector3( ...c.size ), - 0.5 ) );
		box.expandByScalar( 0 );
	}
	if ( box.isEmpty() ) box.setFromCenterAndSize( new THREE.Vector3(), new THREE.Vector3( 12, 6, 12 ) );
	return box;
}

function resetView() {
	const sphere = bounds().getBoundingSphere( new THREE.Sphere() );
	const radius = Math.max( sphere.radius, 3 ) * 0.75 + 1;   // the particles reach a little past the cubes
	home = { target: sphere.center.clone(), distance: radius / Math.sin( THREE.MathUtils.degToRad( camera.fov / 2 ) ) };
	orbit.target.copy( home.target );
	camera.position.copy( home.target ).addScaledVector( VIEW_DIRECTION, home.distance );
	camera.near = home.distance / 500;
	camera.far = home.distance * 50;
	camera.updateProjectionMatrix();
	orbit.update();
	showZoom();
	redraw();
}

function zoom() {
	return home.distance / camera.position.distanceTo( orbit.target );
}

function setZoom( z ) {
	const dir = camera.position.clone().sub( orbit.target ).normalize();
	camera.position.copy( orbit.target ).addScaledVector( dir, home.distance / z );
	orbit.update();
	redraw();
}

function showZoom() {
	if ( document.activeElement !== $( 'zoom' ) ) $( 'zoom' ).value = String( Math.round( zoom() * 100 ) / 100 );
}

// -- drawing: a frame only when something changed ------------------------------------------------------
let dirtyFrame = true, sortNeeded = true;
const redraw = () => { dirtyFrame = true; };

function resize() {
	if ( drawing.fitCanvas( renderer, camera, canvas ) ) {
		const w = Math.max( 1, Math.round( canvas.width * PREVIEW_SCALE ) ), h = Math.max( 1, Math.round( canvas.height * PREVIEW_SCALE ) );
		previewBuffer.setSize( w, h );
		view.setViewport( h );
		redraw();
	}
}

// The preview is drawn as fishgen fly draws its clouds (docs/editor.md, "Drawing"): into a buffer of
// PREVIEW_SCALE of the canvas's width and height, without multisampling, laid over the workspace.
// Soft particles are fill-bound on a software renderer (SwiftShader took 4 s for a frame of 5,000 at
// 1280 x 800 with the cloud on the multisampled canvas); the cubes, their handles and the sun arrow
// are drawn after it, on top.
const PREVIEW_SCALE = 0.5;
const previewBuffer = new THREE.WebGLRenderTarget( 1, 1, { depthBuffer: false } );
const overlayScene = new THREE.Scene(), overlayCamera = new THREE.OrthographicCamera();
const overlay = new THREE.Mesh( new THREE.PlaneGeometry( 2, 2 ), new THREE.ShaderMaterial( {
	uniforms: { map: { value: previewBuffer.texture } }, transparent: true, depthTest: false, depthWrite: false, ...cloudlight.PREMULTIPLIED,
	vertexShader: 'varying vec2 vUv; void main() { vUv = uv; gl_Position = vec4( position.xy, 0.0, 1.0 ); }',
	fragmentShader: 'uniform sampler2D map; varying vec2 vUv; void main() { gl_FragColor = texture2D( map, vUv ); }',
} ) );
overlay.frustumCulled = false;
overlayScene.add( overlay );

function drawFrame() {
	const helper = transform.getHelper(), over = [ cubes, helper, sunArrow ];
	const shown = [ view.group.visible, ...over.map( ( o ) => o.visible ) ];
	view.group.visible = false;
	for ( const o of over ) o.visible = false;
	renderer.autoClear = true;
	renderer.render( scene, camera );   // the sky, the grid, the axes
	view.group.visible = shown[ 0 ];
	over.forEach( ( o, k ) => { o.visible = shown[ k + 1 ]; } );
	renderer.autoClear = false;
	if ( view.group.visible && view.group.children.length ) {
		renderer.setRenderTarget( previewBuffer );
		renderer.setClearColor( 0x000000, 0 );
		renderer.clear();
		renderer.render( view.group, camera );
		renderer.setRenderTarget( null );
		renderer.render( overlayScene, overlayCamera );
	}
	for ( const o of over ) if ( o.visible ) renderer.render( o, camera );   // the cubes, handles and sun on top
	renderer.autoClear = true;
}

// A software renderer (no GPU) can take most of a second a frame: then, while a fill is on its way,
// the frame of the old cloud under the edited cube is skipped (for at most HOLD ms), so the new
// cloud is the next frame drawn, not the one after.
const SLOW_FRAME = 150, HOLD = 1500;
let lastFrame = 0, frameGap = 0;

function tick( now ) {
	resize();
	if ( lastFrame ) { frameGap = now - lastFrame; lastFrame = 0; }
	const hold = state.fill.busy && frameGap > SLOW_FRAME && now - state.fill.since < HOLD;
	if ( dirtyFrame && ! hold ) {
		dirtyFrame = false;
		if ( sortNeeded ) { view.sort( camera ); sortNeeded = false; }
		drawFrame();
		state.frames ++;
		lastFrame = now;
		if ( pendingShown !== null ) {
			state.fill.shown = pendingShown.seq;
			// the frame is drawn once a pixel of it can be read back (the GPU, or SwiftShader, is done)
			const gl = renderer.getContext();
			gl.readPixels( 0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array( 4 ) );
			const at = changedAt.get( pendingShown.version ), done = performance.now();
			state.fill.latency = at === undefined ? null : Math.round( done - at );
			if ( at !== undefined ) state.fill.steps = [ ...pendingShown.steps.map( ( t ) => Math.round( t - at ) ), Math.round( done - at ) ];
			pendingShown = null;
			showFill();
		}
	}
	requestAnimationFrame( tick );
}

// One frame drawn and read back, timed: what the renderer (a GPU, or SwiftShader) takes for the scene.
function drawMs() {
	const start = performance.now(), gl = renderer.getContext();
	drawFrame();
	gl.readPixels( 0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array( 4 ) );
	return Math.round( performance.now() - start );
}

orbit.addEventListener( 'change', () => { sortNeeded = true; showZoom(); redraw(); } );
transform.addEventListener( 'change', redraw );

// -- selecting and moving cubes in the view -----------------------------------------------------------
let dragBefore = null;
transform.addEventListener( 'dragging-changed', ( e ) => { orbit.enabled = ! e.value; } );
transform.addEventListener( 'mouseDown', () => { dragBefore = snapshot(); } );
transform.addEventListener( 'objectChange', () => {
	const c = current(), mesh = transform.object;
	if ( ! c || ! mesh ) return;
	const step = snapping();
	const round = ( v ) => step ? tidy( Math.round( v / step ) * step ) : Math.round( v * HANDLE_DIGITS ) / HANDLE_DIGITS;
	const sized = ( v ) => Math.max( Math.abs( round( v ) ), step || MIN_SIZE );
	// only what the handle moved is rounded (or snapped): the other values stay exactly as they were
	c.centre = mesh.position.toArray().map( ( v, k ) => v === c.centre[ k ] ? v : round( v ) );
	c.size = mesh.scale.toArray().map( ( v, k ) => v === c.size[ k ] ? v : sized( v ) );
	mesh.position.set( ...c.centre );
	mesh.scale.set( ...c.size );
	version ++;
	changedAt.set( version, performance.now() );
	showCube();
	showTotals();
	requestFill();
} );
transform.addEventListener( 'mouseUp', () => {
	if ( dragBefore && JSON.stringify( dragBefore.cubes ) !== JSON.stringify( doc.cubes ) ) {
		undo.push( dragBefore );
		if ( undo.length > HISTORY ) undo.shift();
		redo.length = 0;
		lastKey = null;
		changed();
	}
	dragBefore = null;
} );

const pointer = { x: 0, y: 0, down: false, onHandle: false };
canvas.addEventListener( 'pointerdown', ( e ) => {
	Object.assign( pointer, { x: e.clientX, y: e.clientY, down: true, onHandle: transform.axis !== null } );
} );
canvas.addEventListener( 'pointerup', ( e ) => {
	if ( ! pointer.down ) return;
	pointer.down = false;
	if ( pointer.onHandle || Math.hypot( e.clientX - pointer.x, e.clientY - pointer.y ) > 5 ) return;
	const rect = canvas.getBoundingClientRect();
	const ndc = new THREE.Vector2( ( e.clientX - rect.left ) / rect.width * 2 - 1, - ( e.clientY - rect.top ) / rect.height * 2 + 1 );
	const ray = new THREE.Raycaster();
	ray.setFromCamera( ndc, camera );
	const hit = ray.intersectObjects( cubes.children, false )[ 0 ];
	select( hit ? hit.object.userData.index : - 1 );
} );

// Where a handle of the selected cube is on the screen (CSS pixels in the page), for tests and scripts.
function handlePoint( axis, along ) {
	const mesh = transform.object;
	if ( ! mesh ) return null;
	const size = transform.size * mesh.position.distanceTo( camera.position ) * Math.min( 1.9 * Math.tan( Math.PI * camera.fov / 360 ) / camera.zoom, 7 ) / 4;
	const dir = { X: [ 1, 0, 0 ], Y: [ 0, 1, 0 ], Z: [ 0, 0, 1 ] }[ axis ];
	return toScreen( mesh.position.clone().addScaledVector( new THREE.Vector3( ...dir ), along * size ) );
}

function cubePoint( index ) {
	const c = doc.cubes[ index ];
	return c ? toScreen( new THREE.Vector3( ...c.centre ) ) : null;
}

function toScreen( p ) {
	camera.updateMatrixWorld();
	const v = p.clone().project( camera ), rect = canvas.getBoundingClientRect();
	return { x: rect.left + ( v.x + 1 ) / 2 * rect.width, y: rect.top + ( 1 - v.y ) / 2 * rect.height };
}

function select( index ) {
	selected = index >= 0 && index < doc.cubes.length ? index : - 1;
	lastKey = null;
	typedWrong.clear();   // choosing a cube (the same one too) shows its values again
	syncCubes();
	showCube();
}

// -- the controls -------------------------------------------------------------------------------------
const FIELDS = {   // input id -> how it reads and writes the selected cube
	particles: { get: ( c ) => c.particles, set: ( c, v ) => { c.particles = v; }, whole: true, min: 0 },
	billboards: { get: ( c ) => c.particles, set: ( c, v ) => { c.particles = v; }, whole: true, min: 0 },
	radius: { get: ( c ) => c.radius, set: ( c, v ) => { c.radius = v; }, above: 0 },
	length: { get: ( c ) => c.size[ 0 ], set: ( c, v ) => { c.size[ 0 ] = v; }, above: 0 },
	height: { get: ( c ) => c.size[ 1 ], set: ( c, v ) => { c.size[ 1 ] = v; }, above: 0 },
	width: { get: ( c ) => c.size[ 2 ], set: ( c, v ) => { c.size[ 2 ] = v; }, above: 0 },
	'centre-x': { get: ( c ) => c.centre[ 0 ], set: ( c, v ) => { c.centre[ 0 ] = v; } },
	'centre-y': { get: ( c ) => c.centre[ 1 ], set: ( c, v ) => { c.centre[ 1 ] = v; } },
	'centre-z': { get: ( c ) => c.centre[ 2 ], set: ( c, v ) => { c.centre[ 2 ] = v; } },
};

function parseField( id, text ) {
	const f = FIELDS[ id ], label = $( id ).labels[ 0 ].textContent;
	if ( $( id ).dataset.comma && text.trim() !== '' ) return { error: `${ label }: expected a point before the decimals (2.5), found a comma` };
	delete $( id ).dataset.comma;
	const v = text.trim() === '' ? NaN : Number( text );
	// the browser gives no text for what it cannot read as a number (1e309, "1..2")
	if ( $( id ).validity.badInput ) return { error: `${ label }: expected a number, found something the browser cannot read as one (too large, or not a number)` };
	if ( ! Number.isFinite( v ) ) return { error: `${ label }: expected a number, found ${ JSON.stringify( text ) }` };
	if ( f.whole && ( ! Number.isInteger( v ) || v < f.min ) ) return { error: `${ label }: expected a whole number of 0 or more, found ${ text }` };
	if ( f.above !== undefined && ! ( v > f.above ) ) return { error: `${ label }: expected a number greater than 0, found ${ text }` };
	return { value: v };
}

for ( const id of Object.keys( FIELDS ) ) {
	const input = $( id );
	input.addEventListener( 'input', () => {
		const c = current();
		if ( ! c ) return;
		const { value, error } = parseField( id, input.value );
		input.setAttribute( 'aria-invalid', error ? 'true' : 'false' );
		if ( error ) { typedWrong.set( input, c ); say( error, true ); fieldMessage = state.message; return; }
		typedWrong.delete( input );
		if ( state.message === fieldMessage ) say( '' );   // a field's own error goes; a save's stays
		if ( FIELDS[ id ].get( c ) === value ) return;
		change( () => FIELDS[ id ].set( current(), value ), `${ id }:${ selected }` );
	} );
	input.addEventListener( 'change', () => { lastKey = null; showCube(); } );
	// Chromium drops a comma from a number field without a word: 2,5 became a radius of 25 (QA 22).
	// A comma typed marks the field wrong until it is emptied or its cube's value shown again.
	input.addEventListener( 'keydown', ( e ) => {
		if ( e.key !== ',' ) return;
		e.preventDefault();
		input.dataset.comma = 'typed';
		input.dispatchEvent( new Event( 'input' ) );
	} );
}

function showCube() {
	const c = current();
	for ( const [ id, f ] of Object.entries( FIELDS ) ) {
		const input = $( id );
		input.disabled = ! c;
		if ( c && typedWrong.get( input ) === c ) continue;
		typedWrong.delete( input );
		delete input.dataset.comma;
		if ( document.activeElement !== input || ! c || Number( input.value ) !== f.get( c ) ) input.value = c ? String( f.get( c ) ) : '';
		input.setAttribute( 'aria-invalid', 'false' );
	}
	for ( const id of [ 'delete', 'duplicate', 'scale-all', 'set-texture' ] ) $( id ).disabled = ! c;
	$( 'delete-all' ).disabled = doc.cubes.length === 0;
	const list = $( 'cube' );
	// the first LISTED cubes, and the selected one past them: a list of 50,000 options took seconds,
	// and a cube past the end was selected with nothing shown (QA pass 22)
	const beyond = selected >= LISTED ? String( selected ) : '';
	if ( list.dataset.version !== String( version ) || list.dataset.beyond !== beyond ) {
		const noun = doc.mode === 'texture' ? 'billboards' : 'particles';
		const option = ( c, i ) => new Option( `${ i + 1 }: ${ c.particles } ${ noun } at ${ c.centre.map( ( v ) => Math.round( v * 100 ) / 100 ).join( ', ' ) }`
			+ ( doc.mode === 'texture' && c.texture ? ` (${ c.texture })` : '' ), String( i ) );
		const more = doc.cubes.length - LISTED;
		const rest = more > 0 ? [ Object.assign( new Option( `… ${ more.toLocaleString( 'en' ) } more: click one in the workspace`, '' ), { disabled: true } ) ] : [];
		list.replaceChildren( new Option( doc.cubes.length ? 'none selected' : 'no cubes', '-1' ),
			...doc.cubes.slice( 0, LISTED ).map( option ), ...( beyond ? [ option( doc.cubes[ selected ], selected ) ] : [] ), ...rest );
		list.dataset.version = String( version );
		list.dataset.beyond = beyond;
	}
	list.value = String( selected );
	if ( c && c.texture && textures.includes( c.texture ) && document.activeElement !== $( 'texture' ) ) $( 'texture' ).value = c.texture;
	showThumbnail();
}

$( 'cube' ).addEventListener( 'change', () => select( Number( $( 'cube' ).value ) ) );

// A new cube beside the selected one (or beside the last, or at the origin): same size and radius.
function besides( c ) {
	const centre = [ ...c.centre ];
	centre[ 0 ] += c.size[ 0 ];
	return centre;
}

function newCube() {
	const base = current() || doc.cubes[ doc.cubes.length - 1 ];
	const tex = doc.mode === 'texture' ? ( $( 'texture' ).value || textures[ 0 ] || null ) : ( base ? base.texture : null );
	if ( ! base ) return { particles: 10, size: [ 1, 1, 1 ], centre: [ 0, 0, 0 ], radius: 2, texture: tex };
	return { particles: 10, size: [ ...base.size ], centre: besides( base ), radius: base.radius, texture: tex };
}

function addCube() {
	change( () => { doc.cubes.push( newCube() ); selected = doc.cubes.length - 1; } );
}

function duplicate() {
	const c = current();
	if ( ! c ) return;
	change( () => {
		const copy = structuredClone( c );
		copy.centre = besides( c );
		doc.cubes.splice( selected + 1, 0, copy );
		selected += 1;
	} );
}

function deleteCube() {
	if ( ! current() ) return;
	change( () => {
		doc.cubes.splice( selected, 1 );
		selected = Math.min( selected, doc.cubes.length - 1 );
	} );
}

function deleteAll() {
	if ( ! doc.cubes.length ) return;
	change( () => { doc.cubes = []; selected = - 1; } );
}

$( 'add' ).addEventListener( 'click', addCube );
$( 'duplicate' ).addEventListener( 'click', duplicate );
$( 'delete' ).addEventListener( 'click', deleteCube );
$( 'delete-all' ).addEventListener( 'click', deleteAll );
$( 'undo' ).addEventListener( 'click', undoStep );
$( 'redo' ).addEventListener( 'click', redoStep );

// Scale All: the selected cube's three sizes times the factor given (then back to 1).
$( 'scale-all' ).addEventListener( 'change', () => {
	const input = $( 'scale-all' ), f = Number( input.value ), c = current();
	input.value = '1';
	if ( ! c ) return;
	if ( ! ( f > 0 ) || ! Number.isFinite( f ) ) { say( `Scale All: expected a factor greater than 0, found ${ JSON.stringify( input.value ) }`, true ); return; }
	if ( f === 1 ) return;
	change( () => { current().size = current().size.map( ( v ) => v * f ); } );
} );

$( 'zoom' ).addEventListener( 'input', () => {
	const z = Number( $( 'zoom' ).value );
	if ( z > 0 && Number.isFinite( z ) ) setZoom( z );
} );
$( 'reset-view' ).addEventListener( 'click', resetView );

// Handles: move or scale; snapping to a grid step (handles only: typed values stay as typed).
function gridStep() {
	const step = Number( $( 'grid-step' ).value );
	return step > 0 && Number.isFinite( step ) ? step : 0;
}

function snapping() {
	return $( 'snap' ).checked ? gridStep() : 0;
}

function applySnap() {
	const step = snapping();
	transform.setTranslationSnap( step || null );
	transform.setScaleSnap( step || null );
}

for ( const id of [ 'snap', 'grid-step' ] ) $( id ).addEventListener( 'input', applySnap );
for ( const r of document.querySelectorAll( 'input[name=handles]' ) ) {
	r.addEventListener( 'change', () => transform.setMode( r.value ) );
}

function setHandles( mode ) {
	transform.setMode( mode );
	for ( const r of document.querySelectorAll( 'input[name=handles]' ) ) r.checked = r.value === mode;
}

// -- the two systems ---------------------------------------------------------------------------------
for ( const r of document.querySelectorAll( 'input[name=system]' ) ) {
	r.addEventListener( 'change', () => {
		if ( ! r.checked || r.value === doc.mode ) return;
		change( () => {
			doc.mode = r.value;
			if ( doc.mode === 'texture' ) {
				const tex = $( 'texture' ).value || textures[ 0 ] || null;
				for ( const c of doc.cubes ) if ( ! c.texture ) c.texture = tex;
			}
		} );
		const box = $( 'file-name' ), other = r.value === 'texture' ? SUFFIX.particles : SUFFIX.texture;
		if ( box.value.toLowerCase().endsWith( other ) ) box.value = box.value.slice( 0, - other.length ) + SUFFIX[ r.value ];
	} );
}

function showMode() {
	for ( const r of document.querySelectorAll( 'input[name=system]' ) ) r.checked = r.value === doc.mode;
	$( 'particle-option' ).hidden = doc.mode !== 'particles';
	$( 'texture-option' ).hidden = doc.mode !== 'texture';
	document.body.dataset.mode = doc.mode;
}

// -- texture option: Set Texture, Set To All, the view toggles ---------------------------------------
function showTextures() {
	const select = $( 'texture' ), keep = select.value;
	select.replaceChildren( ...textures.map( ( t ) => new Option( t, t ) ) );
	if ( textures.includes( keep ) ) select.value = keep;
	$( 'no-textures' ).hidden = textures.length > 0;
	showThumbnail();
}

function showThumbnail() {
	const img = $( 'thumbnail' ), t = $( 'texture' ).value;
	if ( ! t ) { img.hidden = true; return; }
	const url = textureUrl( t );
	if ( img.getAttribute( 'src' ) !== url ) img.src = url;
	img.hidden = false;
}

$( 'texture' ).addEventListener( 'change', showThumbnail );
$( 'set-texture' ).addEventListener( 'click', () => {
	const t = $( 'texture' ).value, c = current();
	if ( ! t || ! c || c.texture === t ) return;
	change( () => { current().texture = t; } );
} );
$( 'set-to-all' ).addEventListener( 'click', () => {
	const t = $( 'texture' ).value;
	if ( ! t || doc.cubes.every( ( c ) => c.texture === t ) ) return;
	change( () => { for ( const c of doc.cubes ) c.texture = t; } );
} );

// The manual: Cubes and Quads turn Bounding Box on; Billboards turns Bounding Box and Show Texture on.
const TOGGLES = { 'show-cubes': 'cubes', 'show-quads': 'quads', 'show-billboards': 'billboards', 'show-boxes': 'boxes',
	'show-textures': 'textures', 'show-particles': 'particles' };
const IMPLIES = { 'show-cubes': [ 'show-boxes' ], 'show-quads': [ 'show-boxes' ], 'show-billboards': [ 'show-boxes', 'show-textures' ] };
for ( const [ id, key ] of Object.entries( TOGGLES ) ) {
	$( id ).addEventListener( 'change', () => {
		if ( $( id ).checked ) for ( const other of IMPLIES[ id ] || [] ) $( other ).checked = true;
		for ( const [ i, k ] of Object.entries( TOGGLES ) ) toggles[ k ] = $( i ).checked;
		if ( key === 'textures' ) view.setTextured( toggles.textures );
		showPreview();
		syncCubes();
		if ( ( key === 'particles' || key === 'billboards' ) && $( id ).checked ) requestFill();
	} );
}

function showPreview() {
	view.group.visible = previewOn && ( doc.mode === 'texture' ? toggles.billboards : toggles.particles ) && previewMode === doc.mode;
	redraw();
}

// -- the preview: filled and lit on the server, refreshed on every change ------------------------------
let previewOn = false, previewMode = null, wanted = false, pendingShown = null;

function requestFill() {
	if ( ! previewOn ) return;
	wanted = true;
	pump();
}

async function pump() {
	const f = state.fill;
	if ( f.busy || ! wanted ) return;
	wanted = false;
	if ( ! doc.cubes.length || total() === 0 ) {
		view.clear();
		f.particles = 0;
		f.note = null;
		f.error = null;
		state.fill.shown = ++ f.sent;
		showFill();
		redraw();
		return;
	}
	f.busy = true;
	f.since = performance.now();
	const seq = ++ f.sent, at = version, mode = doc.mode;
	const body = { name, mode, cubes: doc.cubes, seed: seed(), sun };
	try {
		const sent = performance.now();
		const data = await api( '/api/fill', body, 'arrayBuffer' );
		const answered = performance.now();
		const length = new DataView( data ).getUint32( 0, true );
		const facts = JSON.parse( new TextDecoder().decode( new Uint8Array( data, 4, length ) ) );
		await view.show( data.slice( 4 + length ) );
		const built = performance.now();
		Object.assign( f, { ms: facts.ms, particles: facts.particles, note: facts.note, error: null, version: at } );
		previewMode = mode;
		sortNeeded = true;
		pendingShown = { seq, version: at, steps: [ sent, answered, built ] };
		showPreview();
		say( '' );
	} catch ( err ) {
		f.error = err.message;
		state.fill.shown = seq;
		say( err.message, true, err.line );
		showFill();
	} finally {
		f.busy = false;
		pump();
	}
}

function seed() {
	const s = Number( $( 'seed' ).value );
	return Number.isInteger( s ) && s >= 0 ? s : settings.seed;
}

// Preview (Generate Billboards) shows the cloud with the cubes as their bounding boxes, as the
// manual's Billboards mode does; the cubes can still be clicked, and Cubes shows them again.
function preview() {
	previewOn = true;
	const id = doc.mode === 'texture' ? 'show-billboards' : 'show-particles';
	if ( ! $( id ).checked ) { $( id ).checked = true; $( id ).dispatchEvent( new Event( 'change' ) ); }
	if ( $( 'show-cubes' ).checked ) { $( 'show-cubes' ).checked = false; $( 'show-cubes' ).dispatchEvent( new Event( 'change' ) ); }
	requestFill();
}

$( 'preview' ).addEventListener( 'click', preview );
$( 'generate-billboards' ).addEventListener( 'click', preview );
$( 'seed' ).addEventListener( 'input', () => requestFill() );

// The sun: azimuth (degrees from +Z towards +X) and elevation; the server lights with it.
function sunAngles( v ) {
	const [ x, y, z ] = v, h = Math.hypot( x, z );
	return { azimuth: ( THREE.MathUtils.radToDeg( Math.atan2( x, z ) ) + 360 ) % 360, elevation: THREE.MathUtils.radToDeg( Math.atan2( y, h ) ) };
}

function showSun() {
	const v = new THREE.Vector3( ...( sun || settings.sun ) ).normalize();
	sunArrow.setDirection( v );
	const { azimuth, elevation } = sunAngles( v.toArray() );
	$( 'sun-azimuth' ).value = String( Math.round( azimuth ) );
	$( 'sun-elevation' ).value = String( Math.round( elevation ) );
	$( 'sun-text' ).textContent = `${ Math.round( azimuth ) }°, ${ Math.round( elevation ) }° up`;
	redraw();
}

for ( const id of [ 'sun-azimuth', 'sun-elevation' ] ) {
	$( id ).addEventListener( 'input', () => {
		const az = THREE.MathUtils.degToRad( Number( $( 'sun-azimuth' ).value ) );
		const el = THREE.MathUtils.degToRad( Number( $( 'sun-elevation' ).value ) );
		sun = [ Math.cos( el ) * Math.sin( az ), Math.sin( el ), Math.cos( el ) * Math.cos( az ) ].map( ( v ) => Math.round( v * 1e6 ) / 1e6 );
		if ( sun.every( ( v ) => v === 0 ) ) sun = [ 0, 1, 0 ];
		sunArrow.setDirection( new THREE.Vector3( ...sun ).normalize() );
		$( 'sun-text' ).textContent = `${ $( 'sun-azimuth' ).value }°, ${ $( 'sun-elevation' ).value }° up`;
		redraw();
		requestFill();
	} );
}

// -- totals, fill time, file state ---------------------------------------------------------------------
function showTotals() {
	const noun = doc.mode === 'texture' ? 'billboard' : 'particle';
	const n = total(), k = doc.cubes.length;
	$( 'totals' ).textContent = `${ n.toLocaleString( 'en' ) } ${ noun }${ n === 1 ? '' : 's' } in ${ k } cube${ k === 1 ? '' : 's' }`;
}

function showFill() {
	const f = state.fill;
	if ( f.ms === null ) { $( 'fill-time' ).textContent = 'not filled yet'; return; }
	const noun = previewMode === 'texture' ? 'billboards' : 'particles';
	$( 'fill-time' ).textContent = `${ f.particles.toLocaleString( 'en' ) } ${ noun } filled and lit in ${ Math.round( f.ms ).toLocaleString( 'en' ) } ms`
		+ ( f.latency !== null ? `, shown ${ f.latency } ms after the edit` : '' ) + ( f.note ? ` (${ f.note })` : '' );
}

function showFile() {
	const dirty = isDirty();
	$( 'unsaved' ).hidden = ! dirty;
	document.title = `${ dirty ? '● ' : '' }${ name || 'untitled' } · fishgen edit`;
	$( 'undo' ).disabled = ! undo.length;
	$( 'redo' ).disabled = ! redo.length;
	state.undoSteps = undo.length;
	state.redoSteps = redo.length;
}

function showLists() {
	$( 'file-list' ).replaceChildren( new Option( `${ files.length } cube file${ files.length === 1 ? '' : 's' }`, '' ),
		...files.map( ( f ) => new Option( f, f ) ) );
	showTextures();
}

$( 'file-list' ).addEventListener( 'change', () => {
	if ( $( 'file-list' ).value ) $( 'file-name' ).value = $( 'file-list' ).value;
} );

// Everything that follows a change of the document.
function changed() {
	version ++;
	changedAt.set( version, performance.now() );
	if ( changedAt.size > 1000 ) changedAt.delete( changedAt.keys().next().value );
	if ( selected >= doc.cubes.length ) selected = doc.cubes.length - 1;
	if ( doc.cubes.length && state.message === emptyNote ) say( '' );   // no longer an empty workspace
	showMode();
	syncCubes();
	showCube();
	showTotals();
	showFile();
	showPreview();
	requestFill();
}

// -- messages -----------------------------------------------------------------------------------------
function say( text, error = false, line = null ) {
	if ( noWebGL ) {   // every message keeps it: the empty workspace would otherwise go unexplained
		text = text ? `${ text }; ${ noWebGL }` : `the workspace cannot be drawn: ${ noWebGL }; the cubes can still be edited by their numbers and saved`;
		error = true;
	}
	state.message = text;
	$( 'message' ).textContent = text;
	$( 'message' ).className = error ? 'error' : '';
	if ( error && Number.isInteger( line ) && line >= 3 && line - 3 < doc.cubes.length ) select( line - 3 );   // the cube on that line
}

class ServerError extends Error {

	constructor( message, line, status = null ) {
		super( message );
		this.line = line;
		this.status = status;
	}

}

async function api( path, body, as = 'json' ) {
	let res;
	try {
		res = await fetch( path, {
			method: body === undefined ? 'GET' : 'POST', cache: 'no-store',
			headers: { 'X-Fishgen-Token': TOKEN, 'Content-Type': 'application/json' },
			body: body === undefined ? undefined : JSON.stringify( body ),
		} );
	} catch ( err ) {
		throw new ServerError( 'the editor\'s server does not answer (was fishgen edit stopped?)', null );
	}
	if ( ! res.ok ) {
		let answer = {};
		try { answer = await res.json(); } catch ( err ) { answer = { error: `${ res.status } ${ res.statusText }` }; }
		throw new ServerError( answer.error || `${ res.status } ${ res.statusText }`, answer.line, res.status );
	}
	return as === 'json' ? res.json() : res.arrayBuffer();
}

// -- File: Open and Save -------------------------------------------------------------------------------
function load( answer, fresh ) {
	doc.mode = answer.mode;
	doc.cubes = answer.cubes;
	name = answer.name;
	stamp = answer.stamp ?? null;
	files = answer.files;
	textures = answer.textures;
	selected = doc.cubes.length ? 0 : - 1;
	typedWrong.clear();
	conflicted = null;
	saved = answer.exists ? json() : JSON.stringify( { mode: doc.mode, cubes: [] } );
	undo.length = redo.length = 0;
	lastKey = null;
	$( 'file-name' ).value = name;
	$( 'folder' ).textContent = answer.folder || $( 'folder' ).textContent;
	if ( fresh ) resetView();
	showLists();
	changed();
	const notes = [ ...( answer.warnings || [] ) ];
	if ( ! answer.exists ) notes.push( `${ name } does not exist yet: an empty workspace; Save writes it` );
	say( notes.join( '; ' ) );
	emptyNote = answer.exists ? null : state.message;
}

async function openFile() {
	const wanted = $( 'file-name' ).value.trim();
	if ( ! wanted ) { say( 'File name: type the name of a .awn or .awa file in this folder', true ); return; }
	if ( isDirty() && ! confirm( `Discard the unsaved changes to ${ name }?` ) ) return;
	try {
		const answer = await api( '/api/open', { name: wanted } );
		load( answer, true );
		say( `opened ${ answer.name }` + ( answer.warnings.length ? '; ' + answer.warnings.join( '; ' ) : '' ) );
	} catch ( err ) {
		say( err.message, true );
	}
}

async function saveFile() {
	// a field still marked wrong holds a value the document does not: saving would say "saved" and
	// write the last good one (QA pass 22)
	const wrong = [ ...typedWrong ].find( ( [ input, cube ] ) => cube === current() && ! input.disabled );
	if ( wrong ) {
		say( `not saved: ${ wrong[ 0 ].labels[ 0 ].textContent } holds no valid value (${ JSON.stringify( wrong[ 0 ].value ) }); `
			+ 'correct it, or choose the cube again to drop the typing', true );
		fieldMessage = state.message;   // correcting the field clears it, as the field's own error
		wrong[ 0 ].focus();
		return;
	}
	let target = $( 'file-name' ).value.trim() || name;
	if ( ! /\.(awn|awa)$/i.test( target ) ) target += SUFFIX[ doc.mode ];
	// Another file of the folder is replaced only when asked (picking it in the list and pressing
	// Enter wrote over it without a word: QA pass 22), and so is a name a save was refused under
	// (made, changed or removed since: else each Save was refused again, for good). Any other name
	// goes with its stamp, so the server refuses it if the file changed under it.
	const other = target !== name, asked = target === conflicted || other && files.includes( target );
	const why = target === conflicted ? 'It changed on disk since this page last saw it.' : 'Its cubes are lost.';
	if ( asked && ! confirm( `Replace ${ target } with the cubes of ${ name || 'this page' }? ${ why }` ) ) {
		say( `not saved: ${ target } kept` );
		return;
	}
	const sent = json();
	try {
		const body = { name: target, mode: doc.mode, cubes: doc.cubes };
		if ( ! asked ) body.stamp = other ? null : stamp;   // refused (409) if made or changed since
		const answer = await api( '/api/save', body );
		saved = sent;
		stamp = answer.stamp;
		conflicted = null;
		name = answer.saved;
		files = answer.files;
		$( 'file-name' ).value = name;
		showLists();
		showFile();
		say( `saved ${ name }: ${ answer.particles.toLocaleString( 'en' ) } ${ doc.mode === 'texture' ? 'billboards' : 'particles' } in ${ answer.cubes } cubes` );
	} catch ( err ) {
		say( err.message, true, err.line );
		if ( err.status === 409 ) {   // the next Save under this name asks first
			conflicted = target;
			api( '/api/lists' ).then( ( answer ) => { files = answer.files; showLists(); }, () => {} );
		}
	}
}

$( 'open' ).addEventListener( 'click', openFile );
$( 'save' ).addEventListener( 'click', saveFile );
$( 'file-name' ).addEventListener( 'keydown', ( e ) => { if ( e.key === 'Enter' ) saveFile(); } );
window.addEventListener( 'beforeunload', ( e ) => {
	if ( isDirty() ) { e.preventDefault(); e.returnValue = ''; }
} );

// -- keys: Ctrl+Z, Ctrl+Shift+Z (or Ctrl+Y), Ctrl+D, Ctrl+S, Delete, W/R handles, arrows move ----------
window.addEventListener( 'keydown', ( e ) => {
	const t = e.target, typing = t instanceof HTMLInputElement && ( t.type === 'text' || t.type === 'search' ) || t instanceof HTMLTextAreaElement;
	const ctrl = e.ctrlKey || e.metaKey, key = e.key.toLowerCase();
	if ( ctrl && key === 's' ) { e.preventDefault(); saveFile(); return; }
	if ( ctrl && key === 'd' ) { e.preventDefault(); duplicate(); return; }
	if ( typing ) return;   // text boxes keep their own undo and keys
	if ( ctrl && ( key === 'z' && e.shiftKey || key === 'y' ) ) { e.preventDefault(); redoStep(); return; }
	if ( ctrl && key === 'z' ) { e.preventDefault(); undoStep(); return; }
	if ( t instanceof HTMLInputElement || t instanceof HTMLSelectElement || t instanceof HTMLButtonElement ) return;
	if ( key === 'delete' || key === 'backspace' ) { e.preventDefault(); deleteCube(); return; }
	if ( key === 'escape' ) { select( - 1 ); return; }
	if ( key === 'w' ) setHandles( 'translate' );
	if ( key === 'r' ) setHandles( 'scale' );
	const c = current();
	const move = { arrowleft: [ 0, - 1 ], arrowright: [ 0, 1 ], arrowup: [ 2, - 1 ], arrowdown: [ 2, 1 ], pageup: [ 1, 1 ], pagedown: [ 1, - 1 ] }[ key ];
	if ( c && move && t === canvas ) {
		e.preventDefault();
		// by the grid step, as the hint says; onto the grid when snapping
		const step = gridStep() || 0.1, snap = snapping();
		change( () => {
			const moved = current().centre[ move[ 0 ] ] + move[ 1 ] * step;
			current().centre[ move[ 0 ] ] = tidy( snap ? Math.round( moved / snap ) * snap : moved );
		} );
	}
} );

// -- start ----------------------------------------------------------------------------------------------
async function start() {
	try {
		const answer = await api( '/api/document' );
		settings = { seed: answer.seed, sun: answer.sun, limits: answer.limits };
		$( 'seed' ).value = String( answer.seed );
		showSun();
		applySnap();
		load( answer, true );
		state.ready = true;
		requestAnimationFrame( tick );
	} catch ( err ) {
		state.error = err.message;
		say( `could not open the file: ${ err.message }`, true );
	}
}

start();
