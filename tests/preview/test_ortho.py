"""`fishgen preview --ortho`: no perspective, so depth does not move a point on the picture."""
from __future__ import annotations

import numpy as np

from fishgen.preview.camera import frame
from tests.conftest import PARAMS


def test_orthographic_projection_ignores_depth():
    pts = np.array([[-1.0, -0.5, -2.0], [1.0, 0.5, 2.0]])
    cam = frame(pts, "side", 2.0, ortho=True)
    vp = cam.projection() @ cam.view()
    near = vp @ np.array([0.5, 0.2, 0.3, 1.0])
    far = vp @ np.array([-0.5, 0.2, 0.3, 1.0])   # same point seen from +X, one unit deeper
    assert np.allclose(near[:2] / near[3], far[:2] / far[3])
    assert abs(near[2] / near[3]) < 1 and abs(far[2] / far[3]) < 1   # both inside the depth range


def test_ortho_option_renders_a_transparent_side_photo(tmp_path, cli, gl_available):
    from PIL import Image

    out = tmp_path / "side.png"
    r = cli("preview", PARAMS / "bonybream.txt", "--view", "side", "--ortho", "--background", "transparent",
            "--size", "320x160", "-o", out)
    assert r.returncode == 0, r.stderr
    alpha = np.asarray(Image.open(out))[:, :, 3]
    assert alpha[0, 0] == 0 and (alpha > 0).mean() > 0.1


def test_a_coverage_render_is_the_full_render_s_alpha(gl_available):
    """The fit scores silhouettes on ``coverage``: the very alpha ``render`` would give, in
    perspective and orthographic, with translucent fins (partial alpha) included."""
    from fishgen.authoring.photo.compare import render_side
    from fishgen.preview.render import Renderer
    from fishgen.species.parser import load_species

    species = load_species(PARAMS / "threadfingoldie.txt")
    renderer = Renderer(240, 120)
    try:
        for distance in (None, 6.0):
            full = render_side(species, 240, 120, distance, renderer)
            alpha = render_side(species, 240, 120, distance, renderer, coverage=True)
            assert alpha.shape == (120, 240) and np.array_equal(alpha, full[:, :, 3])
            assert ((alpha > 0) & (alpha < 255)).any() and (alpha == 255).any()
    finally:
        renderer.release()
