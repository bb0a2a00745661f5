"""Photos of fishgen fish from a second renderer: three.js (GLTFLoader + WebGLRenderer) in headless
Chromium, side-on with an orthographic camera whose frustum is set here, so where each ring and
fin vertex lands on the picture is known exactly (the truth for the round trip)."""
from __future__ import annotations

import base64
import io
from pathlib import Path

import numpy as np
from PIL import Image

from fishgen.assembly.fish import METRES_PER_WORLD_UNIT, THESIS_TO_GLTF, build_fish
from fishgen.species.model import Species
from tests.authoring.photos import SIZE, Photo, truth_points
from tests.clients.matrix import THREE_DIR, LocalBrowser, three_unavailable

HERE = Path(__file__).resolve().parent
FILL = 0.85


unavailable = three_unavailable  # the client matrix's own check


class ThreePhotographer(LocalBrowser):
    """One local server (three.js, this page, the assets) and one Chromium page for all photos."""

    def __init__(self, assets: Path):
        super().__init__({"/three/": THREE_DIR, "/page/": HERE, "/assets/": assets})
        self.page.goto(f"{self.base}/page/threejs_photo.html")
        self.page.wait_for_function("window.pageReady === true", timeout=30_000)
        self.assets = assets

    def photo(self, species: Species, size=SIZE) -> Photo:
        import fishgen

        w, h = size
        scene = build_fish(species)
        glb = self.assets / f"{species.name}.glb"
        fishgen.export(scene, glb)
        metres = species.world_scale * METRES_PER_WORLD_UNIT
        centre = np.array([0.5 * species.scale[0], 0.0, 0.0])

        def world(p3: np.ndarray) -> np.ndarray:
            return (np.asarray(p3, float) - centre) @ THESIS_TO_GLTF.T * metres

        body, fins = truth_points(species, world)
        pts = np.concatenate([body, *fins.values()])
        cy, cz = (pts[:, 1].min() + pts[:, 1].max()) / 2, (pts[:, 2].min() + pts[:, 2].max()) / 2
        half_h = max(np.ptp(pts[:, 1]) / 2, np.ptp(pts[:, 2]) / 2 * h / w) / FILL
        half_w = half_h * w / h
        cam = {"width": w, "height": h, "halfWidth": half_w, "halfHeight": half_h, "centreY": cy,
               "centreZ": cz, "distance": 10.0 * float(np.abs(pts).max() + 1)}
        url = f"{self.base}/assets/{glb.name}"
        result = self.page.evaluate("([u, c]) => window.photograph(u, c)", [url, cam])
        if "error" in result:
            raise RuntimeError(result["error"])
        png = base64.b64decode(result["png"].split(",", 1)[1])
        rgba = np.asarray(Image.open(io.BytesIO(png)).convert("RGBA"))

        def screen(g: np.ndarray) -> np.ndarray:   # camera on +X looking -X: screen right is -Z
            return np.stack([(-(g[:, 2] - cz) + half_w) / (2 * half_w) * w,
                             (half_h - (g[:, 1] - cy)) / (2 * half_h) * h], 1)

        return Photo(np.ascontiguousarray(rgba), screen(body), {n: screen(p) for n, p in fins.items()})


#: The photographic kinds (issue 25): backdrop, floor, yaw (degrees off side-on), camera pitch
#: (degrees, looking down) and vertical field of view (degrees; a slight perspective).
LIT_KINDS: dict[str, dict] = {
    "lit": {"backdrop": None, "floor": False, "yaw": 12.0, "pitch": 4.0, "fov": 22.0},
    "lit+sand": {"backdrop": "water", "floor": True, "yaw": 0.0, "pitch": 8.0, "fov": 25.0},
    "lit+caustics": {"backdrop": "caustics", "floor": True, "yaw": 15.0, "pitch": 6.0, "fov": 28.0},
    "lit+water": {"backdrop": "water", "floor": False, "yaw": -20.0, "pitch": 10.0, "fov": 25.0},
}


def _data_url(rgb: np.ndarray) -> str:
    buf = io.BytesIO()
    Image.fromarray(rgb, "RGB").save(buf, "PNG")
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode()


def lit_photo(camera: ThreePhotographer, species: Species, kind: str, size=SIZE,
              seed: int = 0) -> tuple[Photo, np.ndarray]:
    """(photo, true silhouette) of ``species`` shot as ``kind`` (:data:`LIT_KINDS`): fins blended
    (translucent against the backdrop), lit by an environment map and a sun whose shadow falls on a
    sandy floor, a perspective camera a little above, the fish turned ``yaw`` degrees. The photo's
    truth points are the ring and fin vertices projected by the same camera (for a turned fish some
    lie on its far side, hidden)."""
    import fishgen
    from tests.authoring import backdrops

    spec = LIT_KINDS[kind]
    w, h = size
    scene = build_fish(species, fins="blend")
    glb = camera.assets / f"{species.name}-lit.glb"
    fishgen.export(scene, glb)
    metres = species.world_scale * METRES_PER_WORLD_UNIT
    centre = np.array([0.5 * species.scale[0], 0.0, 0.0])

    def world(p3: np.ndarray) -> np.ndarray:
        return (np.asarray(p3, float) - centre) @ THESIS_TO_GLTF.T * metres

    body, fins = truth_points(species, world)
    pts = np.concatenate([body, *fins.values()])
    size_m = float(np.ptp(pts[:, 2]))           # the fish's length, nose to tail tip
    cy = float((pts[:, 1].min() + pts[:, 1].max()) / 2)
    fov = spec["fov"]
    height_m = float(np.ptp(pts[:, 1]))
    # far enough that the fish fills about 65 % of the width or 70 % of the height, whichever is less
    tan = np.tan(np.radians(fov) / 2)
    distance = max(0.5 * size_m / 0.65 / (tan * w / h), 0.5 * height_m / 0.7 / tan)
    pitch = np.radians(spec["pitch"])
    eye = [distance * np.cos(pitch), cy + distance * np.sin(pitch), 0.0]
    cam = {"width": w, "height": h, "fov": fov, "yaw": spec["yaw"], "eye": eye, "target": [0.0, cy, 0.0],
           "size": size_m, "sun": 2.2, "floorY": float(pts[:, 1].min() - 0.12 * np.ptp(pts[:, 1])),
           "floor": _data_url(backdrops.sand(512, 512, seed)) if spec["floor"] else None,
           "background": None if spec["backdrop"] is None else
           _data_url(getattr(backdrops, spec["backdrop"])(w, h, seed)),
           "points": pts.tolist()}
    url = f"{camera.base}/assets/{glb.name}"
    result = camera.page.evaluate("([u, c]) => window.photographLit(u, c)", [url, cam])
    if "error" in result:
        raise RuntimeError(result["error"])

    def decode(data: str) -> np.ndarray:
        return np.asarray(Image.open(io.BytesIO(base64.b64decode(data.split(",", 1)[1]))).convert("RGBA"))

    rgba = decode(result["png"])
    if spec["backdrop"] is not None:   # a photograph has no alpha
        rgba = np.dstack([rgba[:, :, :3], np.full(rgba.shape[:2], 255, np.uint8)])
    truth = decode(result["alpha"])[:, :, 3] >= 64
    screen = np.asarray(result["points"], float)
    n_body = len(body)
    out_fins, k = {}, n_body
    for name, p in fins.items():
        out_fins[name] = screen[k:k + len(p)]
        k += len(p)
    return Photo(np.ascontiguousarray(rgba), screen[:n_body], out_fins), truth
