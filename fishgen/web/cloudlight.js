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
