"""Off-screen OpenGL rendering of a preview ``Scene`` with moderngl.

The context is a headless EGL one; with no GPU, Mesa's llvmpipe rasterises on
the CPU. Shading mimics a glTF viewer: base colour (factor x texture x vertex
colour), alpha modes OPAQUE / MASK (cutoff) / BLEND (sorted, drawn after the
opaque pass without depth writes), double-sided materials lit on both faces,
and particles drawn as camera-facing soft discs of their world radius, with
the billboard sprite's Gaussian profile. Transparent parts (BLEND meshes,
their triangles, particles) are drawn farthest first without depth writes, as
three.js blends them. A fishgen cloud's particles get Harris's second pass
from the sunlight baked into the file (``_LIGHT`` and the scene's extras).
The framebuffer holds premultiplied alpha, so a transparent background works.
"""
from __future__ import annotations

import ctypes
import functools
import numbers
import os
import threading
import weakref
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any, TypeVar, cast

import numpy as np

from fishgen.clouds.lighting import Lighting, from_extras
from fishgen.errors import FishgenError, SystemFailure
from fishgen.geometry.mesh import vertex_normals
from fishgen.numeric import to_linear_float
from fishgen.preview.camera import Camera
from fishgen.preview.posing import Batch, Poser, poser_for
from fishgen.scene.model import Material, Primitive, Scene
from fishgen.scene.pose import Pose, deformed

SAMPLES = 4
# World-fixed lights: a sun from above and in front, a weak fill from behind, a
# sky/ground hemisphere - so the top of anything reads brighter than its belly.
SUN_DIR = np.array([0.35, 1.0, 0.55]) / np.linalg.norm([0.35, 1.0, 0.55])
FILL_DIR = np.array([-0.6, 0.1, -0.4]) / np.linalg.norm([-0.6, 0.1, -0.4])
PARTICLE_OPACITY = 0.7
"""A particle's opacity at its centre, times its density, fading out with the billboard sprite's
Gaussian: about as opaque as one of fishgen's billboard particles, whose one to three quads of
opacity 0.5 overlap depending on the side it is seen from."""
POINT_SIZE_FRACTION = 0.004
"""Radius of particles that carry no ``_RADIUS``, as a fraction of the bounding-box diagonal."""
DEFAULT_MATERIAL = Material("default")
_IDENTITY4 = np.eye(4, dtype="f4").tobytes()
_IDENTITY3 = np.eye(3, dtype="f4").tobytes()

_SRGB = """
vec3 to_srgb(vec3 c) {
    c = clamp(c, 0.0, 1.0);
    return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
}
vec3 to_linear(vec3 c) {
    return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), step(0.04045, c));
}
"""

# Harris's second pass (report eq. 3.13): a cloud particle scatters the sunlight that reached it
# (``light``, the first pass baked into the file) towards the eye by the phase function, on top
# of the sky's ambient light. ``u_cloud`` is 0 when the scene carries no fishgen lighting.
_SECOND_PASS = """
uniform bool u_cloud;
uniform vec3 u_cloud_sun, u_sun_color, u_sky_color;
uniform float u_albedo, u_g;
float phase(float c) {   // Cornette-Shanks; g = 0 is Rayleigh's 3/4 (1 + c^2)
    float g2 = u_g * u_g;
    return 1.5 * (1.0 - g2) / (2.0 + g2) * (1.0 + c * c) / pow(1.0 + g2 - 2.0 * u_g * c, 1.5);
}
vec3 scattered(float light, vec3 world, vec3 eye) {
    float c = dot(u_cloud_sun, normalize(world - eye));   // 1: looking towards the sun
    return u_albedo * (u_sky_color + u_sun_color * light * phase(c));
}
"""

