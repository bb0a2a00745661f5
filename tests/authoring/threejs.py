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
