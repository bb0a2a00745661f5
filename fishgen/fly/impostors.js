// Dynamic impostors for fishgen fly (Harris 2002, "Real-Time Cloud Rendering for Games"; SkyWorks'
// SkyRenderableInstanceCloud, in FlightGear's simgear clouds3d): a cloud is drawn once into a
// texture and shown as one quad facing the eye it was drawn from, until the view of it changes.
//
// SkyWorks' rules, kept: the texture is fitted tightly to the bounding sphere from the eye; its side
// is 2 · screen height · radius / distance, rounded to a power of two, at most half the screen; it is
// redrawn when the angle between the near and far points of the sphere on the line it was drawn
// along, seen from the eye now, reaches the tolerance (so from anywhere on that line it stays valid),
// when the eye has passed the sphere's centre along it ("backwards"), or when it needs a finer
// texture; a cloud the eye is in is drawn directly. FlightGear's later rules: a budget of redraws a
// frame, the stalest first, and all of them when the sun changes.
//
// fishgen's own: the budget counts particles, not clouds (on a software renderer a redraw costs its
// particles, and one cloud can hold 50,000). A redraw bigger than what is left of the frame's budget
// is spread over the next frames: its particles are sorted back to front once, along the line from
// the eye to the cloud, and drawn in that order a slice a frame into a second texture ("over" is
// associative, so the slices add up to the picture drawn at once); the old picture is shown until
// the new one is whole. Clouds nearer than `near` radii, and clouds holding a mesh (their particles
// must be cut by its depth), are drawn directly, and so is a cloud with no picture to show yet.
const { THREE } = window.fishgenKit;   // fishgen/web/kit.js
const { PREMULTIPLIED } = window.fishgenKit.cloudlight;

const RELEASE_FRAMES = 30;   // a texture not shown for this many frames goes back to the pool
const DIRECT = 'direct', IMPOSTOR = 'impostor';
const _x = new THREE.Vector3(), _y = new THREE.Vector3();

export class Impostors {

	// `layer`: the clouds' layer; `draws`: the layer only the impostors' own copies of the clouds are
	// on (no other camera sees it). `twin( level )`: a copy of a level's drawable sharing its
	// attributes and material with an index of its own, and its sorter: {object, sorter, size, n}.
	// `sort( sorter, direction )` orders it back to front along a direction; `uniforms( viewportHeight,
	// fadeHeight )` sets the particles' pixel scale.
	constructor( renderer, scene, { angle = 0.125, budget = 5000, near = 1, layer, draws, twin, sort, uniforms } ) {
		Object.assign( this, { renderer, scene, layer, draws, budget, near, makeTwin: twin, onSort: sort, onUniforms: uniforms } );
		this.tolerance = THREE.MathUtils.degToRad( angle );
		this.pool = new Map();   // texture side -> free render targets
		this.quad = new THREE.PlaneGeometry( 2, 2 );
		this.material = new THREE.ShaderMaterial( {
			uniforms: { map: { value: null } }, transparent: true, depthTest: false, depthWrite: false, ...PREMULTIPLIED,
			vertexShader: 'varying vec2 vUv; void main() { vUv = uv; gl_Position = projectionMatrix * modelViewMatrix * vec4( position, 1.0 ); }',
			// the texture holds premultiplied, sRGB-encoded colour and coverage, as a cloud drawn directly writes them
			fragmentShader: 'uniform sampler2D map; varying vec2 vUv; void main() { gl_FragColor = texture2D( map, vUv ); }',
		} );
		this.sun = '';
		this.epoch = 0;   // pictures of an earlier epoch are never shown (a WebGL context lost since)
		this.frame = 0;
		this.stats = { redraws: 0, particles: 0, frames: 0, impostors: 0, direct: 0, textures: 0 };
		this.last = { redraws: 0, particles: 0, impostors: 0, direct: 0 };
	}

	setDepthTest( on ) { this.material.depthTest = on; }

	// Every picture is lost with its WebGL context: after a restore each cloud is drawn directly
	// until it is drawn into a picture again (the clouds stayed away for good: QA pass 22).
	forget() { this.epoch ++; }

	// The texture's side (log2) a cloud needs: SkyWorks' _GetRequiredLogResolution.
	logSize( distance, radius, width, height ) {
		const cap = Math.floor( Math.log2( Math.max( 2, Math.min( width, height ) ) ) ) - 1;
		const side = 2 * height * radius / Math.max( distance, 1e-6 );
		return Math.max( 1, Math.min( cap, side <= 2 ? 1 : Math.round( Math.log2( side ) ) ) );
	}

