// The editor's preview: a filled, lit cloud as `fishgen clouds` writes it (a GLB from the server's
// /api/fill), drawn as fishgen's viewer draws it. The first pass of Harris's method (the sunlight
// reaching each particle, `_LIGHT`) is baked by the server; the materials of fishgen/web/cloudlight.js
// (fishgen view's too) do the second pass: the light scattered towards the eye by the phase
// function, over the sky's ambient light.
const { THREE, GLTFLoader, cloudlight, drawing } = window.fishgenKit;   // fishgen/web/kit.js
const { billboardMaterial, cloudUniforms, particleMaterial: makeParticleMaterial, readCloudLight } = cloudlight;

export { cloudUniforms };

// Particles and billboards as fishgen fly draws them into its cloud buffer (fishgen/web/cloudlight.js:
// premultiplied, for the editor's own half-size buffer, fishgen/editor/app.js), farthest first
// (fishgen/web/drawing.js).
const particleMaterial = makeParticleMaterial( { flying: true } );

const TEXTURE_MATERIAL = 'cloud texture ';

export class CloudView {

	constructor( scene ) {
		this.group = new THREE.Group();
		this.group.name = 'preview';
		scene.add( this.group );
		this.sorted = [];
		this.points = null;
		this.billboards = [];
		this.textured = true;
		this.loader = new GLTFLoader();
	}

	// The height in pixels of the buffer the cloud is drawn into. No sprite fades however near it is
	// (fly's fade is for flying into a cloud; here the camera looks at it).
	setViewport( height ) {
		particleMaterial.uniforms.viewportHeight.value = height;
		particleMaterial.uniforms.fadeHeight.value = 1e9;
	}

	// Show the GLB `glb` (an ArrayBuffer) in place of the last one.
	async show( glb ) {
		const gltf = await this.loader.parseAsync( glb, '' );
		this.clear();
		readCloudLight( gltf.scene.userData );
		gltf.scene.updateMatrixWorld( true );
		gltf.scene.traverse( ( o ) => {
			if ( o.isPoints ) {
				o.material = particleMaterial;
				o.frustumCulled = false;
				this.points = o;
				this.sorted.push( new drawing.DepthSorted( o, 1 ) );
			} else if ( o.isMesh ) {
				o.material = billboardMaterial( o.material, { textured: this.textured, flying: true } );
				o.frustumCulled = false;
				this.billboards.push( o );
				this.sorted.push( new drawing.DepthSorted( o, 3 ) );
			}
		} );
		this.group.add( gltf.scene );
	}

	setTextured( on ) {
		this.textured = on;
		for ( const mesh of this.billboards ) {
			const old = mesh.material;
			mesh.material = billboardMaterial( old.userData.source, { textured: on, flying: true } );
			old.dispose();
		}
	}

	sort( camera ) {
		const dir = camera.getWorldDirection( new THREE.Vector3() );
		for ( const s of this.sorted ) s.sort( dir );
	}

	clear() {
		for ( const child of [ ...this.group.children ] ) {
			child.traverse( ( o ) => {
				if ( o.geometry ) o.geometry.dispose();
				if ( o.material && o.material !== particleMaterial ) {
					const source = o.material.userData && o.material.userData.source;
					if ( source && source.map ) source.map.dispose();
					o.material.dispose();
				}
			} );
			this.group.remove( child );
		}
		this.sorted = [];
		this.points = null;
		this.billboards = [];
	}

	// What is shown, for people and tests: positions, linear colours and light of the particles
	// (as the file holds them), or the billboards' meshes by texture.
	particles() {
		if ( ! this.points ) return null;
		const g = this.points.geometry, n = g.getAttribute( 'position' ).count;
		const read = ( name, size ) => {
			const a = g.getAttribute( name );
			if ( ! a ) return null;
			const out = new Array( n * size );
			for ( let i = 0; i < n; i ++ ) for ( let j = 0; j < size; j ++ ) out[ i * size + j ] = a.getComponent( i, j );
			return out;
		};
		return { count: n, position: read( 'position', 3 ), color: read( 'color', 3 ), light: read( '_light', 1 ),
			radius: read( '_radius', 1 ), density: read( '_density', 1 ) };
	}

	billboardMeshes() {
		return this.billboards.map( ( m ) => {
			const source = m.material.userData.source;
			const name = source && source.name && source.name.startsWith( TEXTURE_MATERIAL ) ? source.name.slice( TEXTURE_MATERIAL.length ) : null;
			return { texture: name, vertices: m.geometry.getAttribute( 'position' ).count, billboards: m.geometry.getAttribute( 'position' ).count / 12,
				textured: m.material.uniforms.plain.value === 0 };
		} );
	}

}