MESH_VS = """
#version 330
uniform mat4 u_model;
uniform mat3 u_normal_matrix;
uniform mat4 u_viewproj;
in vec3 in_pos; in vec3 in_normal; in vec2 in_uv; in vec4 in_color; in float in_light;
out vec3 v_world; out vec3 v_normal; out vec2 v_uv; out vec4 v_color; out float v_light;
void main() {
    vec4 world = u_model * vec4(in_pos, 1.0);
    v_world = world.xyz;
    v_normal = u_normal_matrix * in_normal;
    v_uv = in_uv;
    v_color = in_color;
    v_light = in_light;
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
in vec3 v_world; in vec3 v_normal; in vec2 v_uv; in vec4 v_color; in float v_light;
out vec4 f_color;
""" + _SRGB + _SECOND_PASS + """
void main() {
    vec4 base = u_base * v_color;
    if (u_cloud && v_light >= 0.0) base.rgb = u_base.rgb * scattered(v_light, v_world, u_eye);
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
uniform vec3 u_eye;
in vec2 in_corner;
in vec3 in_center; in float in_radius; in vec4 in_color; in float in_light; in float in_stack;
out vec2 v_corner; out vec4 v_color; out float v_stack;
""" + _SECOND_PASS + """
void main() {
    vec4 c = u_view * vec4(in_center, 1.0);
    c.xy += in_corner * in_radius;   // camera-facing quad of the particle's world radius
    v_corner = in_corner;
    v_color = in_color;
    v_stack = in_stack;
    if (u_cloud && in_light >= 0.0) v_color.rgb = scattered(in_light, in_center, u_eye);
    gl_Position = u_proj * c;
}
"""

POINT_FS = """
#version 330
uniform float u_opacity;
in vec2 v_corner; in vec4 v_color; in float v_stack;
out vec4 f_color;
""" + _SRGB + """
void main() {
    // The billboard sprite's profile (fishgen.clouds.sprite): a Gaussian of sigma 0.4, 0 at the rim.
    float r2 = dot(v_corner, v_corner);
    if (r2 > 1.0) discard;
    float a = v_color.a * u_opacity * max((exp(-r2 / 0.32) - 0.04394) / 0.95606, 0.0);
    // a density past 1 counts stacked sprites (a preview's merged particles): as opaque as that many
    // drawn over each other
    if (v_stack > 1.0) a = 1.0 - pow(1.0 - a, v_stack);
    f_color = vec4(to_srgb(v_color.rgb) * a, a);
}
"""


# moderngl objects are typed ``Any``: its bundled stubs type a program's members as a union, of
# which only ``Uniform`` has the ``value`` / ``write`` used here.
@dataclass
class _GpuMesh:
    """One batch on the GPU: a primitive repeated for each of its nodes, posed on the CPU each frame
    into world space (one buffer upload and one draw call per primitive, not per fish)."""
    index: int        # of its batch in the scene's Poser.batches
    batch: Batch
    material: Material
    vbo: Any          # moderngl.Buffer: world positions and normals, rewritten each frame
    static: Any       # moderngl.Buffer: texture coordinates, colours, baked light
    ibo: Any          # moderngl.Buffer; a BLEND mesh's triangles are rewritten back to front each frame
    vao: Any          # moderngl.VertexArray
    texture: Any      # moderngl.Texture or None
    centroid: np.ndarray     # local, of the primitive's rest positions
    computed_normals: bool   # the file has none: made from the posed triangles each frame


_Method = TypeVar("_Method", bound=Callable[..., Any])


def _in_context(method: _Method) -> _Method:
    """The renderer's GL context current through ``method`` (:meth:`_Gl.current`)."""
    @functools.wraps(method)
    def run(self: Renderer, *args: Any, **kwargs: Any) -> Any:
        with self._gl.current():
            return method(self, *args, **kwargs)
    return cast(_Method, run)


