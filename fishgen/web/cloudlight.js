// Harris's second pass, shared by the pages of fishgen view, edit and fly. The first pass (the
// sunlight reaching each particle) is baked into a fishgen cloud: each particle's `_LIGHT` and the
// scene's extras.fishgen_light. The shaders scatter that light towards the eye with the phase
// function, over the sky's ambient light.
import * as THREE from 'three';

export const SECOND_PASS = /* glsl */`
	uniform bool cloudLit;
	uniform vec3 cloudSun, sunColor, skyColor;
	uniform float albedo, g;
	float phase( float c ) {
		float g2 = g * g;
		return 1.5 * ( 1.0 - g2 ) / ( 2.0 + g2 ) * ( 1.0 + c * c ) / pow( 1.0 + g2 - 2.0 * g * c, 1.5 );
	}
	vec3 scattered( float light, vec3 world ) {
		float c = dot( cloudSun, normalize( world - cameraPosition ) );   // 1: looking towards the sun
		return albedo * ( skyColor + sunColor * light * phase( c ) );
	}`;

// One set per page: every cloud material spreads these into its uniforms, so one sun lights all.
export const cloudUniforms = {
	cloudLit: { value: false }, cloudSun: { value: new THREE.Vector3( 0, 1, 0 ) },
	sunColor: { value: new THREE.Vector3( 1, 1, 1 ) }, skyColor: { value: new THREE.Vector3() },
	albedo: { value: 1 }, g: { value: 0 },
};

// The scene's extras.fishgen_light into cloudUniforms: the unit sun, or null (and the uniforms
// untouched) when the extras hold none that is whole and finite.
export function readCloudLight( extras ) {
	const l = extras && extras.fishgen_light;
	const triple = ( v ) => Array.isArray( v ) && v.length === 3 && v.every( Number.isFinite );
	if ( ! l || ! triple( l.sun ) || ! triple( l.sun_color ) || ! triple( l.sky_color ) ) return null;
	if ( ! Number.isFinite( l.albedo ) || ! Number.isFinite( l.anisotropy ) || Math.abs( l.anisotropy ) > 0.9 ) return null;
	const sun = new THREE.Vector3( ...l.sun );
	if ( sun.lengthSq() === 0 ) return null;
	cloudUniforms.cloudLit.value = true;
	cloudUniforms.cloudSun.value.copy( sun.normalize() );
	cloudUniforms.sunColor.value.set( ...l.sun_color );
	cloudUniforms.skyColor.value.set( ...l.sky_color );
	cloudUniforms.albedo.value = l.albedo;
	cloudUniforms.g.value = l.anisotropy;
	return sun;
}

// fishgen fly's materials (`flying`) draw the clouds into their own buffer, smaller than the window
// and laid over the view (fishgen/fly/app.js), or on the view itself: they write colours
// sRGB-encoded and premultiplied, so that both give the same picture ("over" is associative), and
// test no depth unless the page turns `depthTest` on (fly does, to cut clouds by the meshes' depth).
// The buffer is laid over with the same blending.
export const PREMULTIPLIED = { blending: THREE.CustomBlending, blendSrc: THREE.OneFactor, blendDst: THREE.OneMinusSrcAlphaFactor,
	blendSrcAlpha: THREE.OneFactor, blendDstAlpha: THREE.OneMinusSrcAlphaFactor };
const FLYING = { depthTest: false, ...PREMULTIPLIED };

const ENCODE_SRGB = /* glsl */`
	#ifdef FLYING
	vec3 encodeSRGB( vec3 c ) {   // linear to the window's sRGB, as three's output conversion does it
		c = clamp( c, 0.0, 1.0 );
		return mix( pow( c, vec3( 0.41666 ) ) * 1.055 - vec3( 0.055 ), c * 12.92, vec3( lessThanEqual( c, vec3( 0.0031308 ) ) ) );
	}
	#endif`;

// The end of a fragment shader: linear colour `rgb` with alpha `a`, as the material's target takes it.
const OUTPUT = /* glsl */`
	#ifdef FLYING
		gl_FragColor = vec4( encodeSRGB( rgb ) * a, a );
	#else
		gl_FragColor = vec4( rgb, a );
		#include <colorspace_fragment>
	#endif`;

// Flying, a sprite taller than NEAR_FADE of the view fades out as the camera flies into it (its
// inside shows as a fog of smaller particles, not one particle filling the screen) and is not drawn
// at all at twice that, and it is drawn to SPRITE_CUT of its radius: the faint rim beyond, under 10 %
// of its opacity, would cost a third of the pixels.
const NEAR_FADE = 0.5, SPRITE_CUT = 0.8;

