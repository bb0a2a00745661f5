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

// A cloud's particles as fishgen view and edit draw them: each a soft disc of its world radius
// (`_radius`: fishgen's _RADIUS, a PLY's radius) with the billboard sprite's Gaussian profile, lit
// by the second pass where the file is lit, in its own colour where not. One a page: set
// `uniforms.viewportHeight` to the drawing buffer's height. (fishgen fly draws its own, faded near
// the eye and premultiplied for its half-size buffer.)
export function particleMaterial() {
	return new THREE.ShaderMaterial( {
		uniforms: { viewportHeight: { value: 1 }, ...cloudUniforms },
		vertexColors: true, transparent: true, depthWrite: false,
		vertexShader: /* glsl */`
			attribute float _radius;
			attribute float _density;
			attribute float _light;
			uniform float viewportHeight;
			varying vec3 vColor;
			varying float vAlpha;
			${ SECOND_PASS }
			void main() {
				vec4 world = modelMatrix * vec4( position, 1.0 );
				vec4 mv = viewMatrix * world;
				gl_Position = projectionMatrix * mv;
				gl_PointSize = 2.0 * _radius * projectionMatrix[ 1 ][ 1 ] * 0.5 * viewportHeight / max( - mv.z, 1e-4 );
				vColor = ( cloudLit && _light >= 0.0 ) ? scattered( _light, world.xyz ) : color;
				vAlpha = 0.7 * clamp( _density, 0.0, 1.0 );
			}`,
		fragmentShader: /* glsl */`
			varying vec3 vColor;
			varying float vAlpha;
			void main() {
				vec2 p = gl_PointCoord * 2.0 - 1.0;
				float r2 = dot( p, p );
				if ( r2 > 1.0 ) discard;
				float a = vAlpha * max( ( exp( - r2 / 0.32 ) - 0.04394 ) / 0.95606, 0.0 );
				gl_FragColor = vec4( vColor, a );
				#include <colorspace_fragment>
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
export function billboardMaterial( source, textured = true ) {
	const material = new THREE.ShaderMaterial( {
		uniforms: { map: { value: textured && source.map || whiteTexture() }, plain: { value: textured ? 0 : 1 }, ...cloudUniforms },
		vertexColors: true, transparent: true, depthWrite: false, side: THREE.DoubleSide,
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
			void main() {
				vec4 t = texture2D( map, vUv );
				float a = plain > 0.5 ? 0.6 : vColor.a * t.a;
				gl_FragColor = vec4( vColor.rgb * t.rgb, a );
				#include <colorspace_fragment>
			}`,
	} );
	material.userData.source = source;
	return material;
}