class Renderer:
    """A framebuffer, reused for every image of a run, and the uploads of what it draws, on its
    thread's headless GL context (:func:`_gl_for_thread`). Use it in the thread that made it, and
    release it (or use it as a context manager)."""

    sort_triangles = True
    """Draw a transparent mesh's triangles farthest first (off: in file order, as three.js does)."""
    transparent_depth_writes = False
    """Transparent parts write no depth, as in three.js. (On, they hide what is drawn after them:
    fishgen's preview before issue 20 showed a billboard cloud as hard-edged rectangles.)"""

    def __init__(self, width: int, height: int, *, fine_blending: bool = False, samples: int = SAMPLES):
        """``fine_blending``: blend in 16-bit float colour, not 8-bit. Thousands of faint soft
        discs over one pixel (a cloud's particles) each rounded to 8 bits drew rings and grain over
        a smooth cloud; 16 bits cost 28 bytes a pixel more at 4x multisampling, so only a scene
        with particles (points or billboards) asks for it. ``samples``: multisamples a pixel (1:
        none, each pixel one sample, its masked materials' alpha tested at its centre)."""
        if not all(isinstance(n, numbers.Integral) and 0 < n <= 2**15 for n in (width, height)):
            raise ValueError(f"expected a renderer's width and height as whole numbers from 1 to 32768, "
                             f"found {width!r} x {height!r}")
        width, height = int(width), int(height)
        self._gl = gl = _gl_for_thread()
        self.ctx: Any = gl.ctx
        self.mesh_prog: Any = gl.mesh_prog
        self.point_prog: Any = gl.point_prog
        self.corner_buf = gl.corner_buf
        self.width, self.height = width, height
        samples = min(samples, self.ctx.max_samples) if samples > 1 else 0
        self.colour = "f2" if fine_blending else "f1"
        self._own: list[Any] = []   # framebuffers: what release() frees besides the uploads
        # Caches by id(scene), each entry holding a weak reference to its scene: a scene freed and
        # another made at the same address must not find the first one's buffers (it drew the old cloud).
        self._uploaded: dict[int, tuple[weakref.ref, Poser, list[_GpuMesh]]] = {}
        self._textures: dict[tuple[int, int], tuple[weakref.ref, Any]] = {}
        self._points: dict[int, tuple[weakref.ref, list[tuple[int, Primitive]]]] = {}
        self._framebuffers(width, height, samples, fine_blending)

    def __enter__(self) -> Renderer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.release()

    @_in_context
    def _framebuffers(self, width: int, height: int, samples: int, fine_blending: bool) -> None:
        import moderngl

        try:
            colour = self._keep(self.ctx.renderbuffer((width, height), 4, samples=samples, dtype=self.colour))
            depth = self._keep(self.ctx.depth_renderbuffer((width, height), samples=samples))
            self.msaa = self._keep(self.ctx.framebuffer(color_attachments=[colour], depth_attachment=depth))
            plain = self._keep(self.ctx.renderbuffer((width, height), 4, dtype=self.colour))
            self.resolved = self._keep(self.ctx.framebuffer(color_attachments=[plain]))
        except moderngl.Error as err:  # out of memory: the driver leaves the framebuffer incomplete
            self.release()
            colour_bytes = 8 if fine_blending else 4
            need = width * height * (colour_bytes + 4) * max(samples, 1) + width * height * colour_bytes
            # past the estimate (preview.memory): the system's refusal, as an out-of-memory error is
            raise SystemFailure(f"out of memory for a {width}x{height} framebuffer ({need / 2**20:,.0f} MiB "
                                f"with {samples}x anti-aliasing): the driver could not make one ({err})"
                                ) from None

    def _keep(self, thing: Any) -> Any:
        self._own.append(thing)
        return thing

    def _forget_dead(self) -> None:
        """Free the uploads of scenes gone since they were drawn: a fit draws hundreds of fish through
        one renderer, and the context outlives it."""
        for key, (ref, _, meshes) in list(self._uploaded.items()):
            if ref() is None:
                del self._uploaded[key]
                _free(meshes)
        for tkey, (ref, tex) in list(self._textures.items()):
            if ref() is None:
                del self._textures[tkey]
                tex.release()
        for key, (ref, _) in list(self._points.items()):
            if ref() is None:
                del self._points[key]

    # -- uploads -------------------------------------------------------------
    def _texture(self, scene: Scene, index: int) -> Any:
        import moderngl

        key = (id(scene), index)
        if key not in self._textures or self._textures[key][0]() is not scene:
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
            self._textures[key] = (weakref.ref(scene), tex)
        return self._textures[key][1]

    def _upload(self, scene: Scene, clip: str | None) -> tuple[Poser, list[_GpuMesh]]:
        key = id(scene)
        held = self._uploaded.get(key)
        if held is not None and held[0]() is scene and held[1].active is scene.clip(clip):
            return held[1], held[2]
        self._forget_dead()
        if key in self._uploaded:  # the same scene posed by another clip: drawn again from its rest
            _free(self._uploaded.pop(key)[2])
        out: list[_GpuMesh] = []
        poser = poser_for(scene, clip)
        for index, batch in enumerate(poser.batches):
            prim = batch.prim
            if prim.mode != "TRIANGLES" or batch.indices is None:
                continue
            material = scene.materials[prim.material] if prim.material is not None else DEFAULT_MATERIAL
            vbo = self.ctx.buffer(reserve=batch.instances * prim.vertex_count * 24, dynamic=True)
            static = self.ctx.buffer(np.tile(self._static_data(prim), (batch.instances, 1)).tobytes())
            ibo = self.ctx.buffer(batch.indices.astype(np.uint32).tobytes(),
                                  dynamic=material.alpha_mode == "BLEND")
            vao = self.ctx.vertex_array(self.mesh_prog, [(vbo, "3f 3f", "in_pos", "in_normal"),
                                                         (static, "2f 4f 1f", "in_uv", "in_color",
                                                          "in_light")], ibo)
            tex = self._texture(scene, material.texture) if material.texture is not None else None
            out.append(_GpuMesh(index, batch, material, vbo, static, ibo, vao, tex,
                                np.asarray(prim.positions, float).mean(0), batch.base_nrm is None))
        self._uploaded[key] = (weakref.ref(scene), poser, out)
        return poser, out

    @staticmethod
    def _static_data(prim: Primitive) -> np.ndarray:
        n = prim.vertex_count
        uvs = prim.attributes.get("TEXCOORD_0")
        uvs = np.zeros((n, 2), np.float32) if uvs is None else to_linear_float(uvs)[:, :2] \
            if np.asarray(uvs).dtype.kind in "iu" else np.asarray(uvs, np.float32)
        colors = prim.attributes.get("COLOR_0")
        colors = np.ones((n, 4), np.float32) if colors is None else to_linear_float(colors)
        return np.hstack([uvs, colors, _light(prim)[:, None]]).astype(np.float32)

    # -- drawing -------------------------------------------------------------
    def render(self, scene: Scene, camera: Camera, t: float | None,
               background: tuple[float, float, float, float], clip: str | None = None) -> np.ndarray:
        """Draw ``scene`` posed at ``t``; returns (H, W, 4) uint8 RGBA, straight alpha."""
        self.draw(scene, camera, self.posed(scene, t, clip), background, clip)
        return self.finish()

    def render_all(self, scene: Scene, shots: Sequence[tuple[Camera, float | None]],
                   background: tuple[float, float, float, float],
                   clip: str | None = None) -> Iterator[np.ndarray]:
        """``render`` of each (camera, time), in order. The next frame is posed on the CPU while
        Mesa's threads still rasterise this one: a frame is read back only after that."""
        waiting = False
        for camera, t in shots:
            posed = self.posed(scene, t, clip)
            if waiting:
                yield self.finish()
            self.draw(scene, camera, posed, background, clip)
            self._hand_over()
            waiting = True
        if waiting:
            yield self.finish()

    @_in_context
    def _hand_over(self) -> None:
        self.resolved.use()  # binding another framebuffer hands the frame to Mesa's threads

    @_in_context
    def posed(self, scene: Scene, t: float | None, clip: str | None = None) -> tuple[Pose, list]:
        """Every batch of ``scene`` posed at ``t``: the CPU's share of a frame."""
        poser, meshes = self._upload(scene, clip)
        posed, worlds = poser.frame(t)
        out = []
        for m in meshes:  # morph targets, skins and node transforms: posed on the CPU, drawn in world space
            pos, nrm = worlds[m.index]
            if nrm is None:
                nrm = vertex_normals(pos, m.batch.indices.reshape(-1, 3))  # type: ignore[union-attr]
            out.append((pos, np.hstack([pos, nrm]).astype(np.float32)))
        return posed, out

    def finish(self) -> np.ndarray:
        """The frame last drawn, resolved and read back: (H, W, 4) uint8 RGBA, straight alpha."""
        return unpremultiply(self._resolved())

    def coverage(self, scene: Scene, camera: Camera, t: float | None = None,
                 size: tuple[int, int] | None = None) -> np.ndarray:
        """(H, W) uint8 alpha of ``scene`` drawn on a transparent background: ``render``'s alpha
        channel, without straightening the colours (a third of a small frame's time), for a caller
        that measures only a silhouette. ``size``: (W, H) of a smaller frame, drawn in the
        framebuffer's corner as a renderer of that size draws it (one renderer, and its uploads,
        serving frames of several sizes)."""
        self.draw(scene, camera, self.posed(scene, t), (0.0, 0.0, 0.0, 0.0), size=size)
        return np.ascontiguousarray(self._resolved(size)[:, :, 3])

    @_in_context
    def _resolved(self, size: tuple[int, int] | None = None) -> np.ndarray:
        """The frame last drawn, resolved: (H, W, 4) uint8 RGBA as drawn (premultiplied), top row first
        (``size``: of the frame drawn in the corner)."""
        width, height = size or (self.width, self.height)
        self.ctx.copy_framebuffer(self.resolved, self.msaa)
        raw = self.resolved.read(viewport=(0, 0, width, height), components=4, alignment=1,
                                 dtype=self.colour)
        if self.colour == "f1":
            return np.frombuffer(raw, np.uint8).reshape(height, width, 4)[::-1]
        values = np.clip(np.frombuffer(raw, np.float16), 0, 1)
        values *= np.float16(255)
        return np.rint(values, out=values).astype(np.uint8).reshape(height, width, 4)[::-1]

    @_in_context
    def draw(self, scene: Scene, camera: Camera, frame: tuple[Pose, list],
             background: tuple[float, float, float, float], clip: str | None = None,
             size: tuple[int, int] | None = None) -> None:
        """Issue the GL commands of one frame posed by ``posed``; ``finish`` reads it back. ``size``:
        (W, H) of a smaller frame, drawn in the framebuffer's lower-left corner."""
        import moderngl

        ctx = self.ctx
        _, meshes = self._upload(scene, clip)
        posed, vertices = frame
        view, proj = camera.view(), camera.projection()
        viewproj = proj @ view
        if size is not None and (size[0] > self.width or size[1] > self.height):
            raise ValueError(f"a {size[0]}x{size[1]} frame does not fit a {self.width}x{self.height} "
                             "renderer")
        self.msaa.viewport = (0, 0, *(size or (self.width, self.height)))
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
        cloud = from_extras(scene.extras)
        for program in (self.mesh_prog, self.point_prog):
            _set_cloud_light(program, cloud)

        self.msaa.depth_mask = True
        models: dict[int, np.ndarray] = {}
        posed_positions: dict[int, np.ndarray] = {}
        self._posed = posed_positions
        for m, (pos, data) in zip(meshes, vertices, strict=True):
            m.vbo.write(data.tobytes())
            posed_positions[id(m)] = pos
            # a BLEND batch holds one node: its depth is that of its rest centroid, placed
            models[id(m)] = posed.matrix(int(m.batch.nodes[0]))
        opaque = [m for m in meshes if m.material.alpha_mode != "BLEND"]
        blended = [m for m in meshes if m.material.alpha_mode == "BLEND"]

        def depth(m: _GpuMesh) -> float:
            c = view @ models[id(m)] @ np.append(m.centroid, 1.0)
            return float(c[2])  # more negative = farther

        for m in opaque:
            self._draw_mesh(m)
        # Transparent parts are blended over what lies behind them, as three.js blends them (its
        # GLTFLoader turns depth writes off for BLEND materials), and drawn farthest first: whole
        # meshes, and each mesh's triangles (a billboard cloud's quads, a fin's folds).
        self.msaa.depth_mask = self.transparent_depth_writes
        for m in sorted(blended, key=depth):
            if self.sort_triangles:
                self._sort_triangles(m, view)
            self._draw_mesh(m)
        self._draw_points(scene, posed, view, proj, camera.eye)
        self.msaa.depth_mask = True

    def _sort_triangles(self, m: _GpuMesh, view: np.ndarray) -> None:
        """Rewrite a transparent mesh's index buffer with its triangles farthest first."""
        tris = m.batch.indices.reshape(-1, 3)  # type: ignore[union-attr]
        if len(tris) < 2:
            return
        centroids = self._posed[id(m)][tris].mean(axis=1)
        depth = centroids @ view[2, :3]           # view-space z: more negative = farther
        order = np.argsort(depth, kind="stable")
        m.ibo.write(np.ascontiguousarray(tris[order], np.uint32).tobytes())

    def _draw_mesh(self, m: _GpuMesh) -> None:
        import moderngl

        prog, mat = self.mesh_prog, m.material
        prog["u_model"].write(_IDENTITY4)
        prog["u_normal_matrix"].write(_IDENTITY3)
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

    def _draw_points(self, scene: Scene, posed: Pose, view: np.ndarray, proj: np.ndarray,
                     eye: np.ndarray) -> None:
        import moderngl

        parts = []
        held = self._points.get(id(scene))
        if held is None or held[0]() is not scene:  # drawn() walks every node: once a scene, not a frame
            drawn = [(node, prim) for node, prim in scene.drawn()
                     if prim.mode == "POINTS" and prim.vertex_count]
            self._points[id(scene)] = held = (weakref.ref(scene), drawn)
        for node, prim in held[1]:
            c, r, col = particles(scene, node, prim, posed)
            parts.append((c, r, col, _light(prim), stacks(prim)))
        if not parts:
            return
        c = np.concatenate([p[0] for p in parts]).astype(np.float32)
        r = np.concatenate([p[1] for p in parts]).astype(np.float32)
        col = np.concatenate([p[2] for p in parts]).astype(np.float32)
        light = np.concatenate([p[3] for p in parts]).astype(np.float32)
        stack = np.concatenate([p[4] for p in parts]).astype(np.float32)
        order = np.argsort((c @ view[2, :3]) + view[2, 3], kind="stable")  # back to front: "over"
        inst = np.hstack([c[order], r[order, None], col[order], light[order, None],
                          stack[order, None]]).astype(np.float32)
        buf = self.ctx.buffer(inst.tobytes())
        prog = self.point_prog
        prog["u_view"].write(view.T.astype("f4").tobytes())
        prog["u_proj"].write(proj.T.astype("f4").tobytes())
        prog["u_eye"].value = tuple(eye)
        prog["u_opacity"].value = PARTICLE_OPACITY
        vao = self.ctx.vertex_array(prog, [(self.corner_buf, "2f", "in_corner"),
                                           (buf, "3f 1f 4f 1f 1f/i", "in_center", "in_radius", "in_color",
                                            "in_light", "in_stack")])
        vao.render(moderngl.TRIANGLE_STRIP, instances=len(inst))
        vao.release()
        buf.release()

    def release(self) -> None:
        """Free the framebuffers and every upload; the thread's context and programs stay for the
        next renderer (:func:`_gl_for_thread`)."""
        with self._gl.current():
            for _, _, meshes in self._uploaded.values():
                _free(meshes)
            for _, tex in self._textures.values():
                tex.release()
            self._uploaded.clear()
            self._textures.clear()
            self._points.clear()
            for thing in reversed(self._own):
                thing.release()
            self._own.clear()
        self._gl.done()


