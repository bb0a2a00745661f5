"""Off-screen OpenGL rendering of a preview ``Scene`` with moderngl.

The context is a headless EGL one; with no GPU, Mesa's llvmpipe rasterises on
the CPU. Shading mimics a glTF viewer: base colour (factor x texture x vertex
colour), alpha modes OPAQUE / MASK (cutoff) / BLEND (sorted, drawn after the
opaque pass without depth writes), double-sided materials lit on both faces,
and particles drawn as camera-facing soft discs of their world radius.
The framebuffer holds premultiplied alpha, so a transparent background works.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from fishgen.errors import FishgenError
from fishgen.geometry.mesh import vertex_normals
from fishgen.numeric import to_linear_float
from fishgen.preview.camera import Camera
from fishgen.scene.model import Material, Primitive, Scene
from fishgen.scene.pose import Pose, deformed, pose

SAMPLES = 4
# World-fixed lights: a sun from above and in front, a weak fill from behind, a
# sky/ground hemisphere - so the top of anything reads brighter than its belly.
SUN_DIR = np.array([0.35, 1.0, 0.55]) / np.linalg.norm([0.35, 1.0, 0.55])
FILL_DIR = np.array([-0.6, 0.1, -0.4]) / np.linalg.norm([-0.6, 0.1, -0.4])
PARTICLE_OPACITY = 0.55
POINT_SIZE_FRACTION = 0.004
"""Radius of particles that carry no ``_RADIUS``, as a fraction of the bounding-box diagonal."""
DEFAULT_MATERIAL = Material("default")

_SRGB = """
vec3 to_srgb(vec3 c) {
    c = clamp(c, 0.0, 1.0);
    return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
}
vec3 to_linear(vec3 c) {
    return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), step(0.04045, c));
}
"""

MESH_VS = """
#version 330
uniform mat4 u_model;
uniform mat3 u_normal_matrix;
uniform mat4 u_viewproj;
in vec3 in_pos; in vec3 in_normal; in vec2 in_uv; in vec4 in_color;
out vec3 v_world; out vec3 v_normal; out vec2 v_uv; out vec4 v_color;
void main() {
    vec4 world = u_model * vec4(in_pos, 1.0);
    v_world = world.xyz;
    v_normal = u_normal_matrix * in_normal;
    v_uv = in_uv;
    v_color = in_color;
    gl_Position = u_viewproj * world;
}
"""

MESH_FS = """
#version 330
uniform vec4 u_base;
uniform sampler2D u_tex;
uniform bool u_has_tex;
uniform int u_alpha_mode;   // 0 opaque, 1 mask, 2 blend
uniform float u_cutoff;
uniform bool u_unlit;
uniform vec3 u_eye, u_sun, u_fill;
in vec3 v_world; in vec3 v_normal; in vec2 v_uv; in vec4 v_color;
out vec4 f_color;
""" + _SRGB + """
void main() {
    vec4 base = u_base * v_color;
    if (u_has_tex) {
        vec4 t = texture(u_tex, v_uv);
        base *= vec4(to_linear(t.rgb), t.a);
    }
    if (u_alpha_mode == 1 && base.a < u_cutoff) discard;
    if (u_alpha_mode != 2) base.a = 1.0;
    vec3 color = base.rgb;
    if (!u_unlit) {
        vec3 n = normalize(v_normal);
        if (!gl_FrontFacing) n = -n;   // double-sided: the back face is lit as its own front
        vec3 v = normalize(u_eye - v_world);
        vec3 ambient = mix(vec3(0.16, 0.15, 0.14), vec3(0.50, 0.55, 0.62), 0.5 + 0.5 * n.y);
        float sun = max(dot(n, u_sun), 0.0);
        float fill = max(dot(n, u_fill), 0.0);
        float spec = pow(max(dot(n, normalize(u_sun + v)), 0.0), 48.0) * 0.18 * step(0.0, sun);
        color = base.rgb * (ambient + vec3(1.0, 0.97, 0.92) * 0.95 * sun + vec3(0.35, 0.42, 0.5) * fill)
              + vec3(spec);
    }
    f_color = vec4(to_srgb(color) * base.a, base.a);
}
"""

POINT_VS = """
#version 330
uniform mat4 u_view, u_proj;
in vec2 in_corner;
in vec3 in_center; in float in_radius; in vec4 in_color;
out vec2 v_corner; out vec4 v_color;
void main() {
    vec4 c = u_view * vec4(in_center, 1.0);
    c.xy += in_corner * in_radius;   // camera-facing quad of the particle's world radius
    v_corner = in_corner;
    v_color = in_color;
    gl_Position = u_proj * c;
}
"""

POINT_FS = """
#version 330
uniform vec3 u_sun_view;
uniform float u_opacity;
in vec2 v_corner; in vec4 v_color;
out vec4 f_color;
""" + _SRGB + """
void main() {
    float r2 = dot(v_corner, v_corner);
    if (r2 > 1.0) discard;
    // Shade the disc like a soft sphere so a cloud reads as puffs, not flat stickers.
    vec3 n = vec3(v_corner, sqrt(1.0 - r2));
    float light = 0.62 + 0.38 * dot(n, u_sun_view);
    float a = v_color.a * u_opacity * smoothstep(1.0, 0.35, sqrt(r2));
    f_color = vec4(to_srgb(v_color.rgb * light) * a, a);
}
"""


# moderngl objects are typed ``Any``: its bundled stubs lack ``Context.depth_mask`` and type a
# program's members as a union, of which only ``Uniform`` has the ``value`` / ``write`` used here.
@dataclass
class _GpuMesh:
    node: int
    prim: Primitive
    material: Material
    vbo: Any          # moderngl.Buffer
    vao: Any          # moderngl.VertexArray
    texture: Any      # moderngl.Texture or None
    centroid: np.ndarray
    deforms: bool            # skinned or morphed: positions re-posed on the CPU every frame


class Renderer:
    """One headless GL context and framebuffer, reused for every image of a run."""

    def __init__(self, width: int, height: int):
        import moderngl

        try:
            # the stubs type ``**settings`` as dicts; the backend is a string
            self.ctx: Any = moderngl.create_context(standalone=True, backend="egl")  # type: ignore[arg-type]
        except Exception as err:  # no libEGL / no Mesa driver on this machine
            raise FishgenError(
                "expected an OpenGL 3.3 context from EGL (Debian: apt-get install libegl1 "
                f"libgl1-mesa-dri), found none ({err})") from None
        self.width, self.height = width, height
        samples = min(SAMPLES, self.ctx.max_samples)
        try:
            self.msaa = self.ctx.framebuffer(
                color_attachments=[self.ctx.renderbuffer((width, height), 4, samples=samples)],
                depth_attachment=self.ctx.depth_renderbuffer((width, height), samples=samples))
            self.resolved = self.ctx.framebuffer(
                color_attachments=[self.ctx.renderbuffer((width, height), 4)])
        except moderngl.Error as err:  # out of memory: the driver leaves the framebuffer incomplete
            self.ctx.release()
            need = width * height * (4 + 4) * samples + width * height * 4
            raise FishgenError(f"expected memory for a {width}x{height} framebuffer ({need / 2**20:,.0f} MiB "
                               f"with {samples}x anti-aliasing), found the driver unable to make one "
                               f"({err}); use a smaller --size") from None
        self.mesh_prog: Any = self.ctx.program(vertex_shader=MESH_VS, fragment_shader=MESH_FS)
        self.point_prog: Any = self.ctx.program(vertex_shader=POINT_VS, fragment_shader=POINT_FS)
        corners = np.array([-1, -1, 1, -1, -1, 1, 1, 1], np.float32)
        self.corner_buf = self.ctx.buffer(corners.tobytes())
        self._uploaded: dict[int, list[_GpuMesh]] = {}
        self._textures: dict[tuple[int, int], Any] = {}

    # -- uploads -------------------------------------------------------------
    def _texture(self, scene: Scene, index: int) -> Any:
        import moderngl

        key = (id(scene), index)
        if key not in self._textures:
            try:
                img = np.ascontiguousarray(scene.images[index].rgba())
            except Exception as err:  # Pillow raises anything from OSError to SyntaxError
                source = scene.source  # a path string when the scene was read from a file
                raise FishgenError(f"expected a readable texture image, found {scene.images[index].name!r} "
                                   f"damaged ({type(err).__name__})",
                                   source if isinstance(source, str) else None) from None
            tex = self.ctx.texture((img.shape[1], img.shape[0]), 4, img.tobytes())
            tex.build_mipmaps()
            tex.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
            # No anisotropic filtering: llvmpipe's takes ~0.5 s a frame on fins seen edge-on in a tiny
            # image (a 32x32 front-view loop ran 31 s instead of 1 s); trilinear mipmaps suffice here.
            tex.anisotropy = 1.0
            self._textures[key] = tex
        return self._textures[key]

    def _upload(self, scene: Scene) -> list[_GpuMesh]:
        key = id(scene)
        if key in self._uploaded:
            return self._uploaded[key]
        out: list[_GpuMesh] = []
        for node, prim in scene.drawn():
            if (prim.mode != "TRIANGLES" or prim.indices is None or not prim.vertex_count
                    or not len(prim.indices)):
                continue
            material = scene.materials[prim.material] if prim.material is not None else DEFAULT_MATERIAL
            deforms = bool(prim.targets) or (scene.nodes[node].skin is not None
                                             and "JOINTS_0" in prim.attributes)
            data = self._vertex_data(prim, *self._local(prim))
            vbo = self.ctx.buffer(data.tobytes(), dynamic=deforms)
            ibo = self.ctx.buffer(np.asarray(prim.indices, np.uint32).tobytes())
            vao = self.ctx.vertex_array(self.mesh_prog, [(vbo, "3f 3f 2f 4f", "in_pos", "in_normal",
                                                          "in_uv", "in_color")], ibo)
            tex = self._texture(scene, material.texture) if material.texture is not None else None
            out.append(_GpuMesh(node, prim, material, vbo, vao, tex,
                                np.asarray(prim.positions, float).mean(0), deforms))
        self._uploaded[key] = out
        return out

    @staticmethod
    def _local(prim: Primitive) -> tuple[np.ndarray, np.ndarray]:
        pos = np.asarray(prim.positions, np.float32)
        nrm = prim.attributes.get("NORMAL")
        if nrm is None:
            nrm = vertex_normals(pos.astype(np.float64), np.asarray(prim.indices, np.int64))
        return pos, np.asarray(nrm, np.float32)

    @staticmethod
    def _vertex_data(prim: Primitive, positions: np.ndarray, normals: np.ndarray) -> np.ndarray:
        n = prim.vertex_count
        uvs = prim.attributes.get("TEXCOORD_0")
        uvs = np.zeros((n, 2), np.float32) if uvs is None else to_linear_float(uvs)[:, :2] \
            if np.asarray(uvs).dtype.kind in "iu" else np.asarray(uvs, np.float32)
        colors = prim.attributes.get("COLOR_0")
        colors = np.ones((n, 4), np.float32) if colors is None else to_linear_float(colors)
        return np.hstack([positions, normals, uvs, colors]).astype(np.float32)

    # -- drawing -------------------------------------------------------------
    def render(self, scene: Scene, camera: Camera, t: float | None,
               background: tuple[float, float, float, float], clip: str | None = None) -> np.ndarray:
        """Draw ``scene`` posed at ``t``; returns (H, W, 4) uint8 RGBA, straight alpha."""
        import moderngl

        ctx = self.ctx
        posed = pose(scene, t, clip)
        view, proj = camera.view(), camera.projection()
        viewproj = proj @ view
        self.msaa.use()
        r, g, b, a = background
        ctx.clear(r * a, g * a, b * a, a)  # premultiplied, like everything drawn
        ctx.enable(moderngl.DEPTH_TEST | moderngl.BLEND)
        ctx.blend_func = moderngl.ONE, moderngl.ONE_MINUS_SRC_ALPHA
        prog = self.mesh_prog
        prog["u_viewproj"].write(viewproj.T.astype("f4").tobytes())
        prog["u_eye"].value = tuple(camera.eye)
        prog["u_sun"].value = tuple(SUN_DIR)
        prog["u_fill"].value = tuple(FILL_DIR)

        meshes = self._upload(scene)
        models: dict[int, np.ndarray] = {}
        for m in meshes:
            if m.deforms:  # morph targets and skins are posed on the CPU, drawn in world space
                pos, nrm = deformed(scene, m.node, m.prim, posed)
                if nrm is None:
                    nrm = vertex_normals(pos, np.asarray(m.prim.indices, np.int64))
                data = self._vertex_data(m.prim, pos.astype(np.float32), nrm.astype(np.float32))
                m.vbo.write(data.tobytes())
                models[id(m)] = np.eye(4)
            else:
                models[id(m)] = posed.matrix(m.node)
        opaque = [m for m in meshes if m.material.alpha_mode != "BLEND"]
        blended = [m for m in meshes if m.material.alpha_mode == "BLEND"]

        def depth(m: _GpuMesh) -> float:
            c = view @ models[id(m)] @ np.append(m.centroid, 1.0)
            return float(c[2])  # more negative = farther

        ctx.depth_mask = True
        for m in opaque:
            self._draw_mesh(m, models[id(m)])
        ctx.depth_mask = False  # transparent fins must not hide what lies behind them
        for m in sorted(blended, key=depth):
            self._draw_mesh(m, models[id(m)])
        self._draw_points(scene, posed, view, proj)
        ctx.depth_mask = True

        ctx.copy_framebuffer(self.resolved, self.msaa)
        raw = self.resolved.read(components=4, alignment=1)
        img = np.frombuffer(raw, np.uint8).reshape(self.height, self.width, 4)[::-1]
        return unpremultiply(img)

    def _draw_mesh(self, m: _GpuMesh, model: np.ndarray) -> None:
        import moderngl

        prog, mat = self.mesh_prog, m.material
        prog["u_model"].write(model.T.astype("f4").tobytes())
        linear = model[:3, :3]
        normal = np.linalg.inv(linear).T if abs(np.linalg.det(linear)) > 1e-30 else np.eye(3)
        prog["u_normal_matrix"].write(normal.T.astype("f4").tobytes())
        prog["u_base"].value = tuple(mat.base_color)
        prog["u_alpha_mode"].value = {"OPAQUE": 0, "MASK": 1, "BLEND": 2}.get(mat.alpha_mode, 0)
        prog["u_cutoff"].value = 0.5 if mat.alpha_cutoff is None else mat.alpha_cutoff
        prog["u_unlit"].value = mat.unlit
        prog["u_has_tex"].value = m.texture is not None
        if m.texture is not None:
            m.texture.use(0)
            prog["u_tex"].value = 0
        if mat.double_sided:
            self.ctx.disable(moderngl.CULL_FACE)
        else:
            self.ctx.enable(moderngl.CULL_FACE)
        m.vao.render(moderngl.TRIANGLES)
        self.ctx.disable(moderngl.CULL_FACE)

    def _draw_points(self, scene: Scene, posed: Pose, view: np.ndarray, proj: np.ndarray) -> None:
        centers: list[np.ndarray] = []
        radii: list[np.ndarray] = []
        colors: list[np.ndarray] = []
        for node, prim in scene.drawn():
            if prim.mode != "POINTS" or not prim.vertex_count:
                continue
            c, r, col = particles(scene, node, prim, posed)
            centers.append(c)
            radii.append(r)
            colors.append(col)
        if not centers:
            return
        c = np.concatenate(centers).astype(np.float32)
        r = np.concatenate(radii).astype(np.float32)
        col = np.concatenate(colors).astype(np.float32)
        order = np.argsort((c @ view[2, :3]) + view[2, 3])  # back to front for "over" blending
        inst = np.hstack([c[order], r[order, None], col[order]]).astype(np.float32)
        buf = self.ctx.buffer(inst.tobytes())
        prog = self.point_prog
        prog["u_view"].write(view.T.astype("f4").tobytes())
        prog["u_proj"].write(proj.T.astype("f4").tobytes())
        prog["u_sun_view"].value = tuple(view[:3, :3] @ SUN_DIR)
        prog["u_opacity"].value = PARTICLE_OPACITY
        vao = self.ctx.vertex_array(prog, [(self.corner_buf, "2f", "in_corner"),
                                           (buf, "3f 1f 4f/i", "in_center", "in_radius", "in_color")])
        self.ctx.depth_mask = False
        import moderngl
        vao.render(moderngl.TRIANGLE_STRIP, instances=len(inst))
        vao.release()
        buf.release()

    def release(self) -> None:
        self.ctx.release()


def particles(scene: Scene, node: int, prim: Primitive,
              posed: Pose) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """World centres, world radii and linear RGBA of a point set: a soft disc per particle.

    ``_RADIUS`` sizes each particle (else a small fraction of the set's extent);
    ``_DENSITY`` (fishgen clouds) fades the thin edges.
    """
    centers, _ = deformed(scene, node, prim, posed)
    m = posed.matrix(node)
    a = prim.attributes
    if "_RADIUS" in a:
        radii = np.asarray(a["_RADIUS"], np.float32).ravel()
    else:
        span = np.ptp(prim.positions, axis=0) if prim.vertex_count else np.ones(3)
        radii = np.full(prim.vertex_count, POINT_SIZE_FRACTION * float(np.linalg.norm(span)), np.float32)
    radii = radii * float(np.cbrt(abs(np.linalg.det(m[:3, :3]))))
    rgba = (np.ones((prim.vertex_count, 4), np.float32) if "COLOR_0" not in a
            else to_linear_float(a["COLOR_0"]))
    material = scene.materials[prim.material] if prim.material is not None else DEFAULT_MATERIAL
    rgba = rgba * np.asarray(material.base_color, np.float32)
    if "_DENSITY" in a:
        rgba[:, 3] *= np.clip(np.asarray(a["_DENSITY"], np.float32).ravel(), 0, 1)
    return centers, radii, rgba


def unpremultiply(img: np.ndarray) -> np.ndarray:
    """Premultiplied RGBA8 to straight alpha (what PNG and WebP store)."""
    a = img[..., 3:4].astype(np.float32)
    if np.all(a == 255):
        return img.copy()
    rgb = np.where(a > 0, img[..., :3] * (255.0 / np.maximum(a, 1)), 0)
    return np.concatenate([np.clip(rgb + 0.5, 0, 255).astype(np.uint8), img[..., 3:4]], -1)
