"""The round trip with photos from a second renderer (three.js in Chromium), so the check does
not only agree with fishgen's own renderer: same tolerances as test_photo_roundtrip."""
from __future__ import annotations

import pytest

from fishgen.authoring.photo.compare import silhouette_iou
from tests.authoring import photos as ph
from tests.authoring.conftest import SHIPPED
from tests.authoring.test_photo_roundtrip import BODY_TOLERANCE, FIN_TOLERANCE, MIN_IOU, run_round_trip
from tests.authoring.threejs import ThreePhotographer, unavailable

pytestmark = pytest.mark.skipif(unavailable() is not None, reason=str(unavailable()))


@pytest.fixture(scope="module")
def three_photos(tmp_path_factory, photos):
    camera = ThreePhotographer(tmp_path_factory.mktemp("three"))
    try:
        yield {name: (sp, camera.photo(sp)) for name, (sp, _) in photos.items()}
    finally:
        camera.close()


@pytest.mark.parametrize("name", SHIPPED)
def test_three_js_photo_round_trip(tmp_path, gl_available, three_photos, name):
    species, photo = three_photos[name]
    assert (photo.rgba[:, :, 3] >= 64).mean() > 0.05, "three.js drew (almost) nothing"
    result, rebuilt, body, fins = run_round_trip(tmp_path, species, photo)
    assert body.max() <= BODY_TOLERANCE, f"{name}: body point off by {body.max():.4f}"
    worst = max(fins, key=lambda n: fins[n])
    assert fins[worst] <= FIN_TOLERANCE, f"{name}: {worst} fin off by {fins[worst]:.4f}"
    iou = silhouette_iou(result.level_mask, ph.rendered_mask(rebuilt))
    assert iou >= MIN_IOU, f"{name}: IoU {iou:.3f}"