def _free(meshes: list[_GpuMesh]) -> None:
    for m in meshes:   # not the texture: the renderer's texture cache holds it
        for thing in (m.vao, m.vbo, m.static, m.ibo):
            thing.release()


class _Gl:
    """A headless GL context and the programs compiled in it. A new context costs about 15 ms, and
    its first frame about 110 ms more while llvmpipe compiles the shaders; a photo fit makes a
    renderer for each of its measures, a test worker hundreds."""

    def __init__(self, kept: bool):
        import moderngl

        if _DREW and os.getpid() not in _DREW:
            raise FishgenError(
                "expected to draw in a process not forked from one that drew: Mesa's rasteriser "
                "stayed with the parent, and a first draw here hangs (start the process with "
                "multiprocessing's spawn or forkserver), found a fork")
        try:
            # the stubs type ``**settings`` as dicts; the backend is a string
            self.ctx: Any = moderngl.create_context(standalone=True, backend="egl")  # type: ignore[arg-type]
        except Exception as err:  # no libEGL / no Mesa driver on this machine
            raise FishgenError(
                "expected an OpenGL 3.3 context from EGL (Debian: apt-get install libegl1 "
                f"libgl1-mesa-dri), found none ({err})") from None
        _DREW.add(os.getpid())
        self.kept, self.pid, self.thread = kept, os.getpid(), threading.get_ident()
        self.handle = _egl_current()   # made current by its making
        self.mesh_prog = self.ctx.program(vertex_shader=MESH_VS, fragment_shader=MESH_FS)
        self.point_prog = self.ctx.program(vertex_shader=POINT_VS, fragment_shader=POINT_FS)
        corners = np.array([-1, -1, 1, -1, -1, 1, 1, 1], np.float32)
        self.corner_buf = self.ctx.buffer(corners.tobytes())

    @contextmanager
    def current(self) -> Iterator[None]:
        """The context current for a renderer's work. A context the caller had current is current
        again after: its GL calls (a buffer's release by its name) must not reach this one's."""
        if threading.get_ident() != self.thread:
            raise RuntimeError("a fishgen Renderer draws only in the thread that made it: make one "
                               "in this thread")
        before = _egl_state()
        if before is not None and before[3] == self.handle:
            yield
            return
        self.ctx.__enter__()
        try:
            yield
        finally:
            if before is not None and before[3]:   # the caller's context, current again
                _egl().eglMakeCurrent(*before)

    def done(self) -> None:
        """A renderer is done with it: a context of its own goes, a kept one stays."""
        if self.kept:
            return
        self.ctx.release()
        if _egl_current() in (0, self.handle):
            # the thread's own EGL state, 3 MB a thread that drew otherwise
            _egl().eglReleaseThread()


