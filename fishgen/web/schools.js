// A fishgen school (`fishgen school`: scene extras fishgen_school, one node per fish over its
// species' shared part meshes) drawn as one InstancedMesh per species and material, so a school of
// one species costs as many draw calls as one fish has materials (a body and its fins: two), not
// one per fish and part. Shared by fishgen view and fly.
//
// Each frame the fish's root tracks are sampled for all fish of a species at once (one key search
// per distinct key-times array, then a flat loop over typed arrays) into their matrices, and their
// body-wave weights likewise; the fins' swings, which fishgen keys in a few phases shared by many
// fish, are sampled once per phase. Just before a species is drawn, its fish in the camera's view
// are laid out nearest first in float textures (matrix, fin phase and tint a fish; three.js's
// per-instance morph texture for the weights) and the instanced meshes drawn with that many
// instances: culled and ordered as three.js culls and orders a node per fish, and uploaded when
// drawn. The vertex shader moves each vertex by its part's matrix for the fish's phase, then by
// the fish's. Anything that does not fit this layout (skins, levels of detail, other
// interpolations) stays as it was.
import * as THREE from 'three';
import { mergeGeometries } from 'three/addons/utils/BufferGeometryUtils.js';

// -- what the file holds ------------------------------------------------------------------------

// Each animated object's tracks by property, from the clips; GLTFLoader names a track
// "<unique object name>.<property>".
function tracksOf( root, clips ) {
	const byName = new Map();
	root.traverse( ( o ) => byName.set( o.name, o ) );
	const found = new Map();   // object -> { clip, position, quaternion, scale, morphTargetInfluences }
	for ( const clip of clips ) for ( const track of clip.tracks ) {
		const dot = track.name.lastIndexOf( '.' );
		const object = byName.get( track.name.slice( 0, dot ) );
		if ( ! object ) continue;
		const entry = found.get( object ) || { clips: new Set() };
		entry.clips.add( clip );
		entry[ track.name.slice( dot + 1 ) ] = track;
		found.set( object, entry );
	}
	return found;
}

const linear = ( track ) => ! track || track.getInterpolation() === THREE.InterpolateLinear;

function signature( material ) {   // a material's kind: fish whose parts differ only in colour share a drawing
	const m = material;
	return [ m.type, m.map && m.map.uuid, m.transparent, m.alphaTest, m.side, m.opacity, m.roughness, m.metalness,
		m.vertexColors, m.emissive && m.emissive.getHexString(), m.depthWrite, m.blending ].join( ',' );
}

const round = ( values ) => values.map( ( v ) => v.toFixed( 6 ) ).join( ',' );

// One fish as the instancer sees it, or null when it cannot be drawn as an instance: a node of
// plain mesh parts, every track linear, its parts moved only by rotation keys, one weights track
// (or none) for all its parts.
function fishOf( node, tracks ) {
	if ( node.isMesh || node.children.length === 0 ) return null;
	const own = tracks.get( node ) || { clips: new Set() };
	if ( own.scale || ! linear( own.position ) || ! linear( own.quaternion ) ) return null;
	const clips = new Set( own.clips );
	const parts = [];
	let weights = null, morphs = - 1;
	for ( const part of node.children ) {
		if ( ! part.isMesh || part.isSkinnedMesh || part.isInstancedMesh || part.children.length || Array.isArray( part.material ) ) return null;
		const t = tracks.get( part ) || { clips: new Set() };
		if ( t.position || t.scale || ! linear( t.quaternion ) || ! linear( t.morphTargetInfluences ) ) return null;
		for ( const c of t.clips ) clips.add( c );
		const count = ( part.geometry.morphAttributes.position || [] ).length;
		if ( morphs >= 0 && count !== morphs ) return null;
		morphs = count;
		const w = t.morphTargetInfluences || null;
		if ( parts.length && ( w ? w.values : null ) !== ( weights ? weights.values : null ) ) return null;
		if ( ! w && count && parts.length && round( part.morphTargetInfluences ) !== round( parts[ 0 ].mesh.morphTargetInfluences ) ) return null;
		weights = w;
		parts.push( { mesh: part, swing: t.quaternion || null } );
	}
	if ( clips.size > 1 ) return null;
	// parts that share a material share a drawing: which part's material each part wears
	const wears = parts.map( ( p ) => parts.findIndex( ( q ) => q.mesh.material === p.mesh.material ) );
	const key = [ wears.join( ',' ), ...parts.map( ( { mesh: m } ) => [ m.geometry.uuid, signature( m.material ),
		round( m.position.toArray() ), round( m.quaternion.toArray() ), round( m.scale.toArray() ),
		[ 'r', 'g', 'b' ].map( ( c ) => m.material.color[ c ] === 0 ).join( '' ) ].join( ';' ) ) ].join( '|' );
	return { node, key, parts, wears, clip: clips.size ? [ ...clips ][ 0 ] : null, position: own.position || null,
		quaternion: own.quaternion || null, weights, morphs: Math.max( morphs, 0 ) };
}