// A cloud's particles: each a soft disc of its world radius (`_radius`: fishgen's _RADIUS, a PLY's
// radius) with the billboard sprite's Gaussian profile, renormalised to reach 0 where it is cut, lit
// by the second pass where the file is lit, in its own colour where not. One a page: set
// `uniforms.viewportHeight` to the height of the buffer it is drawn into and, flying, `fadeHeight`
// to the pixels of that buffer the window's height stands for (they differ in an impostor's texture).
export function particleMaterial( { flying = false } = {} ) {
	const cut = flying ? SPRITE_CUT : 1, edge = Math.exp( - cut * cut / 0.32 );
	return new THREE.ShaderMaterial( {
		uniforms: { viewportHeight: { value: 1 }, fadeHeight: { value: 1 }, ...cloudUniforms },
		defines: flying ? { FLYING: 1 } : {},
		vertexColors: true, transparent: true, depthWrite: false, ...( flying ? FLYING : {} ),
		vertexShader: /* glsl */`
			attribute float _radius;
			attribute float _density;
			attribute float _light;
			uniform float viewportHeight, fadeHeight;
			varying vec3 vColor;
			varying float vAlpha;
			${ SECOND_PASS }
			void main() {
				vec4 world = modelMatrix * vec4( position, 1.0 );
				vec4 mv = viewMatrix * world;
				gl_Position = projectionMatrix * mv;
				float size = _radius * projectionMatrix[ 1 ][ 1 ] * viewportHeight / max( - mv.z, 1e-4 );   // diameter, pixels
				vColor = ( cloudLit && _light >= 0.0 ) ? scattered( _light, world.xyz ) : color;
				vAlpha = 0.7 * clamp( _density, 0.0, 1.0 );
			#ifdef FLYING
				float limit = ${ NEAR_FADE.toFixed( 3 ) } * fadeHeight;
				gl_PointSize = min( size, limit ) * ${ cut.toFixed( 3 ) };
				vAlpha *= clamp( 2.0 - size / limit, 0.0, 1.0 );
				if ( vAlpha <= 0.0 || - mv.z <= 0.0 ) gl_Position = vec4( 2.0, 2.0, 2.0, 1.0 );   // not rasterized at all
			#else
				gl_PointSize = size;
			#endif
			}`,
		fragmentShader: /* glsl */`
			varying vec3 vColor;
			varying float vAlpha;
			${ ENCODE_SRGB }
			void main() {
				vec2 p = ( gl_PointCoord * 2.0 - 1.0 ) * ${ cut.toFixed( 3 ) };
				float a = vAlpha * ( exp( - dot( p, p ) / 0.32 ) - ${ edge.toFixed( 6 ) } ) / ${ ( 1 - edge ).toFixed( 6 ) };
				if ( a <= 0.0 ) discard;
				vec3 rgb = vColor;
				${ OUTPUT }
			}`,
	} );
}

let white = null;   // made when first needed: a page that never draws billboards holds none

function whiteTexture() {
	if ( ! white ) {
		white = new THREE.DataTexture( new Uint8Array( [ 255, 255, 255, 255 ] ), 1, 1 );
		white.needsUpdate = true;
	}
	return white;
}

// A cloud's billboards (three crossed quads a particle, or a texture cloud's) in place of the
// material `source` the file gave them: the texture's colour and alpha times the vertex alpha, lit
// by the second pass where the file is lit. `textured` false draws plain quads instead (the
// editor's Show Texture off). The source stays in `userData.source`.
export function billboardMaterial( source, { textured = true, flying = false } = {} ) {
	const material = new THREE.ShaderMaterial( {
		uniforms: { map: { value: textured && source.map || whiteTexture() }, plain: { value: textured ? 0 : 1 }, ...cloudUniforms },
		defines: flying ? { FLYING: 1 } : {},
		vertexColors: true, transparent: true, depthWrite: false, side: THREE.DoubleSide, ...( flying ? FLYING : {} ),
		vertexShader: /* glsl */`
			attribute float _light;
			varying vec2 vUv;
			varying vec4 vColor;
			${ SECOND_PASS }
			void main() {
				vec4 world = modelMatrix * vec4( position, 1.0 );
				gl_Position = projectionMatrix * viewMatrix * world;
				vUv = uv;
				vColor = vec4( ( cloudLit && _light >= 0.0 ) ? scattered( _light, world.xyz ) : color.rgb, color.a );
			}`,
		fragmentShader: /* glsl */`
			uniform sampler2D map;
			uniform float plain;
			varying vec2 vUv;
			varying vec4 vColor;
			${ ENCODE_SRGB }
			void main() {
				vec4 t = texture2D( map, vUv );
				float a = plain > 0.5 ? 0.6 : vColor.a * t.a;
				vec3 rgb = vColor.rgb * t.rgb;
				${ OUTPUT }
			}`,
	} );
	material.userData.source = source;
	return material;
}