_MAIN_GL: list[_Gl] = []
"""The main thread's kept context."""
_DREW: set[int] = set()
"""The processes that made a context here: this one, or the one it was forked from."""
_EGL: list[Any] = []


def _egl() -> Any:
    """libEGL, as glcontext loads it (None: not by that name)."""
    if not _EGL:
        try:
            lib: Any = ctypes.CDLL(os.environ.get("GLCONTEXT_LINUX_LIBEGL") or "libEGL.so.1")
        except OSError:
            _EGL.append(None)
            return None
        for name in ("eglGetCurrentContext", "eglGetCurrentDisplay", "eglGetCurrentSurface"):
            getattr(lib, name).restype = ctypes.c_void_p
        lib.eglMakeCurrent.argtypes = [ctypes.c_void_p] * 4
        _EGL.append(lib)
    return _EGL[0]


def _egl_state() -> tuple[int | None, ...] | None:
    """What is current in this thread, as eglMakeCurrent takes it back: display, draw and read
    surfaces, context (glcontext's own exit makes nothing current, not what was)."""
    lib = _egl()
    if lib is None:
        return None
    return (lib.eglGetCurrentDisplay(), lib.eglGetCurrentSurface(0x3059),   # EGL_DRAW
            lib.eglGetCurrentSurface(0x305A), lib.eglGetCurrentContext())   # EGL_READ