// -- the shader ---------------------------------------------------------------------------------

// fishgenParts: a row per fin phase, three texels a part: its matrix's rows (rest translation and
// scale, the swing's rotation). fishgenInstances: a row per drawn fish: its matrix's three rows,
// then for each of the species' materials (its tint, its fin phase). Seven fetches a vertex: on a
// software renderer each costs as much as the rest of the vertex's own work.
const PARS = `
uniform highp sampler2D fishgenParts;
uniform highp sampler2D fishgenInstances;
attribute float fishgenPart;
varying vec3 fishgenTint;
`;
const FETCH = ( slot ) => `
	vec4 fishgenFish0 = texelFetch( fishgenInstances, ivec2( 0, gl_InstanceID ), 0 );
	vec4 fishgenFish1 = texelFetch( fishgenInstances, ivec2( 1, gl_InstanceID ), 0 );
	vec4 fishgenFish2 = texelFetch( fishgenInstances, ivec2( 2, gl_InstanceID ), 0 );
	vec4 fishgenLook = texelFetch( fishgenInstances, ivec2( ${ 3 + slot }, gl_InstanceID ), 0 );
	fishgenTint = fishgenLook.rgb;
	ivec2 fishgenAt = ivec2( int( fishgenPart ) * 3, int( fishgenLook.w ) );
	vec4 fishgenPart0 = texelFetch( fishgenParts, fishgenAt, 0 );
	vec4 fishgenPart1 = texelFetch( fishgenParts, fishgenAt + ivec2( 1, 0 ), 0 );
	vec4 fishgenPart2 = texelFetch( fishgenParts, fishgenAt + ivec2( 2, 0 ), 0 );
`;
// normals as three.js turns an instance's: divided by the matrix's columns' squared lengths, then
// turned by it (right for any scale but shear), the part's matrix then the fish's
const NORMAL = `
	objectNormal /= fishgenPart0.xyz * fishgenPart0.xyz + fishgenPart1.xyz * fishgenPart1.xyz + fishgenPart2.xyz * fishgenPart2.xyz;
	objectNormal = vec3( dot( fishgenPart0.xyz, objectNormal ), dot( fishgenPart1.xyz, objectNormal ), dot( fishgenPart2.xyz, objectNormal ) );
	objectNormal /= fishgenFish0.xyz * fishgenFish0.xyz + fishgenFish1.xyz * fishgenFish1.xyz + fishgenFish2.xyz * fishgenFish2.xyz;
	objectNormal = vec3( dot( fishgenFish0.xyz, objectNormal ), dot( fishgenFish1.xyz, objectNormal ), dot( fishgenFish2.xyz, objectNormal ) );
`;
const POSITION = `
	transformed = vec3( dot( fishgenPart0, vec4( transformed, 1.0 ) ), dot( fishgenPart1, vec4( transformed, 1.0 ) ), dot( fishgenPart2, vec4( transformed, 1.0 ) ) );
	transformed = vec3( dot( fishgenFish0, vec4( transformed, 1.0 ) ), dot( fishgenFish1, vec4( transformed, 1.0 ) ), dot( fishgenFish2, vec4( transformed, 1.0 ) ) );
`;

