"""Every output format in every client that runs here (docs/clients.md).

One test per (format, client) cell; the whole matrix is printed at the end of
the session and written to out/client-matrix.md.
"""
from __future__ import annotations

import shutil

import pytest

from tests.clients.matrix import KNOWN_LIMITS, ROOT, Asset, Format, cells


@pytest.mark.parametrize(("label", "client"), cells(), ids=[f"{c}-{fmt.replace(' ', '_')}" for fmt, c in cells()])
def test_cell(matrix, label, client):
    cell = matrix.run(label, client)
    if cell.status == "skip":
        pytest.skip(cell.reason)
    if cell.status == "known":
        pytest.xfail(f"known client limitation: {cell.reason} ({cell.details.get('error')})")
    assert cell.status == "pass", f"{label} in {client}: {cell.reason}"


def test_known_limits_name_real_cells():
    assert set(KNOWN_LIMITS) <= set(cells())


def test_cli_summary_counts_were_read(matrix):
    for asset in matrix.assets.values():
        key = "triangles" if asset.fmt.kind == "fish" else "particles"
        assert asset.reported[key] > 0, asset.summary


# The harness must catch what it is there to catch: these break a good asset on purpose.

def _broken_copy(matrix, label: str, name: str) -> Asset:
    good = matrix.assets[label]
    fmt = Format(f"selftest {name}", good.fmt.kind, good.fmt.filename, good.fmt.flags)
    folder = matrix.asset_dir / fmt.slug
    if folder.exists():
        shutil.rmtree(folder)
    shutil.copytree(good.path.parent, folder)
    return Asset(fmt, folder / fmt.filename, list(good.files), good.summary, dict(good.reported), dict(good.expected))


@pytest.fixture
def three(matrix):
    client = matrix.three()
    if client is None:
        pytest.skip(matrix._three_error or "three.js unavailable")
    return client


def test_three_fails_the_obj_cell_on_the_imfchan_404(matrix, three):
    # Before the fix, map_d carried '-imfchan m': MTLLoader asked for a file named '-imfchan m fish_skin.png'.
    asset = _broken_copy(matrix, "fish obj", "obj imfchan")
    mtl = asset.path.with_suffix(".mtl")
    mtl.write_text(mtl.read_text().replace("map_d fish_skin_mask.png", "map_d -imfchan m fish_skin.png"))
    with pytest.raises(AssertionError, match="404"):
        three.check(asset)


def test_three_fails_a_gltf_whose_texture_is_missing(matrix, three):
    asset = _broken_copy(matrix, "fish gltf", "gltf no png")
    (asset.path.parent / "fish_skin.png").unlink()
    with pytest.raises(AssertionError, match="404|did not arrive"):
        three.check(asset)


def test_three_fails_on_a_count_fishgen_did_not_report(matrix, three):
    asset = _broken_copy(matrix, "cloud glb points", "points wrong count")
    asset.expected["particles"] += 1
    with pytest.raises(AssertionError, match="particles"):
        three.check(asset)


def test_three_js_plays_the_body_wave_at_full_amplitude(matrix, three):
    """three.js's own morph code moves BonyBream's tail tip as the wave says (issue 10, within 10 %)."""
    import numpy as np

    from fishgen.assembly.fish import make_fish
    from fishgen.exchange import export
    from fishgen.geometry.body_wave import BodyWave
    from fishgen.species.parser import load_species

    fish = make_fish(load_species(ROOT / "params" / "bonybream.txt"))
    scene = fish.scene
    export(scene, matrix.asset_dir / "wave" / "bonybream.glb")
    duration = scene.clip("swim").duration
    times = np.linspace(0.0, duration, 600, endpoint=False)
    result = three.tail_track("wave/bonybream.glb", times.tolist())
    lateral = np.array(result["track"])[:, 0]
    wave = BodyWave()
    print(f"three.js tail tip: peak-to-peak {np.ptp(lateral) / result['length']:.3f} body lengths")
    assert result["influences"] == 4
    assert np.ptp(lateral) == pytest.approx(wave.tail_peak_to_peak * result["length"], rel=0.10)
    upward = np.count_nonzero((lateral[:-1] < lateral.mean()) & (lateral[1:] >= lateral.mean()))
    assert upward / duration == pytest.approx(fish.facts.tail_beat_hz, rel=0.10)