def _egl_current() -> int:
    """The EGL context current in this thread (0: none; -1: libEGL not found by that name)."""
    state = _egl_state()
    return -1 if state is None else state[3] or 0


def _gl_for_thread() -> _Gl:
    """The main thread keeps one context for every renderer it makes. Another thread gets a context
    of its own, freed with its renderer: a thread's end would leave a kept one current nowhere,
    never freed. A process forked after drawing cannot draw (:class:`_Gl`); no fishgen process pool
    draws."""
    if threading.current_thread() is not threading.main_thread():
        return _Gl(kept=False)
    if not _MAIN_GL or _MAIN_GL[-1].pid != os.getpid():   # a forked parent's is not this one's
        _MAIN_GL.append(_Gl(kept=True))
    return _MAIN_GL[-1]


def particles(scene: Scene, node: int, prim: Primitive,
              posed: Pose) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """World centres, world radii and linear RGBA of a point set: a soft disc per particle.

    ``_RADIUS`` sizes each particle (else a small fraction of the set's extent);
    ``_DENSITY`` (fishgen clouds) fades the thin edges; past 1 it stacks (``stacks``).
    """
    centers, _ = deformed(scene, node, prim, posed)
    m = posed.matrix(node)
    a = prim.attributes
    radii = point_radii(prim) * float(np.cbrt(abs(np.linalg.det(m[:3, :3]))))
    rgba = (np.ones((prim.vertex_count, 4), np.float32) if "COLOR_0" not in a
            else to_linear_float(a["COLOR_0"]))
    material = scene.materials[prim.material] if prim.material is not None else DEFAULT_MATERIAL
    rgba = rgba * np.asarray(material.base_color, np.float32)
    if "_DENSITY" in a:   # past 1: stacked sprites (``stacks``)
        rgba[:, 3] *= np.clip(np.asarray(a["_DENSITY"], np.float32).ravel(), 0, 1)
    return centers, radii, rgba