function instancedMaterial( source, species, slot ) {
	const material = source.clone();
	material.onBeforeCompile = ( shader ) => {
		shader.uniforms.fishgenParts = { value: species.partTexture };
		shader.uniforms.fishgenInstances = { value: species.instanceTexture };
		shader.vertexShader = shader.vertexShader
			.replace( '#include <common>', '#include <common>\n' + PARS )
			.replace( '#include <beginnormal_vertex>', FETCH( slot ) + '#include <beginnormal_vertex>' )
			.replace( '#include <morphnormal_vertex>', '#include <morphnormal_vertex>\n' + NORMAL )
			.replace( '#include <morphtarget_vertex>', '#include <morphtarget_vertex>\n' + POSITION );
		shader.fragmentShader = shader.fragmentShader
			.replace( '#include <common>', '#include <common>\nvarying vec3 fishgenTint;' )
			.replace( '#include <color_fragment>', '#include <color_fragment>\n\tdiffuseColor.rgb *= fishgenTint;' );
	};
	material.customProgramCacheKey = () => `fishgen-school-${ slot }`;
	return material;
}

// -- sampling keyframes for many fish at once -------------------------------------------------------

// The key pair around t and the weight of the second, as three.js's linear interpolants take it.
function bracket( times, t, out ) {
	const n = times.length;
	if ( n === 1 || t <= times[ 0 ] ) { out[ 0 ] = out[ 1 ] = 0; out[ 2 ] = 0; return out; }
	if ( t >= times[ n - 1 ] ) { out[ 0 ] = out[ 1 ] = n - 1; out[ 2 ] = 0; return out; }
	let lo = 0, hi = n - 1;
	while ( hi - lo > 1 ) { const mid = ( lo + hi ) >> 1; if ( times[ mid ] <= t ) lo = mid; else hi = mid; }
	out[ 0 ] = lo; out[ 1 ] = hi; out[ 2 ] = ( t - times[ lo ] ) / ( times[ hi ] - times[ lo ] );
	return out;
}

// Fish grouped by their track's key times (fishgen shares one array per key spacing): the keys
// around t are searched once a group.
function byTimes( tracks ) {
	const groups = new Map();
	tracks.forEach( ( track, i ) => {
		if ( ! track ) return;
		if ( ! groups.has( track.times ) ) groups.set( track.times, [] );
		groups.get( track.times ).push( i );
	} );
	return [ ...groups ].map( ( [ times, fish ] ) => ( { times, fish: Int32Array.from( fish ) } ) );
}

// -- one species' drawing ---------------------------------------------------------------------------

const _m = new THREE.Matrix4(), _p = new THREE.Vector3(), _q = new THREE.Quaternion(), _s = new THREE.Vector3();
const _at = [ 0, 0, 0 ], _swing = [ 0, 0, 0, 0 ], _frustum = new THREE.Frustum(), _sphere = new THREE.Sphere();
const _view = new THREE.Matrix4(), _eye = new THREE.Vector3(), _look = new THREE.Vector3();
const WAVE_MARGIN = 1.25;   // a fish's bounding sphere, grown for the body wave and the fins' swing

class Species {

