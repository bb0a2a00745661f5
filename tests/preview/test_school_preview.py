"""Previewing a school file: it starts after the warm-up the file records, --time wins, a bar counts
the frames, and the whole-scene posing the renderer uses equals `fishgen.scene.pose`."""
from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from tests.conftest import PARAMS, run_cli

pytestmark = pytest.mark.usefixtures("gl_available")
WARMUP = 1.0
LOOP = ("--size", "96x72", "--frames", "3", "--duration", "0.5", "--view", "top")


@pytest.fixture(scope="module")
def school(tmp_path_factory):
    """Six fish swimming 3 s, of which the first second is warm-up (recorded in the file)."""
    out = tmp_path_factory.mktemp("school") / "school.glb"
    result = run_cli("school", PARAMS / "bonybream.txt", "--count", "6", "--frames", "90", "--fps", "30",
                     "--warmup", str(WARMUP), "-o", out, "--quiet")
    assert result.returncode == 0, result.stderr
    return out


def _frames(path) -> list[np.ndarray]:
    img = Image.open(path)
    out = []
    for k in range(getattr(img, "n_frames", 1)):
        img.seek(k)
        out.append(np.asarray(img.convert("RGB"), np.int16))
    return out


def _preview(school, out, *args) -> list[np.ndarray]:
    result = run_cli("preview", school, "-o", out, *args)
    assert result.returncode == 0, result.stderr
    return _frames(out)


def test_a_school_loop_starts_after_its_warmup(school, tmp_path):
    default = _preview(school, tmp_path / "default.gif", *LOOP)
    after = _preview(school, tmp_path / "after.gif", *LOOP, "--time", str(WARMUP))
    start = _preview(school, tmp_path / "start.gif", *LOOP, "--time", "0")
    assert all(np.array_equal(a, b) for a, b in zip(default, after, strict=True))
    assert np.abs(default[0] - start[0]).max() > 40  # the fish stand elsewhere at 0 s


def test_a_school_still_is_posed_after_its_warmup_and_time_overrides(school, tmp_path):
    still = ("--size", "96x72", "--view", "top")
    default = _preview(school, tmp_path / "default.png", *still)[0]
    after = _preview(school, tmp_path / "after.png", *still, "--time", str(WARMUP))[0]
    later = _preview(school, tmp_path / "later.png", *still, "--time", "2.5")[0]
    assert np.array_equal(default, after)
    assert np.abs(default - later).max() > 40


def test_the_progress_bar_counts_each_frame_once(school, tmp_path):
    from fishgen.commands import Events
    from fishgen.commands.preview import PreviewCommandOptions, preview
    from tests.progress_bars import recorded_bars

    bars, progress = recorded_bars()
    options = PreviewCommandOptions(size=(64, 48), frames=5, view="top")
    preview([school], tmp_path / "loop.gif", options, Events(progress=progress))
    assert bars == [("rendering", 5, [1, 1, 1, 1, 1])]


def test_whole_scene_posing_equals_pose_and_deformed(school):
    from fishgen.preview.inputs import load_input
    from fishgen.preview.posing import Poser, batches
    from fishgen.scene.pose import deformed, pose

    scene = load_input(school)
    poser, shared = Poser(scene), batches(scene)
    assert any(b.instances > 1 for b in shared)  # the fish share their meshes: one draw each
    for t in (None, 0.0, 0.37, 1.5, 99.0):  # rest, the first key, between keys, past the last
        fast, slow = poser(t), pose(scene, t)
        assert np.allclose(np.stack(fast.world), np.stack(slow.world), atol=1e-12)
        assert fast.weights.keys() == slow.weights.keys()
        for batch in shared:
            pos, nrm = batch.world(scene, fast)
            each = [deformed(scene, int(n), batch.prim, slow) for n in batch.nodes]
            assert np.allclose(pos, np.concatenate([p for p, _ in each]), atol=1e-9)
            assert nrm is not None and np.allclose(nrm, np.concatenate([q for _, q in each]), atol=1e-9)