def point_radii(prim: Primitive) -> np.ndarray:
    """Each particle's radius in its mesh's frame, as drawn: ``_RADIUS`` (a negative one draws as its
    size), else a small fraction of the set's extent (float32)."""
    if "_RADIUS" in prim.attributes:
        return np.abs(np.asarray(prim.attributes["_RADIUS"], np.float32).ravel())
    # in float64: a set 1e20 wide squared past float32's range, and its particles became infinite
    span = np.ptp(prim.positions.astype(np.float64), axis=0) if prim.vertex_count else np.ones(3)
    return np.full(prim.vertex_count, POINT_SIZE_FRACTION * float(np.linalg.norm(span)), np.float32)


def stacks(prim: Primitive) -> np.ndarray:
    """Per particle, how many sprites it draws stacked: its ``_DENSITY`` past 1 (a preview's merged
    particle holds that much optical mass over its area), else 1."""
    if "_DENSITY" not in prim.attributes:
        return np.ones(prim.vertex_count, np.float32)
    density = np.nan_to_num(np.asarray(prim.attributes["_DENSITY"], np.float32).ravel())
    return np.maximum(density, np.float32(1))


def _light(prim: Primitive) -> np.ndarray:
    """Per vertex: the baked sunlight of a fishgen cloud particle (``_LIGHT``), else -1 (none)."""
    light = prim.attributes.get("_LIGHT")
    if light is None or len(light) != prim.vertex_count:
        return np.full(prim.vertex_count, -1.0, np.float32)
    return np.clip(np.nan_to_num(np.asarray(light, np.float32).ravel(), nan=0.0), 0, 1)


def _set_cloud_light(program: Any, lighting: Lighting | None) -> None:
    """The second pass's uniforms: the lighting a cloud file records, or off."""
    program["u_cloud"].value = lighting is not None
    if lighting is None:
        return
    program["u_cloud_sun"].value = lighting.sun_unit
    program["u_sun_color"].value = lighting.sun_color
    program["u_sky_color"].value = lighting.sky_color
    program["u_albedo"].value = lighting.albedo
    program["u_g"].value = lighting.anisotropy


def unpremultiply(img: np.ndarray) -> np.ndarray:
    """Premultiplied RGBA8 to straight alpha (what PNG and WebP store)."""
    a = img[..., 3:4].astype(np.float32)
    if np.all(a == 255):
        return img.copy()
    rgb = np.where(a > 0, img[..., :3] * (255.0 / np.maximum(a, 1)), 0)
    return np.concatenate([np.clip(rgb + 0.5, 0, 255).astype(np.uint8), img[..., 3:4]], -1)