	constructor( fish, parent, bounds ) {
		const first = fish[ 0 ], n = fish.length, parts = first.parts.length;
		this.name = first.node.name.replace( /_\d+$/, '' );
		this.fish = fish;
		this.clip = first.clip;
		this.time = 0;
		this.version = 0;
		this.drawn = { key: null, count: 0 };
		// the fish's own rest pose and tracks, as flat arrays; `matrices` holds all fish's, posed
		this.restPosition = new Float32Array( n * 3 );
		this.restQuaternion = new Float32Array( n * 4 );
		this.scale = new Float32Array( n * 3 );
		fish.forEach( ( f, i ) => {
			f.node.position.toArray( this.restPosition, 3 * i );
			f.node.quaternion.toArray( this.restQuaternion, 4 * i );
			f.node.scale.toArray( this.scale, 3 * i );
		} );
		this.matrices = new Float32Array( n * 16 );
		this.positions = byTimes( fish.map( ( f ) => f.position ) );
		this.quaternions = byTimes( fish.map( ( f ) => f.quaternion ) );
		this.positionValues = fish.map( ( f ) => f.position && f.position.values );
		this.quaternionValues = fish.map( ( f ) => f.quaternion && f.quaternion.values );
		// the fin phases: fish with the same swing tracks share a row of part matrices
		const phases = new Map(), ids = new Map();
		const id = ( track ) => { if ( ! track ) return 0; if ( ! ids.has( track.values ) ) ids.set( track.values, ids.size + 1 ); return ids.get( track.values ); };
		this.phase = new Float32Array( n );
		fish.forEach( ( f, i ) => {
			const key = f.parts.map( ( p ) => id( p.swing ) ).join( ',' );
			if ( ! phases.has( key ) ) phases.set( key, { row: phases.size, swings: f.parts.map( ( p ) => p.swing ) } );
			this.phase[ i ] = phases.get( key ).row;
		} );
		this.phases = [ ...phases.values() ].map( ( p ) => p.swings );
		this.rest = first.parts.map( ( { mesh } ) => ( { position: mesh.position.clone(), quaternion: mesh.quaternion.clone(), scale: mesh.scale.clone() } ) );
		this.partTexture = new THREE.DataTexture( new Float32Array( parts * 3 * this.phases.length * 4 ), parts * 3, this.phases.length,
			THREE.RGBAFormat, THREE.FloatType );
		// the fish's bounds in its own frame, for culling
		this.sphere = new THREE.Sphere();
		first.parts.forEach( ( { mesh } ) => {
			if ( ! mesh.geometry.boundingSphere ) mesh.geometry.computeBoundingSphere();
			mesh.updateMatrix();
			const s = mesh.geometry.boundingSphere.clone().applyMatrix4( mesh.matrix );
			if ( this.sphere.isEmpty() ) this.sphere.copy( s ); else this.sphere.union( s );
		} );
		this.sphere.radius *= WAVE_MARGIN;
		// the body wave: one weights track a fish
		this.morphs = first.morphs;
		this.weights = byTimes( fish.map( ( f ) => f.weights ) );
		this.weightValues = fish.map( ( f ) => f.weights && f.weights.values );
		this.relative = first.parts[ 0 ].mesh.geometry.morphTargetsRelative;
		this.weightsNow = new Float32Array( ( this.morphs + 1 ) * n );
		fish.forEach( ( f, i ) => {
			const w = f.parts[ 0 ].mesh.morphTargetInfluences || [];
			this.weightsNow.set( w, i * ( this.morphs + 1 ) + 1 );
			this.weightsNow[ i * ( this.morphs + 1 ) ] = this.relative ? 1 : 1 - w.reduce( ( a, b ) => a + b, 0 );
		} );
		this.morphTexture = this.morphs ? new THREE.DataTexture( new Float32Array( ( this.morphs + 1 ) * n ), this.morphs + 1, n,
			THREE.RedFormat, THREE.FloatType ) : null;
		// one InstancedMesh a material of the first fish, its parts merged; each fish's tint per material
		const slots = [ ...new Set( first.wears ) ];
		this.width = 3 + slots.length;
		this.tints = slots.map( ( slot ) => colours( fish, slot, first.parts[ slot ].mesh.material ) );
		this.instanceTexture = new THREE.DataTexture( new Float32Array( this.width * n * 4 ), this.width, n, THREE.RGBAFormat, THREE.FloatType );
		this.order = new Int32Array( n );
		this.depth = new Float32Array( n );
		this.meshes = slots.map( ( slot, k ) => {
			const members = first.parts.map( ( _, j ) => j ).filter( ( j ) => first.wears[ j ] === slot );
			const geometry = merged( members.map( ( j ) => [ first.parts[ j ].mesh.geometry, j ] ) );
			if ( ! geometry ) throw new Error( 'parts of different layouts' );
			const source = first.parts[ slot ].mesh.material;
			// the instance matrices stay identity: each fish's is in fishgenInstances
			const mesh = new THREE.InstancedMesh( geometry, instancedMaterial( source, this, k ), n );
			mesh.name = `${ this.name } (${ n } instances, ${ source.name || 'material ' + slot })`;
			mesh.morphTexture = this.morphTexture;
			mesh.frustumCulled = false;   // culled fish by fish before it is drawn
			mesh.boundingBox = bounds.clone();
			mesh.boundingSphere = bounds.getBoundingSphere( new THREE.Sphere() );
			mesh.onBeforeRender = ( renderer, scene, camera ) => { mesh.count = this.layout( camera, mesh.matrixWorld ); };
			parent.add( mesh );
			return mesh;
		} );
		this.update( 0 );
	}

