"""The renderer's GL context: one kept for a thread's renderers, and what each renderer frees."""
from __future__ import annotations

import gc
import os
import subprocess
import sys
import threading

import numpy as np
import pytest

from fishgen.authoring.photo.compare import side_camera
from fishgen.preview.render import Renderer
from tests.conftest import PARAMS

pytestmark = pytest.mark.usefixtures("gl_available")


@pytest.fixture(scope="module")
def species():
    from fishgen.species.parser import load_species

    return load_species(PARAMS / "bonybream.txt")


def drawn(renderer: Renderer, species, size=(96, 48)) -> np.ndarray:
    from fishgen.assembly.fish import build_fish

    scene = build_fish(species)
    return renderer.render(scene, side_camera(scene, *size), None, (0.0, 0.0, 0.0, 0.0))


def released(thing) -> bool:
    return type(thing.mglo).__name__ == "InvalidObject"


def gpu_objects(renderer: Renderer) -> list:
    meshes = [m for _, _, held in renderer._uploaded.values() for m in held]
    return ([thing for m in meshes for thing in (m.vao, m.vbo, m.static, m.ibo)]
            + [tex for _, tex in renderer._textures.values()])


def test_renderers_made_one_after_another_share_one_context_and_draw_as_a_new_context_does(species):
    first = Renderer(96, 48)
    try:
        picture = drawn(first, species)
    finally:
        first.release()
    second = Renderer(200, 100, samples=1)   # another size and sampling: the same context
    try:
        assert second.ctx is first.ctx and not released(second.ctx)
    finally:
        second.release()
    third = Renderer(96, 48)
    try:
        again = drawn(third, species)
    finally:
        third.release()
    elsewhere: list[np.ndarray] = []

    def on_a_thread() -> None:
        # another thread's renderer has a context of its own, made fresh, and freed with it
        renderer = Renderer(96, 48)
        try:
            assert renderer.ctx is not first.ctx
            elsewhere.append(drawn(renderer, species))
        finally:
            renderer.release()
        assert released(renderer.ctx)

    thread = threading.Thread(target=on_a_thread)
    thread.start()
    thread.join()
    assert picture[..., 3].any()
    np.testing.assert_array_equal(again, picture)
    np.testing.assert_array_equal(elsewhere[0], picture)


def test_a_released_renderer_frees_its_uploads_and_framebuffers_but_not_the_context(species):
    renderer = Renderer(96, 48)
    drawn(renderer, species)
    held = gpu_objects(renderer) + [renderer.msaa, renderer.resolved]
    assert len(held) > 2 and not any(map(released, held))
    renderer.release()
    assert all(map(released, held))
    assert not released(renderer.ctx) and not released(renderer.mesh_prog)


def test_a_scene_gone_is_freed_when_the_next_one_is_uploaded(species):
    from fishgen.assembly.fish import build_fish

    renderer = Renderer(96, 48)
    try:
        drawn(renderer, species)   # its scene is gone when drawn() returns
        gone = gpu_objects(renderer)
        gc.collect()
        assert not any(map(released, gone))   # until another scene is uploaded
        scene = build_fish(species)
        renderer.render(scene, side_camera(scene, 96, 48), None, (0.0, 0.0, 0.0, 0.0))
        assert all(map(released, gone))
        assert list(renderer._uploaded) == [id(scene)]
    finally:
        renderer.release()


def test_a_context_made_between_two_draws_does_not_take_the_renderer_s_place(species):
    import moderngl

    renderer = Renderer(96, 48)
    try:
        before = drawn(renderer, species)
        moderngl.create_context(standalone=True, backend="egl").release()   # as a GL probe does
        probe = moderngl.create_context(standalone=True, backend="egl")     # ... and one left current
        try:
            np.testing.assert_array_equal(drawn(renderer, species), before)
        finally:
            probe.release()
    finally:
        renderer.release()


def test_the_context_a_caller_had_current_is_current_again_after_a_render(species):
    """A library user's own GL work goes on in their context: a render must not leave fishgen's
    current, where the user's next calls (releasing a buffer by its name) would reach fishgen's."""
    import moderngl

    renderer = Renderer(96, 48)
    try:
        before = drawn(renderer, species)
        mine = moderngl.create_context(standalone=True, backend="egl")
        try:
            frame = mine.simple_framebuffer((4, 4))
            buffers = [mine.buffer(reserve=64) for _ in range(4)]   # names 1, 2, ...: as fishgen's
            drawn(renderer, species)
            frame.use()
            mine.clear(0.0, 0.0, 1.0, 1.0)
            assert frame.read(components=4)[:4] == bytes([0, 0, 255, 255])   # my blue, in my frame
            for buffer in buffers:
                buffer.release()
            np.testing.assert_array_equal(drawn(renderer, species), before)
        finally:
            mine.release()
    finally:
        renderer.release()


def test_a_renderer_is_used_in_the_thread_that_made_it():
    renderer = Renderer(16, 16)
    failed: list[BaseException] = []

    def elsewhere() -> None:
        try:
            renderer.finish()
        except BaseException as err:  # noqa: BLE001 - what the thread met is the test's
            failed.append(err)

    try:
        thread = threading.Thread(target=elsewhere)
        thread.start()
        thread.join()
    finally:
        renderer.release()
    assert isinstance(failed[0], RuntimeError) and "thread that made it" in str(failed[0])


def test_threads_that_draw_and_end_leave_no_gl_state_behind(species):
    def resident_mib() -> float:
        return int(open("/proc/self/statm").read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20

    def once() -> None:
        with Renderer(96, 48) as renderer:
            drawn(renderer, species)

    once_on_a_thread = [threading.Thread(target=once) for _ in range(21)]
    once_on_a_thread[0].start()
    once_on_a_thread[0].join()
    start = resident_mib()
    for thread in once_on_a_thread[1:]:
        thread.start()
        thread.join()
    # each thread's EGL state had stayed: 7.5 MiB a thread here
    assert resident_mib() - start < 20 * 2


def test_a_process_forked_after_drawing_is_refused_in_one_line_not_hung():
    code = """if True:
        import multiprocessing, sys
        from fishgen.errors import FishgenError
        from fishgen.preview.render import Renderer

        def child(_):
            try:
                Renderer(16, 16).release()
            except FishgenError as err:
                return str(err)
            return "drew"

        Renderer(16, 16).finish()
        with multiprocessing.get_context("fork").Pool(1) as pool:
            print(pool.map_async(child, [0]).get(60)[0])
    """
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("expected to draw in a process not forked from one that drew")


@pytest.mark.parametrize("size", [(-5, 10), (0, 16), (16.5, 16), (10**6, 16)])
def test_a_renderer_of_no_size_or_an_absurd_one_is_refused_before_any_gl(size):
    with pytest.raises(ValueError, match=r"^expected a renderer's width and height as whole numbers from 1 "):
        Renderer(*size)   # -5 x 10 had been "out of memory for a -5x10 framebuffer (-0 MiB ...)"