	// How far past its tolerance a picture is for the eye now (>= 1: due for a redraw; Infinity:
	// none, or one that must not be shown: made under another sun).
	staleness( u, picture, eye, log ) {
		if ( ! picture || picture.sun !== this.sun ) return Infinity;
		const finer = log > picture.log ? 1 + log - picture.log : 0;
		if ( picture.level !== u.level ) return Math.max( 2, finer );   // another level of detail than the one to show
		if ( eye.equals( picture.origin ) ) return finer;
		const x = _x.copy( picture.near ).sub( eye ), y = _y.copy( picture.far ).sub( eye );
		const lx = x.length(), ly = y.length();
		if ( lx > ly ) return 1e3;   // the eye has passed the centre along the line it was drawn from
		const cos = x.dot( y ) / Math.max( lx * ly, 1e-12 );
		return Math.max( ( cos < 1 ? Math.acos( cos ) : 0 ) / this.tolerance, finer );
	}

	// Choose how each visible unit is drawn this frame and go on with the stalest redraws, within
	// the budget. Units are fishgen fly's clouds: {levels, level, world (sphere), distance, visible,
	// holds, renderOrder}. `sun`: a key of the sun's uniforms; `camRadius`: the eye's own extent.
	plan( units, camera, width, height, sun, camRadius ) {
		this.frame ++;
		this.sun = `${ sun } ${ this.epoch }`;   // a picture made under another sun is never shown again
		const eye = camera.position, due = [];
		for ( const u of units ) {
			const p = u.impostor;
			const direct = ! u.visible || u.holds || u.distance - u.world.radius <= camRadius || u.distance < this.near * u.world.radius;
			if ( direct ) {
				u.mode = u.visible ? DIRECT : null;
				if ( p ) this.idle( p );
				continue;
			}
			const log = this.logSize( u.distance, u.world.radius, width, height );
			const age = p ? this.staleness( u, p.shown, eye, log ) : Infinity;
			u.mode = age === Infinity ? DIRECT : IMPOSTOR;
			u.age = age;
			// a redraw under way goes on unless it was started under another sun or for another level
			if ( p && p.next && ( p.next.sun !== this.sun || p.next.level !== u.level ) ) { this.release( p.next.target ); p.next = null; }
			if ( p && p.next ) due.push( [ Infinity, u, log ] );   // begun: finished first
			else if ( age >= 1 ) due.push( [ age, u, log ] );
		}
		due.sort( ( a, b ) => b[ 0 ] - a[ 0 ] );
		let left = this.budget, redraws = 0, particles = 0;
		for ( const [ , u, log ] of due ) {
			if ( left <= 0 ) break;
			const p = u.impostor || ( u.impostor = { shown: null, next: null, quad: null, seen: this.frame, twins: [], redraws: 0 } );
			if ( ! p.next ) this.begin( u, p, camera, log, height );
			const drawn = this.step( p, left );
			left -= drawn; particles += drawn;
			if ( p.next.done === p.next.n ) {
				this.finish( p );
				redraws ++;
				u.mode = IMPOSTOR;
				u.age = this.staleness( u, p.shown, eye, log );   // begun frames ago, it may be stale already
			}
		}
		let impostors = 0, direct = 0, error = 0;
		for ( const u of units ) {
			const p = u.impostor;
			if ( u.mode === IMPOSTOR ) {
				impostors ++;
				this.place( u, p );
				error += Math.min( u.age, 1e3 );
			} else if ( u.mode === DIRECT ) direct ++;
			if ( p && p.quad ) p.quad.visible = u.mode === IMPOSTOR;
		}
		// error: how stale the pictures shown are, the mean over them in units of the tolerance
		this.last = { redraws, particles, impostors, direct, error: impostors ? error / impostors : 0 };
		const s = this.stats;
		s.redraws += redraws; s.particles += particles; s.frames ++; s.impostors += impostors; s.direct += direct;
		return particles;
	}

	// A unit not shown as an impostor drops its redraw under way, and after a while its texture.
	idle( p ) {
		if ( p.quad ) p.quad.visible = false;
		if ( p.next ) { this.release( p.next.target ); p.next = null; }
		if ( p.shown && this.frame - p.seen > RELEASE_FRAMES ) { this.release( p.shown.target ); p.shown = null; }
	}