	// Pose every fish at the clip's time t (seconds).
	update( t ) {
		this.time = t;
		this.version ++;
		this.updateMatrices( t );
		this.updateParts( t );
		if ( this.morphs ) this.updateWeights( t );
	}

	updateMatrices( t ) {
		const out = this.matrices, n = this.fish.length;
		const position = new Float32Array( this.restPosition ), quaternion = new Float32Array( this.restQuaternion );
		for ( const { times, fish } of this.positions ) {
			const [ a, b, w ] = bracket( times, t, _at );
			for ( const i of fish ) {
				const v = this.positionValues[ i ];
				for ( let c = 0; c < 3; c ++ ) position[ 3 * i + c ] = v[ 3 * a + c ] * ( 1 - w ) + v[ 3 * b + c ] * w;
			}
		}
		for ( const { times, fish } of this.quaternions ) {
			const [ a, b, w ] = bracket( times, t, _at );
			for ( const i of fish ) {
				const v = this.quaternionValues[ i ];
				THREE.Quaternion.slerpFlat( quaternion, 4 * i, v, 4 * a, v, 4 * b, w );
			}
		}
		for ( let i = 0; i < n; i ++ ) {
			_p.fromArray( position, 3 * i ); _q.fromArray( quaternion, 4 * i ); _s.fromArray( this.scale, 3 * i );
			_m.compose( _p, _q, _s ).toArray( out, 16 * i );
		}
	}

	updateParts( t ) {
		const data = this.partTexture.image.data, width = this.rest.length * 3;
		this.phases.forEach( ( swings, row ) => swings.forEach( ( swing, k ) => {
			const rest = this.rest[ k ];
			_q.copy( rest.quaternion );
			if ( swing ) {
				const [ a, b, w ] = bracket( swing.times, t, _at );
				THREE.Quaternion.slerpFlat( _swing, 0, swing.values, 4 * a, swing.values, 4 * b, w );
				_q.fromArray( _swing );
			}
			const e = _m.compose( rest.position, _q, rest.scale ).elements, at = ( row * width + 3 * k ) * 4;
			for ( let r = 0; r < 3; r ++ ) for ( let c = 0; c < 4; c ++ ) data[ at + 4 * r + c ] = e[ 4 * c + r ];
		} ) );
		this.partTexture.needsUpdate = true;
	}

	updateWeights( t ) {
		const data = this.weightsNow, m = this.morphs, stride = m + 1;
		for ( const { times, fish } of this.weights ) {
			const [ a, b, w ] = bracket( times, t, _at );
			for ( const i of fish ) {
				const v = this.weightValues[ i ];
				let sum = 0;
				for ( let c = 0; c < m; c ++ ) {
					const x = v[ m * a + c ] * ( 1 - w ) + v[ m * b + c ] * w;
					data[ stride * i + 1 + c ] = x;
					sum += x;
				}
				data[ stride * i ] = this.relative ? 1 : 1 - sum;
			}
		}
	}

