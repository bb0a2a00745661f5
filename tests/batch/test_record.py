"""Incremental runs: a job runs again exactly when a file it reads, its options or its output changed."""
from __future__ import annotations

import json
import os
import subprocess
import sys

from PIL import Image

from tests.batch.conftest import batch, hashes, record, statuses
from tests.conftest import ROOT

FISH = {"fish/bonybream.glb", "fish/centroberyx.glb", "fish/pineapplefish.glb", "fish/threadfingoldie.glb"}
CLOUDS = {"clouds/table_4_2.glb", "clouds/table_4_3.glb", "clouds/table_4_4.glb", "clouds/sky.glb"}
ALL = FISH | CLOUDS | {"schools/reef.glb"}


def rebuilt(run) -> set[str]:
    assert run.returncode == 0, run.stderr
    found = statuses(run.stdout)
    assert set(found) == ALL, run.stdout
    return {name for name, status in found.items() if status == "built"}


def test_the_example_builds_everything_valid_and_a_second_run_skips_everything(shipped, gltf_validator):
    manifest, out = shipped / "params" / "assets.toml", shipped / "out" / "assets"
    assert rebuilt(batch(manifest, "-j", "2")) == ALL
    gltf_validator(*sorted(out.rglob("*.glb")))
    first = hashes(out)
    assert set(first) == ALL
    entries = record(out)
    assert set(entries) == ALL and all(entries[n]["outputs"][n] == first[n] for n in ALL)
    # The species' textures and the school's species are recorded as inputs too.
    assert "../../textures/bonybream.png" in entries["fish/bonybream.glb"]["inputs"]
    school_inputs = set(entries["schools/reef.glb"]["inputs"])
    assert {"../../params/reef.toml", "../../params/bonybream.txt",
            "../../textures/threadfingoldie_mask.png"} <= school_inputs
    assert rebuilt(batch(manifest)) == set()
    assert hashes(out) == first


def test_deciding_that_nothing_changed_imports_no_numpy(shipped):
    """What keeps a no-change rerun of 100 jobs well under a second: no library is loaded."""
    manifest = shipped / "params" / "assets.toml"
    batch(manifest, "-j", "2")
    run = subprocess.run([sys.executable, "-X", "importtime", "-m", "fishgen", "batch", str(manifest)],
                         cwd=ROOT, capture_output=True, text=True)
    assert run.returncode == 0 and set(statuses(run.stdout).values()) == {"skipped"}
    imported = {line.split("|")[-1].strip() for line in run.stderr.splitlines() if "|" in line}
    assert not imported & {"numpy", "trimesh", "pygltflib", "PIL", "scipy"}


def test_editing_a_species_file_rebuilds_exactly_the_jobs_that_read_it(shipped):
    manifest, out = shipped / "params" / "assets.toml", shipped / "out" / "assets"
    batch(manifest, "-j", "2")
    before = hashes(out)
    species = shipped / "params" / "bonybream.txt"
    species.write_text(species.read_text() + "// edited\n")  # a comment: new content, same fish
    assert rebuilt(batch(manifest, "-j", "2")) == {"fish/bonybream.glb", "schools/reef.glb"}
    assert hashes(out) == before  # the same inputs that matter: byte-identical outputs
    os.utime(shipped / "params" / "centroberyx.txt")  # a new time, the same content: nothing to do
    assert rebuilt(batch(manifest)) == set()


def test_editing_a_texture_rebuilds_the_species_and_the_school_that_show_it(shipped):
    manifest = shipped / "params" / "assets.toml"
    batch(manifest, "-j", "2")
    texture = shipped / "textures" / "threadfingoldie.png"
    with Image.open(texture) as image:
        image = image.copy()
    image.putpixel((0, 0), (255, 0, 255) if image.mode == "RGB" else image.getpixel((1, 1)))
    image.save(texture)
    assert rebuilt(batch(manifest)) == {"fish/threadfingoldie.glb", "schools/reef.glb"}


def test_a_removed_or_damaged_output_is_rebuilt_and_force_rebuilds_all(shipped):
    manifest, out = shipped / "params" / "assets.toml", shipped / "out" / "assets"
    batch(manifest, "-j", "2")
    good = hashes(out)
    (out / "clouds" / "table_4_2.glb").unlink()
    with open(out / "fish" / "pineapplefish.glb", "r+b") as handle:
        handle.write(b"junk")
    assert rebuilt(batch(manifest)) == {"clouds/table_4_2.glb", "fish/pineapplefish.glb"}
    assert hashes(out) == good
    assert rebuilt(batch(manifest, "--force")) == ALL
    assert hashes(out) == good


def test_changed_options_rebuild_the_job_and_a_damaged_record_rebuilds_everything(shipped):
    manifest, out = shipped / "params" / "assets.toml", shipped / "out" / "assets"
    batch(manifest, "-j", "2")
    manifest.write_text(manifest.read_text().replace('output = "fish/bonybream.glb"',
                                                     'output = "fish/bonybream.glb"\nfins = "opaque"'))
    assert rebuilt(batch(manifest)) == {"fish/bonybream.glb"}
    (out / ".fishgen-batch.json").write_text("{not json")
    assert rebuilt(batch(manifest, "-j", "2")) == ALL
    assert set(record(out)) == ALL


def test_a_job_built_with_other_library_versions_runs_again(tmp_path):
    """Pillow 10.4 and 13.0 drew one random species' texture 15 pixels apart: a record holding
    fishgen's version alone kept the old picture after an upgrade."""
    from fishgen.batch.record import library_versions

    (tmp_path / "cube.awn").write_bytes((ROOT / "params" / "clouds" / "table_4_3.awn").read_bytes())
    manifest = tmp_path / "assets.toml"
    manifest.write_text('out = "out"\n\n[[clouds]]\ninput = "cube.awn"\noutput = "cloud.ply"\n')
    out = tmp_path / "out"
    assert statuses(batch(manifest).stdout) == {"cloud.ply": "built"}
    entry = record(out)["cloud.ply"]
    assert entry["libraries"] == library_versions() and "numpy" in entry["libraries"]
    assert statuses(batch(manifest).stdout) == {"cloud.ply": "skipped"}
    whole = json.loads((out / ".fishgen-batch.json").read_text())
    whole["jobs"]["cloud.ply"]["libraries"]["numpy"] = "1.0"
    (out / ".fishgen-batch.json").write_text(json.dumps(whole))
    again = batch(manifest, "--verbose")
    assert statuses(again.stdout) == {"cloud.ply": "built"}
    assert f"numpy 1.0 built it, this is {library_versions()['numpy']}" in again.stdout
