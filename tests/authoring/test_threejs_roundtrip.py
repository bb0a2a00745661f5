"""The round trip with photos from a second renderer (three.js in Chromium), so the check does
not only agree with fishgen's own renderer: same tolerances as test_photo_roundtrip."""
from __future__ import annotations

from dataclasses import replace

import pytest

from fishgen.authoring.photo.compare import silhouette_iou
from tests.authoring import photos as ph
from tests.authoring.conftest import SHIPPED
from tests.authoring.test_photo_roundtrip import BODY_TOLERANCE, FIN_TOLERANCE, MIN_IOU, run_round_trip
from tests.authoring.threejs import ThreePhotographer, unavailable

pytestmark = pytest.mark.skipif(unavailable() is not None, reason=str(unavailable()))


@pytest.fixture(scope="module")
def camera(tmp_path_factory):
    """One Chromium page for the module (Playwright's sync API allows one instance per thread)."""
    cam = ThreePhotographer(tmp_path_factory.mktemp("three"))
    try:
        yield cam
    finally:
        cam.close()


@pytest.fixture(scope="module")
def three_photos(camera):
    """species name -> (species, its photo by three.js), for each shipped species."""
    from fishgen.species.parser import load_species
    from tests.conftest import PARAMS

    species = {name: load_species(PARAMS / f"{name}.txt") for name in SHIPPED}
    return {name: (sp, camera.photo(sp)) for name, sp in species.items()}


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


@pytest.mark.slow
@pytest.mark.parametrize("subject, base_name",
                         [("sampled_7", "threadfingoldie"), ("forked", "pineapplefish")])
def test_unseen_fish_lit_and_turned_fits_any_base(tmp_path, gl_available, camera, subject, base_name):
    """Issue 25: a fish fishgen does not ship, lit by an environment map and a sun, turned 12 degrees
    off side-on in a slight perspective, with translucent fins, made into a species with
    --fit-shape on another species' base: three.js, photographing the rebuilt fish side-on, sees
    IoU >= 0.85 with the photo's true silhouette, and the fish is whole."""
    from fishgen.authoring.photo.checks import fit_problems
    from fishgen.authoring.photo.run import TextureOptions, make_texture
    from fishgen.species.parser import load_species
    from tests.authoring.subjects import SAMPLED, variants, write_subjects
    from tests.authoring.threejs import lit_photo
    from tests.conftest import PARAMS

    seeds = tuple(seed for seed in SAMPLED if f"sampled_{seed}" == subject)   # this subject alone
    species = write_subjects(tmp_path / "subjects", seeds,
                             {k: v for k, v in variants().items() if k == subject})[subject]
    photo, truth = lit_photo(camera, species, "lit")
    photo.save(tmp_path / "photo.png")
    result = make_texture(tmp_path / "photo.png", load_species(PARAMS / f"{base_name}.txt"),
                          tmp_path / "new.txt", TextureOptions(fit_shape=True))
    rebuilt = load_species(tmp_path / "new.txt")
    shot = camera.photo(replace(rebuilt, name=f"rebuilt_{subject}"))
    assert result.fitted and result.frame is not None
    iou = silhouette_iou(result.frame.level(truth), shot.rgba[:, :, 3] >= 64)
    assert iou >= 0.85, f"{subject} on {base_name}: IoU {iou:.3f} by three.js"
    fit = result.shape_fit
    assert fit_problems(rebuilt, fit.work, fit.placement) == []


def test_mottled_water_beside_an_opaque_fin_stays_backdrop(tmp_path, camera):
    """The translucent-fin search (issue 32) keeps only patches whose tint lifts them as a whole:
    three.js's mottled water beside BonyBream's thin tail fin, brighter than the water around it
    at its crest, stays backdrop (it cost that photo's fits 0.08-0.12 IoU when it was taken)."""
    from scipy import ndimage  # type: ignore[import-untyped]

    from fishgen.authoring.photo.image import load_photo
    from fishgen.authoring.photo.silhouette import silhouette
    from fishgen.species.parser import load_species
    from tests.authoring.threejs import lit_photo
    from tests.conftest import PARAMS

    photo, truth = lit_photo(camera, load_species(PARAMS / "bonybream.txt"), "lit+water")
    photo.save(tmp_path / "photo.png")
    found = silhouette(load_photo(tmp_path / "photo.png"))
    assert found.source == "background model"
    outside = found.mask & ~ndimage.binary_dilation(truth, iterations=2)
    assert outside.sum() <= 0.002 * truth.sum(), f"{outside.sum()} px of water taken as fish"