	// The fish in the camera's view laid out nearest first for drawing (their matrices, phases,
	// tints and weights); how many. Done once for both materials' meshes and again only when the
	// fish or the view moved.
	layout( camera, world ) {
		const key = `${ this.version } ${ camera.uuid } ${ camera.projectionMatrix.elements.join( ',' ) } ${ camera.matrixWorld.elements.join( ',' ) } ${ world.elements.join( ',' ) }`;
		if ( this.drawn.key === key ) return this.drawn.count;
		_view.multiplyMatrices( camera.projectionMatrix, camera.matrixWorldInverse );
		_frustum.setFromProjectionMatrix( _view.multiply( world ) );   // in the school's frame
		camera.getWorldPosition( _eye ).applyMatrix4( _m.copy( world ).invert() );
		camera.getWorldDirection( _look ).transformDirection( _m.copy( world ).invert() );
		const n = this.fish.length, e = this.matrices;
		let count = 0;
		for ( let i = 0; i < n; i ++ ) {
			const o = 16 * i;
			_sphere.center.copy( this.sphere.center ).applyMatrix4( _m.fromArray( e, o ) );
			_sphere.radius = this.sphere.radius * _m.getMaxScaleOnAxis();
			if ( ! _frustum.intersectsSphere( _sphere ) ) continue;
			this.depth[ i ] = _sphere.center.sub( _eye ).dot( _look );
			this.order[ count ++ ] = i;
		}
		const depth = this.depth, order = this.order.subarray( 0, count ).sort( ( a, b ) => depth[ a ] - depth[ b ] );
		const data = this.instanceTexture.image.data, width = this.width;
		const weights = this.weightsNow, stride = this.morphs + 1, morph = this.morphTexture && this.morphTexture.image.data;
		for ( let k = 0; k < count; k ++ ) {
			const i = order[ k ], o = 16 * i, at = 4 * width * k;
			for ( let r = 0; r < 3; r ++ ) for ( let c = 0; c < 4; c ++ ) data[ at + 4 * r + c ] = e[ o + 4 * c + r ];
			this.tints.forEach( ( tint, s ) => {
				data.set( tint.subarray( 3 * i, 3 * i + 3 ), at + 12 + 4 * s );
				data[ at + 15 + 4 * s ] = this.phase[ i ];
			} );
			if ( morph ) morph.set( weights.subarray( stride * i, stride * i + stride ), stride * k );
		}
		this.instanceTexture.needsUpdate = true;
		if ( this.morphTexture ) this.morphTexture.needsUpdate = true;
		this.drawn = { key, count };
		return count;
	}

}

// The parts' geometries as one, each vertex knowing its part (the row of its matrix); null when
// they cannot be merged (different attributes or morph targets).
function merged( geometries ) {
	const layout = ( g ) => [ g.index !== null, ...Object.keys( g.attributes ).sort().map( ( k ) => k + g.attributes[ k ].itemSize ),
		...Object.keys( g.morphAttributes ).sort().map( ( k ) => k + g.morphAttributes[ k ].length ), g.morphTargetsRelative ].join( ',' );
	if ( new Set( geometries.map( ( [ g ] ) => layout( g ) ) ).size !== 1 ) return null;
	const parts = geometries.map( ( [ g, k ] ) => {
		const copy = g.clone();
		copy.setAttribute( 'fishgenPart', new THREE.BufferAttribute( new Float32Array( g.getAttribute( 'position' ).count ).fill( k ), 1 ) );
		return copy;
	} );
	return mergeGeometries( parts );
}

