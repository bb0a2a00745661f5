"""Every output format in every client that runs here (docs/clients.md).

One test per (format, client) cell; the whole matrix is printed at the end of
the session and written to out/client-matrix.md.
"""
from __future__ import annotations

import shutil

import pytest

from tests.clients.matrix import KNOWN_LIMITS, ROOT, Asset, Format, cells


@pytest.mark.parametrize(("label", "client"), cells(),
                         ids=[f"{c}-{fmt.replace(' ', '_')}" for fmt, c in cells()])
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
        key = {"fish": "triangles", "school": "fish", "cloud": "particles"}[asset.fmt.kind]
        assert asset.reported[key] > 0, asset.summary


# The harness must catch what it is there to catch: these break a good asset on purpose.

def _broken_copy(matrix, label: str, name: str) -> Asset:
    good = matrix.assets[label]
    fmt = Format(f"selftest {name}", good.fmt.kind, good.fmt.filename, good.fmt.flags)
    folder = matrix.asset_dir / fmt.slug
    if folder.exists():
        shutil.rmtree(folder)
    shutil.copytree(good.path.parent, folder)
    return Asset(fmt, folder / fmt.filename, list(good.files), good.summary, dict(good.reported),
                 dict(good.expected), good.clip, good.bounds, good.engine)


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


# Babylon.js: the same self-tests as three.js's, through its own page.

@pytest.fixture
def babylon(matrix):
    client = matrix.babylon()
    if client is None:
        pytest.skip(matrix._babylon_error or "Babylon.js unavailable")
    return client


def test_babylon_fails_a_gltf_whose_texture_is_missing(matrix, babylon):
    asset = _broken_copy(matrix, "fish gltf", "babylon gltf no png")
    (asset.path.parent / "fish_skin.png").unlink()
    with pytest.raises(AssertionError, match="404|did not arrive|never"):
        babylon.check(asset)


def test_babylon_fails_a_clip_with_a_wrong_key(matrix, babylon):
    """Counts are not enough: one morph weight key changed in the .bin fails the cell."""
    from tests.clients.godot import spoil_weight_key

    asset = _broken_copy(matrix, "fish gltf", "babylon gltf bad key")
    spoil_weight_key(asset.path)
    with pytest.raises(AssertionError, match="key weight off by"):
        babylon.check(asset)


def test_babylon_appends_the_engine_fish_textured(matrix, babylon):
    """The engine fish's Babylon.js cell is a known limit of asset containers (KNOWN_LIMITS): a scene
    loaded whole keeps the materials the levels share, and shows the finest level only."""
    result = babylon.append(matrix.assets["engine fish glb"])
    names = {m["path"].split("/")[0] for m in result["meshes"]}
    assert names == {"bonybream_LOD0"}
    assert result["settled"]
    materials = [m["material"] for m in result["meshes"]]
    assert all(m is not None and m["albedo"] and m["albedo"]["ready"] for m in materials)
    assert {m["name"] for m in materials} == {"bonybream_body", "bonybream_fins"}


def _without_clip(matrix, label: str, name: str, clip: str) -> Asset:
    """A copy of an engine row's .glb whose clip ``clip`` is renamed: every count still right."""
    from tests.clients.godot import read_glb, write_glb

    asset = _broken_copy(matrix, label, name)
    doc, blob = read_glb(asset.path)
    (anim,) = [a for a in doc["animations"] if a["name"] == clip]
    anim["name"] = f"{clip}_renamed"
    write_glb(asset.path, doc, blob)
    return asset


def test_three_fails_an_engine_fish_without_a_clip(matrix, three):
    asset = _without_clip(matrix, "engine fish glb", "engine no burst three", "burst")
    with pytest.raises(AssertionError, match=r"clips missing: \['burst'\]"):
        three.check(asset)


def test_babylon_fails_an_engine_fish_without_a_clip(matrix, babylon):
    asset = _without_clip(matrix, "engine fish glb", "engine no burst babylon", "burst")
    with pytest.raises(AssertionError, match=r"animation groups missing: \['burst'\]"):
        babylon.check(asset)


# Godot 3: every file it reads was imported into one project in one run (tests/clients/godot.py),
# the self-test's and the two-species files with them.

@pytest.fixture
def godot(matrix):
    run = matrix.godot()
    if run is None:
        pytest.skip(matrix._godot_error or "Godot unavailable")
    return run


def test_godot_fails_positions_it_reads_as_raw_integers(matrix, godot, gltf_validator):
    """Valid glTF (KHR_mesh_quantization: normalized 16-bit positions) that Godot 3.2 imports as
    ±32767 without a word: only the bounds catch it. Babylon.js reads the same file right, so
    the check is not merely refusing quantized files."""
    from tests.clients.godot import SELFTEST_QUANTIZED

    asset = godot.assets[SELFTEST_QUANTIZED]
    gltf_validator(asset.path)
    assert not godot.problems(asset)  # no error, no warning: the import "worked"
    with pytest.raises(AssertionError, match=r"surface 0 bounds \[-2\.3"):  # 32767 x the node's scale
        godot.check(asset)
    babylon = matrix.babylon()
    if babylon is not None:
        babylon.check(asset)


def test_godot_fails_a_clip_with_a_wrong_key(godot):
    """Counts are not enough: one morph weight key changed in the .bin fails the cell."""
    from tests.clients.godot import SELFTEST_KEY

    with pytest.raises(AssertionError, match="key weight off by"):
        godot.check(godot.assets[SELFTEST_KEY])


def test_godot_counts_every_blend_shape_track(matrix, godot):
    """A fish's swim in Godot: 4 transform tracks (the paired fins) and 36 blend shape tracks
    (9 meshes x 4 morph targets), each bound to a node and a property that exists."""
    result = godot.results[godot.files["fish glb"]]
    (swim,) = [a for a in result["animations"] if a["name"] == "swim"]
    kinds = [t["type"] for t in swim["tracks"]]
    assert (kinds.count(1), kinds.count(0)) == (4, 36)
    assert all(t["bound"] and t.get("property_exists", True) for t in swim["tracks"])


def test_godot_two_species_in_one_folder_keep_their_own_materials(godot):
    """`fishgen build bonybream.txt centroberyx.txt -o DIR --format glb`, DIR imported into Godot:
    each fish keeps its own skin and fin mode (centroberyx's fins blend, bonybream's are masked)."""
    from tests.clients.godot import TWO_SPECIES

    def materials(label: str) -> dict[str, dict]:
        result = godot.results[godot.files[label]]
        return {s["material"]["name"]: s["material"] for m in result["meshes"] for s in m["surfaces"]}

    bream, centro = materials(TWO_SPECIES[0]), materials(TWO_SPECIES[1])
    assert bream["bonybream_fins"]["alpha_scissor"] and not bream["bonybream_fins"]["transparent"]
    assert centro["centroberyx_fins"]["transparent"] and not centro["centroberyx_fins"]["alpha_scissor"]
    assert bream["bonybream_body"]["path"] != centro["centroberyx_body"]["path"]
