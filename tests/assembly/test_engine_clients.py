"""The issue's fish as three.js, Babylon.js, Godot 3 and Blender play it: the finest level only, each
clip as fishgen poses it, and bent bodies shaded bent (normals within 5 degrees of the posed
surface's own, at times between the keys, where targets blend).

    fishgen build params/bonybream.txt --lods 32x24,16x12,8x6 --merge \
        --clips swim,idle,turn_left,turn_right,burst

three.js and Babylon.js run in the client matrix's headless Chromium, Godot 3 is Debian's
godot3-server, and Blender needs a Python with PyPI's `bpy` ($FISHGEN_BPY_PYTHON or
/tmp/bpyvenv/bin/python). Each is skipped where it is missing.
"""
from __future__ import annotations

import numpy as np
import pytest

from fishgen.assembly.fish import make_fish
from fishgen.exchange import export
from fishgen.species.parser import load_species
from tests.assembly import engine_clients as ec
from tests.clients.babylon import babylon_unavailable
from tests.clients.godot import godot_unavailable
from tests.clients.matrix import three_unavailable
from tests.conftest import PARAMS

LODS = ((32, 24), (16, 12), (8, 6))
CLIPS = ("swim", "idle", "turn_left", "turn_right", "burst")
NORMAL_LIMIT = 5.0


@pytest.fixture(scope="module")
def engine_folder(tmp_path_factory):
    """Where both layouts of the fish are written (merged/fish.glb, parts/fish.glb): one page of each
    browser client serves them both."""
    return tmp_path_factory.mktemp("engine")


@pytest.fixture(scope="module", params=[True, False], ids=["merged", "parts"])
def fish(request, engine_folder):
    """The fish, and the folder of its fish.glb (under :func:`engine_folder`)."""
    made = make_fish(load_species(PARAMS / "bonybream.txt"), lods=LODS, merge=request.param, clips=CLIPS)
    folder = engine_folder / ("merged" if request.param else "parts")
    folder.mkdir(exist_ok=True)
    export(made.scene, folder / "fish.glb")
    return made, folder


def _file(fish) -> str:
    """The fish's .glb as the browser clients ask for it (under :func:`engine_folder`)."""
    return f"{fish[1].name}/fish.glb"


@pytest.fixture(scope="module")
def three(engine_folder):
    reason = three_unavailable()
    if reason:
        pytest.skip(reason)
    client = ec.ThreeEngine(engine_folder)
    yield client
    client.close()


@pytest.fixture(scope="module")
def babylon(engine_folder):
    reason = babylon_unavailable()
    if reason:
        pytest.skip(reason)
    client = ec.BabylonEngine(engine_folder)
    yield client
    client.close()


@pytest.fixture(scope="module")
def godot(fish, tmp_path_factory):
    """Every clip as Godot 3 plays it, imported as its import dock does by default (normals packed in
    bytes) and with Meshes > Compress off."""
    reason = godot_unavailable()
    if reason:
        pytest.skip(reason)
    made, folder = fish
    clips = {c: _between_keys(made.scene, c) for c in CLIPS}
    return ec.godot_play(folder / "fish.glb", clips, tmp_path_factory.mktemp("godot"), (True, False))


@pytest.fixture(scope="module")
def blender_shading(fish):
    if ec.BPY is None:
        pytest.skip("no Python with bpy ($FISHGEN_BPY_PYTHON)")
    made, folder = fish
    clips = {c: _between_keys(made.scene, c) for c in CLIPS}
    return ec.blender_play(folder / "fish.glb", clips, np.zeros((0, 3)), shading=True)


def _times(scene, clip, count=25):
    return np.linspace(0.0, scene.clip(clip).duration, count)


def _between_keys(scene, clip, count=16):
    """Times off the keys (a key holds a single target at full weight): every one a blend."""
    return (np.arange(count) + 0.37) / count * scene.clip(clip).duration


def _is_fins(name: str) -> bool:
    """A Godot surface (``node path/surface#mesh``) of fins: a fin's node, or a merged fish's second."""
    *path, surface = name.split("#")[0].split("/")
    return "_fin" in path[-1] or surface == "1"


def _measures(probes: ec.Probes, tracks: np.ndarray, times: np.ndarray) -> dict[str, float]:
    p = probes.split(tracks)
    curvature = ec.bend_curvature(p["midline"], probes.length)
    return {"tail": ec.peak_to_peak(p["tail"], probes.length), "hz": ec.frequency(p["tail"], times),
            "bend": float(curvature.max()), "bend_min": float(curvature.min()),
            "fin": float(np.ptp(ec.fin_swing(p["fin_tip"], p["fin_base"])))}


@pytest.mark.parametrize("clip", CLIPS)
def test_three_js_plays_each_clip_as_fishgen_poses_it(fish, three, clip):
    made, _ = fish
    scene = made.scene
    probes = ec.probes(scene)
    times = _times(scene, clip)
    ours = ec.fishgen_play(scene, clip, times, probes.all())
    theirs = three.play(_file(fish), clip, times, probes.all())
    assert [c["name"] for c in three.last["clips"]] == list(CLIPS)
    assert len(theirs.meshes) == (2 if made.facts.merged else 9)            # the finest level only
    a, b = _measures(probes, ours.probes, times), _measures(probes, theirs.probes, times)
    print(clip, {k: f"{a[k]:.3f}/{b[k]:.3f}" for k in a})
    assert np.abs(ours.probes - theirs.probes).max() < 1e-3 * probes.length
    assert b["tail"] == pytest.approx(a["tail"], rel=0.01) and b["fin"] == pytest.approx(a["fin"], abs=0.2)