// Each fish's colour over the first fish's, for one material (a tinted variant), rgb a fish.
function colours( fish, slot, source ) {
	const out = new Float32Array( fish.length * 3 ).fill( 1 ), base = source.color.toArray();
	fish.forEach( ( f, i ) => {
		const c = f.parts[ slot ].mesh.material.color.toArray();
		for ( let k = 0; k < 3; k ++ ) out[ 3 * i + k ] = base[ k ] === 0 ? 1 : c[ k ] / base[ k ];
	} );
	return out;
}

const MAX_INSTANCES = 8192;
// A species' fish are rows of float textures (and of three.js's morph texture): WebGL2 promises
// textures of 2,048 rows, every browser here gives 8,192 or more; more fish stay node by node.

// -- the page's entry ---------------------------------------------------------------------------------

// Draw the schools under root (a loaded glTF scene) instanced: each species' fish nodes are taken
// out and one InstancedMesh a material put in their place. Returns the clips without the taken
// fish's tracks (for the page's AnimationMixer), `follow( mixer )` to pose the instances at their
// clip's time after the mixer moved, and what was instanced. With enabled false, or for anything
// but a fishgen school, nothing changes.
export function instanceSchools( root, clips, enabled = true ) {
	const none = { clips, species: [], follow() {}, info: { species: 0, fish: 0, meshes: 0 } };
	if ( ! enabled || ! root.userData || ! root.userData.fishgen_school ) return none;
	const tracks = tracksOf( root, clips );
	const groups = new Map();
	for ( const node of [ ...root.children ] ) {
		const fish = fishOf( node, tracks );
		if ( ! fish ) continue;
		if ( ! groups.has( fish.key ) ) groups.set( fish.key, [] );
		groups.get( fish.key ).push( fish );
	}
	const species = [];
	const taken = new Set();
	root.updateMatrixWorld( true );
	const toRoot = root.matrixWorld.clone().invert();
	for ( const fish of groups.values() ) {
		if ( fish.length > MAX_INSTANCES ) continue;
		// the fish's bounds as drawn node by node, for pages that frame the view on them
		const bounds = new THREE.Box3();
		for ( const f of fish ) bounds.union( new THREE.Box3().setFromObject( f.node ).applyMatrix4( toRoot ) );
		let drawn;
		try {
			drawn = new Species( fish, root, bounds );
		} catch ( err ) {   // a species whose parts cannot be merged is drawn fish by fish
			continue;
		}
		species.push( drawn );
		for ( const f of fish ) {
			root.remove( f.node );
			taken.add( f.node );
			for ( const p of f.parts ) taken.add( p.mesh );
		}
	}
	if ( ! species.length ) return none;
	const names = new Set( [ ...taken ].map( ( o ) => o.name ) );
	const kept = clips.map( ( clip ) => {
		const left = clip.tracks.filter( ( t ) => ! names.has( t.name.slice( 0, t.name.lastIndexOf( '.' ) ) ) );
		const out = new THREE.AnimationClip( clip.name, clip.duration, left );
		species.forEach( ( s ) => { if ( s.clip === clip ) s.clip = out; } );
		return out;
	} );
	return {
		clips: kept, species,
		// after mixer.update or setTime: each species at its clip's action's time (rest when it does not play)
		follow( mixer ) {
			for ( const s of species ) {
				const action = s.clip && mixer.existingAction( s.clip );
				s.update( action && action.isRunning() ? action.time : 0 );
			}
		},
		info: { species: species.length, fish: species.reduce( ( a, s ) => a + s.fish.length, 0 ),
			meshes: species.reduce( ( a, s ) => a + s.meshes.length, 0 ) },
	};
}

// For tests: each instanced species' fish names and their positions (x, y, z per fish) as drawn.
export function instancePositions( drawing ) {
	return drawing.species.map( ( s ) => {
		const e = s.matrices;
		return { species: s.name, fish: s.fish.map( ( f ) => f.node.name ),
			positions: s.fish.map( ( _, i ) => [ e[ 16 * i + 12 ], e[ 16 * i + 13 ], e[ 16 * i + 14 ] ] ) };
	} );
}