	acquire( side ) {
		const free = this.pool.get( side );
		if ( free && free.length ) return free.pop();
		this.stats.textures ++;
		return new THREE.WebGLRenderTarget( side, side, { depthBuffer: false, generateMipmaps: false } );   // linear filtering
	}

	release( target ) {
		if ( ! this.pool.has( target.width ) ) this.pool.set( target.width, [] );
		this.pool.get( target.width ).push( target );
	}

	// Drop every picture (tests and still frames: each is redrawn for the view now).
	dropAll( units ) {
		for ( const u of units ) {
			const p = u.impostor;
			if ( ! p ) continue;
			if ( p.next ) this.release( p.next.target );
			if ( p.shown ) this.release( p.shown.target );
			p.next = p.shown = null;
			if ( p.quad ) p.quad.visible = false;
		}
	}

	// Start a redraw of unit `u`'s current level into a texture of side 2^log, fitted to its bounding
	// sphere from the eye, with the eye's up (SkyWorks' TightlyFitToSphere): its camera, its order.
	begin( u, p, camera, log, bufferHeight ) {
		const centre = u.world.center, r = u.world.radius, d = u.distance, side = 1 << log;
		const half = Math.asin( Math.min( r / d, 0.999 ) ), cam = new THREE.PerspectiveCamera( THREE.MathUtils.radToDeg( 2 * half ), 1,
			Math.max( d - r, d * 1e-3 ), d + r );
		cam.layers.set( this.draws );
		cam.position.copy( camera.position );
		cam.up.set( 0, 1, 0 ).applyQuaternion( camera.quaternion );
		cam.lookAt( centre );
		cam.updateMatrixWorld();
		const axis = centre.clone().sub( camera.position ).normalize();
		if ( ! p.twins[ u.level ] ) p.twins[ u.level ] = this.makeTwin( u.levels[ u.level ] );
		const twin = p.twins[ u.level ];
		this.onSort( twin.sorter, axis );
		// a sprite fades by its share of the window (cloudlight's NEAR_FADE), not of this texture
		const tanHalf = Math.tan( THREE.MathUtils.degToRad( camera.fov / 2 ) );
		p.next = { target: this.acquire( side ), camera: cam, twin, n: twin.n, done: 0, log, level: u.level, sun: this.sun,
			origin: camera.position.clone(), near: camera.position.clone().addScaledVector( axis, cam.near ),
			far: camera.position.clone().addScaledVector( axis, cam.far ), quaternion: cam.quaternion.clone(),
			size: d * Math.tan( half ), centre: centre.clone(), side, fade: bufferHeight > 0 ? side * tanHalf / Math.tan( half ) : side };
		this.renderer.setRenderTarget( p.next.target );
		this.renderer.setClearColor( 0x000000, 0 );
		this.renderer.clear( true, false, false );
	}

	// Draw the next slice of a redraw, at most `most` particles, in back-to-front order: how many.
	step( p, most ) {
		const next = p.next, count = Math.min( next.n - next.done, Math.max( 1, most ) ), object = next.twin.object;
		object.geometry.setDrawRange( next.done * next.twin.size, count * next.twin.size );
		object.visible = true;   // alone: every other copy stays hidden
		this.onUniforms( next.side, next.fade );
		const renderer = this.renderer, background = this.scene.background;
		this.scene.background = null;
		renderer.setRenderTarget( next.target );
		renderer.render( this.scene, next.camera );
		this.scene.background = background;
		object.geometry.setDrawRange( 0, Infinity );
		object.visible = false;
		next.done += count;
		return count;
	}

	// A whole new picture: shown from now on, the old texture back to the pool.
	finish( p ) {
		if ( p.shown ) this.release( p.shown.target );
		p.shown = p.next;
		p.next = null;
		p.redraws ++;
		if ( ! p.quad ) {
			p.quad = new THREE.Mesh( this.quad, this.material.clone() );
			p.quad.frustumCulled = false;
			p.quad.layers.set( this.layer );
			this.scene.add( p.quad );
		}
		p.quad.material.uniforms.map.value = p.shown.target.texture;
	}

	// The quad where the picture was taken: at the sphere's centre, facing the eye it was drawn from,
	// the texture's half side there.
	place( u, p ) {
		const q = p.quad, shown = p.shown;
		q.position.copy( shown.centre );
		q.quaternion.copy( shown.quaternion );
		q.scale.set( shown.size, shown.size, 1 );
		q.renderOrder = u.renderOrder;
		p.seen = this.frame;
	}

}