@pytest.mark.parametrize("clip", CLIPS)
def test_bent_bodies_are_shaded_bent_in_three_js_and_in_fishgen(fish, three, clip):
    """The normals a client computes from the file (morph NORMAL deltas, then the skin) against the
    normals of the posed triangles themselves, at every vertex, over the clip."""
    made, _ = fish
    times = _between_keys(made.scene, clip)
    worst = {}
    for who, played in (("fishgen", ec.fishgen_play(made.scene, clip, times, np.zeros((0, 3)))),
                        ("three.js", three.play(_file(fish), clip, times, np.zeros((0, 3))))):
        worst.update({(who, name): v for name, v in ec.worst_normal_error(played).items()})
    print(clip, {k: f"{v:.2f}" for k, v in worst.items()})
    assert max(worst.values()) < NORMAL_LIMIT


@pytest.mark.parametrize("clip", CLIPS)
def test_babylon_js_shades_bent_bodies_bent(fish, babylon, clip):
    """Babylon's own CPU morphing and skinning of the finest level (getPositionData/getNormalsData)."""
    made, _ = fish
    played = babylon.play(_file(fish), clip, _between_keys(made.scene, clip))
    assert len(played.meshes) == (2 if made.facts.merged else 9)
    worst = ec.worst_normal_error(played)
    print(clip, {k: f"{v:.2f}" for k, v in worst.items()})
    assert max(worst.values()) < NORMAL_LIMIT


@pytest.mark.parametrize("clip", CLIPS)
def test_godot_3_shades_bent_bodies_bent_with_mesh_compression_off(fish, godot, clip):
    """Every surface of every level (Godot 3 shows them all), as its player poses them."""
    worst = ec.worst_normal_error(godot[False][clip])
    print(clip, {k: f"{v:.2f}" for k, v in worst.items()})
    assert len(worst) >= 6 and max(worst.values()) < NORMAL_LIMIT


@pytest.mark.parametrize("clip", CLIPS)
def test_godot_3_shades_bent_bodies_bent_as_imported_by_default(fish, godot, clip):
    """With the import's default compression the body's normals lose only their byte rounding."""
    worst = ec.worst_normal_error(godot[True][clip])
    body = {k: v for k, v in worst.items() if not _is_fins(k)}
    print(clip, {k: f"{v:.2f}" for k, v in worst.items()})
    assert body and max(body.values()) < NORMAL_LIMIT


@pytest.mark.xfail(strict=True, reason="Godot 3 packs normals in bytes and clamps each component to "
                   "[-1, 1]: the exact morph normals of fins riding the body reach 2.5 (docs/decisions.md)")
def test_godot_3_default_import_shades_riding_fins_bent(fish, godot):
    worst = {}
    for clip in CLIPS:
        for k, v in ec.worst_normal_error(godot[True][clip]).items():
            if _is_fins(k):
                worst[k] = max(worst.get(k, 0.0), v)
    print({k: f"{v:.2f}" for k, v in worst.items()})
    assert max(worst.values()) < NORMAL_LIMIT


def _blender_body(report) -> dict[str, np.ndarray]:
    """The body's vertices but the two where its rings close (nose and tail tips: a fan of one
    triangle per circle section), by mesh."""
    out = {}
    for name, (faces, _, _) in report["shading"]["__rest__"].meshes.items():
        fans = np.bincount(faces.ravel(), minlength=len(report["fins"][name]))
        out[name] = ~report["fins"][name] & (fans <= 8)
    return out


@pytest.mark.parametrize("clip", CLIPS)
def test_blender_shades_bent_bodies_bent(blender_shading, clip):
    """Blender's evaluated mesh (shape keys, then the armature) and its corner normals: Blender keeps
    no morph normals, but carries the file's in its smooth-fan spaces, which bend with the body."""
    rest = ec.worst_normal_error(blender_shading["shading"]["__rest__"])
    assert max(rest.values()) < 1.0                            # the file's normals, as imported
    body = _blender_body(blender_shading)
    assert sum(int(b.sum()) for b in body.values()) > 600
    worst = ec.worst_normal_error(blender_shading["shading"][clip], body)
    print(clip, {k: f"{v:.2f}" for k, v in worst.items()})
    assert max(worst.values()) < NORMAL_LIMIT


@pytest.mark.xfail(strict=True, reason="Blender keeps no morph normals: the nose and tail tips and the "
                   "fins riding the body are shaded by its smooth-fan spaces, up to 53 degrees off "
                   "(docs/decisions.md)")
def test_blender_shades_fins_and_tips_bent(blender_shading):
    worst = {}
    for clip in CLIPS:
        for k, v in ec.worst_normal_error(blender_shading["shading"][clip]).items():
            worst[k] = max(worst.get(k, 0.0), v)
    print({k: f"{v:.2f}" for k, v in worst.items()})
    assert max(worst.values()) < NORMAL_LIMIT
