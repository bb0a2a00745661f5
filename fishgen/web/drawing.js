// Drawing shared by the pages of fishgen view, edit and fly: the canvas's size, and transparent
// things (particles, billboards) drawn farthest first.
import * as THREE from 'three';

// The page's WebGL renderer on ``options.canvas``; where the browser gives no WebGL context (it is
// off, or no GPU and no software rasterizer), null, after ``said( text )`` with why and what to do:
// a page that threw here was left dead and silent (QA pass 22).
export function webglRenderer( options, said ) {
	try {
		return new THREE.WebGLRenderer( options );
	} catch ( error ) {
		said( `this page draws with WebGL, and the browser gave it none (${ error && error.message || error }): `
			+ 'turn on hardware acceleration (or WebGL) in the browser, or open the page in another one' );
		return null;
	}
}

// A renderer that draws nothing, for a page that has other work than drawing (the editor's cubes
// by their numbers) where the browser gave no WebGL context.
export function noRenderer( canvas ) {
	let ratio = 1;
	const gl = { readPixels() {}, RGBA: 0, UNSIGNED_BYTE: 0 };
	return {
		domElement: canvas, autoClear: true, info: { render: { calls: 0 } },
		setPixelRatio( r ) { ratio = r; }, getPixelRatio: () => ratio,
		setSize( w, h ) { canvas.width = Math.floor( w * ratio ); canvas.height = Math.floor( h * ratio ); },
		render() {}, setRenderTarget() {}, setClearColor() {}, clear() {}, getContext: () => gl,
	};
}

// The renderer and camera fitted to the canvas's size in the page; true when they changed.
export function fitCanvas( renderer, camera, canvas ) {
	const w = canvas.clientWidth, h = canvas.clientHeight, ratio = renderer.getPixelRatio();
	if ( canvas.width === Math.floor( w * ratio ) && canvas.height === Math.floor( h * ratio ) ) return false;
	renderer.setSize( w, h, false );
	camera.aspect = w / Math.max( h, 1 );
	camera.updateProjectionMatrix();
	return true;
}

// Each primitive's centroid (points: size 1, triangles: 3), xyz in a Float32Array, with the
// geometry's index (one made when it has none) and the primitives' count.
export function centroids( geometry, size ) {
	const pos = geometry.getAttribute( 'position' );
	const index = geometry.index ? geometry.index.array.slice() : Uint32Array.from( { length: pos.count }, ( _, i ) => i );
	const n = index.length / size, out = new Float32Array( n * 3 );
	for ( let k = 0; k < n; k ++ ) for ( let j = 0; j < size; j ++ ) {
		const v = index[ k * size + j ];
		out[ 3 * k ] += pos.getX( v ) / size;
		out[ 3 * k + 1 ] += pos.getY( v ) / size;
		out[ 3 * k + 2 ] += pos.getZ( v ) / size;
	}
	return { index, centroids: out, n };
}

// One object's primitives, re-ordered in its index farthest first along the view by sort( dir ).
export class DepthSorted {

	constructor( object, size ) {
		const g = object.geometry, { index, centroids: c, n } = centroids( g, size );
		if ( ! g.index ) g.setIndex( new THREE.BufferAttribute( index.slice(), 1 ) );
		Object.assign( this, { object, centroids: c, index, size, keys: new Float32Array( n ), order: new Uint32Array( n ) } );
	}

	sort( dir ) {
		const e = this.object.matrixWorld.elements, c = this.centroids, n = this.keys.length;
		for ( let k = 0; k < n; k ++ ) {
			const x = c[ 3 * k ], y = c[ 3 * k + 1 ], z = c[ 3 * k + 2 ];
			const wx = e[ 0 ] * x + e[ 4 ] * y + e[ 8 ] * z + e[ 12 ], wy = e[ 1 ] * x + e[ 5 ] * y + e[ 9 ] * z + e[ 13 ];
			const wz = e[ 2 ] * x + e[ 6 ] * y + e[ 10 ] * z + e[ 14 ];
			this.keys[ k ] = - ( wx * dir.x + wy * dir.y + wz * dir.z );   // farther: smaller key
			this.order[ k ] = k;
		}
		const keys = this.keys;
		this.order.sort( ( a, b ) => keys[ a ] - keys[ b ] );
		const out = this.object.geometry.index.array, size = this.size;
		for ( let k = 0; k < n; k ++ ) for ( let j = 0; j < size; j ++ ) out[ k * size + j ] = this.index[ this.order[ k ] * size + j ];
		this.object.geometry.index.needsUpdate = true;
	}

}
