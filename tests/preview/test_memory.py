"""A preview too big for memory is refused before anything is drawn, and one the driver cannot hold
past the estimate is the system's refusal (exit 1), not bad input."""
from __future__ import annotations

import pytest

import fishgen.preview.memory as memory
from fishgen.errors import SystemFailure, UsageError
from fishgen.memory import ADDRESS_SPACE
from tests.conftest import PARAMS

AVAILABLE = "the memory this machine has available"

# Whole `fishgen preview params/bonybream.txt` runs (2026-12-05), KiB: (W, H, held pixels) ->
# (resident peak, address-space peak or None where not measured).
MEASURED = {(256, 256, 0): (133_132, 836_348), (2048, 2048, 0): (325_368, 996_284),
            (4096, 4096, 0): (916_768, 1_587_756), (8192, 8192, 0): (3_282_472, None),
            (1024, 1024, 60 * 1024 * 1024): (792_580, None),          # --frames 60 -o .gif
            (2048, 2048, 30 * 2048 * 2048): (1_537_148, None)}        # --frames 30 -o .gif


# `fishgen preview params/clouds/table_4_4.awn --size 4096x4096` (2026-12-05): particles are blended
# in 16-bit colour
MEASURED_FINE = {(4096, 4096, 0): (1_381_668, 2_054_248)}


def test_the_estimate_is_above_what_a_preview_of_particles_peaks_at():
    for (w, h, held), (resident, address) in MEASURED_FINE.items():
        got = memory.estimate(w, h, held, fine=True)
        assert resident * 1024 < got[0] < 1.4 * resident * 1024
        assert address * 1024 < got[1] < 1.4 * address * 1024


def test_the_estimate_is_above_what_a_preview_peaks_at():
    """It errs high, by less than 40 %."""
    for (w, h, held), (resident, address) in MEASURED.items():
        got = memory.estimate(w, h, held)
        assert resident * 1024 < got[0] < 1.4 * resident * 1024, (w, h, held)
        if address is not None:
            assert address * 1024 < got[1] < 1.4 * address * 1024, (w, h, held)


def test_a_preview_over_the_address_space_limit_is_refused_before_it_is_drawn(tmp_path, monkeypatch):
    """`ulimit -v 2500000` and an 8192x8192 still: the GL driver failed after the model was loaded,
    as bad input (exit 2)."""
    from fishgen.commands import command, run

    monkeypatch.setattr(memory, "allowed", lambda: (int(2.4 * 2**30), ADDRESS_SPACE))
    preview = command("preview")
    with pytest.raises(UsageError, match=r"fits in 2\.4 GiB \(this process's address-space limit\), found "
                                         r"8192x8192, which needs about 4\.1 GiB"):
        run(preview, (PARAMS / "bonybream.txt",), tmp_path / "big.png", preview.options(size=(8192, 8192)))
    assert not (tmp_path / "big.png").exists()


def test_the_resident_estimate_is_what_available_memory_is_compared_with(monkeypatch):
    """The driver maps 830 MiB it never touches: a small still runs where 500 MiB are free."""
    monkeypatch.setattr(memory, "allowed", lambda: (500 * 2**20, AVAILABLE))
    memory.check_fits(800, 600, 0)
    with pytest.raises(UsageError, match=r"holding 629,145,600 pixels of frames"):
        memory.check_fits(1024, 1024, 600 * 1024 * 1024)


def test_a_framebuffer_the_driver_cannot_make_is_the_system_s_refusal(monkeypatch):
    import moderngl

    from fishgen.preview.render import Renderer

    def refuse(*args, **kwargs):
        raise moderngl.Error("the framebuffer is not complete")

    monkeypatch.setattr(moderngl.Context, "renderbuffer", refuse)
    with pytest.raises(SystemFailure, match=r"^out of memory for a 64x64 framebuffer") as err:
        Renderer(64, 64)
    assert err.value.status == 1 and err.value.kind == "os"
