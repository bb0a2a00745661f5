"""The CI fuzz run: the whole seed corpus plus a fixed-seed budget of generated inputs per target.

Every input must succeed (finite outputs) or raise FishgenError (the CLI: exit 2, one stderr
line, no traceback), within the worker's memory and time budget (docs/fuzzing.md). These
tests fail while any finding exists; each failure names the finding and its saved input
(out/fuzz-findings-ci/) and the command that replays it. The nightly runs the same harness
for longer: `python -m fishgen.fuzz --minutes 30`.
"""
from __future__ import annotations

import os
import random
import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fishgen.errors import FishgenError
from fishgen.fuzz import TARGETS, load_seeds, make_case, run
from fishgen.fuzz.cases import NEW_TARGETS, run_case
from fishgen.fuzz.inputs import DEFAULT_CORPUS, Case
from fishgen.fuzz.mutate import NUMBERS, pack_glb, unpack_glb
from fishgen.fuzz.verdict import classify

CI_SEED = 20240601
#: Inputs per target (the seed corpus comes first). About 25 s on 2 cores; rates in docs/fuzzing.md.
#: A smoke run that every push pays for: the long runs (`--minutes`, the 10^6 run) do the searching.
#: The dearest per input (cli 37 ms, editor 60 ms, gltf and obj 11 ms) were cut by 40-50 % in the
#: eleventh session, when the suite stood within 10 s of its 8 minutes.
CI_COUNTS = {"species": 1200, "cubes": 4000, "gltf": 900, "obj": 600, "ply": 900, "cli": 300,
             "scene": 600, "paths": 150, "manifest": 400, "fxl": 2000, "photo": 12, "awa": 300, "editor": 80,
             "options": 60}
#: The test command writes nothing into the user's out/: findings and work files go to a temporary
#: folder (FISHGEN_FUZZ_FINDINGS keeps CI's findings where a CI job can collect them).
WORK = Path(tempfile.mkdtemp(prefix="fishgen-fuzz-"))


@pytest.fixture(scope="session")   # not module: made once even if a worker's run of this file is split
def ci_report():
    findings = Path(os.environ.get("FISHGEN_FUZZ_FINDINGS", WORK / "findings"))
    return run(list(TARGETS), seed=CI_SEED, counts=CI_COUNTS, jobs=min(2, os.cpu_count() or 1),
               findings_dir=findings)


@pytest.mark.slow
@pytest.mark.parametrize("target", TARGETS)
def test_no_findings(ci_report, target):
    stats = ci_report.stats[target]
    assert stats.inputs == CI_COUNTS[target]
    found = [f for f in ci_report.findings.values() if f.target == target]
    assert not found, f"{len(found)} distinct finding(s) fuzzing {target}:\n" + "\n".join(
        f"  {f.key} (x{f.count}); input in {f.folder}; "
        f"replay: python -m fishgen.fuzz --replay {f.target}:{f.seed}:{f.index}" for f in found)


def test_seed_corpus_is_small_and_complete():
    seeds = load_seeds()
    assert len(seeds.species) >= 4 and len(seeds.cubes) >= 3
    assert all(len(v) >= 2 for v in seeds.assets.values())
    size = sum(p.stat().st_size for p in DEFAULT_CORPUS.rglob("*") if p.is_file())
    assert size < 2 << 20


def test_cases_are_reproducible():
    seeds = load_seeds()
    for target in TARGETS:
        for index in (0, 57, 1234):
            a, b = make_case(seeds, target, 7, index), make_case(seeds, target, 7, index)
            assert (a.text, a.data, a.files, a.argv, a.requests) == \
                (b.text, b.data, b.files, b.argv, b.requests)


def test_seed_cases_are_the_corpus_verbatim():
    seeds = load_seeds()
    assert make_case(seeds, "species", 1, 0).text == seeds.species[0]
    main, files = seeds.assets["gltf"][0]
    assert make_case(seeds, "gltf", 1, 0).files == files


def test_glb_round_trip():
    main, files = next((m, f) for m, f in load_seeds().assets["gltf"] if m.endswith(".glb"))
    doc, blob = unpack_glb(files[main])  # type: ignore[arg-type]
    again = unpack_glb(pack_glb(doc, blob))
    assert again[0] == doc and again[1][: len(blob)] == blob


def test_the_judge_flags_what_it_should():
    """The harness itself: FishgenError passes, anything else (or a hidden MemoryError) is a finding."""
    assert classify(FishgenError("expected x, found y", "f", 1)).status == "error"
    try:
        [][1]
    except IndexError as err:
        assert classify(err).status == "finding"
    try:
        try:
            raise MemoryError
        except MemoryError:
            raise FishgenError("not a readable glTF asset (MemoryError: )") from None
    except FishgenError as err:
        assert classify(err).key.startswith("budget overrun (memory)")
    bad_cli = Case("cli", 0, argv=["build", "missing.txt", "--fps", "nan"])
    assert run_case(bad_cli, WORK / "selftest").status == "error"


# Property-based generation (hypothesis) over the two text parsers, in-process: records of
# interesting tokens in the layout of the real files.
_token = st.one_of(st.sampled_from(NUMBERS), st.text(max_size=6),
                   st.floats(allow_nan=True, allow_infinity=True).map(repr))


@settings(max_examples=300, deadline=None, suppress_health_check=list(HealthCheck), derandomize=True)
@given(st.data())
def test_species_parser_hypothesis(data):
    seeds = load_seeds()
    lines = random.Random(0).choice(seeds.species).split("\n")
    k = data.draw(st.integers(0, len(lines) - 1))
    tokens = lines[k].split() or [""]
    i = data.draw(st.integers(0, len(tokens) - 1))
    tokens[i] = data.draw(_token)
    lines[k] = " ".join(tokens)
    outcome = run_case(Case("species", 0, text="\n".join(lines)), WORK / "selftest")
    assert outcome.status != "finding", outcome.detail


@settings(max_examples=300, deadline=None, suppress_health_check=list(HealthCheck), derandomize=True)
@given(st.lists(st.lists(_token, min_size=1, max_size=9), min_size=0, max_size=6),
       st.sampled_from([", ", " ", ","]))
def test_cubes_parser_hypothesis(rows, sep):
    text = "\n".join(sep.join(r) for r in rows)
    outcome = run_case(Case("cubes", 0, data=text.encode("utf-8", "surrogatepass")), WORK / "cubes")
    assert outcome.status != "finding", outcome.detail


def test_new_targets_replay_their_seeds_first():
    """Issue 26's targets start from the repository's own files: the first cases are the seeds verbatim."""
    seeds = load_seeds()
    assert make_case(seeds, "scene", 1, 0).files["scene.toml"] == seeds.new["scene"]["bait-ball.toml"]
    assert make_case(seeds, "manifest", 1, 0).files["assets.toml"] == seeds.new["manifest"]["assets.toml"]
    assert make_case(seeds, "awa", 1, 0).files["sky.awa"] == seeds.new["awa"]["sky.awa"]
    assert make_case(seeds, "paths", 1, 0).files["path.csv"] == seeds.new["scene"]["path.csv"]
    for target in NEW_TARGETS:
        assert run_case(make_case(seeds, target, 1, 0), WORK / "seeds").status != "finding", target


def test_the_editor_judge(monkeypatch):
    """A request the server refuses passes; an exception escaping the handler is a finding, and so is
    a file written outside the editor's folder."""
    from fishgen.editor.session import Session

    lists = b"GET /api/lists?token={TOKEN} HTTP/1.1\r\nHost: 127.0.0.1:{PORT}\r\n\r\n"
    bad_token = b"GET /api/lists?token=x HTTP/1.1\r\nHost: 127.0.0.1:{PORT}\r\n\r\n"
    files: dict[str, bytes | int] = {"small.awn": load_seeds().new["awa"]["small.awn"]}

    def judge(request: bytes):
        return run_case(Case("editor", 0, files=files, main="small.awn", requests=[request]), WORK / "editor")

    assert judge(lists).status == "ok" and judge(bad_token).status == "ok"

    def escaping(self, request):
        raise ValueError("a bug")

    monkeypatch.setattr(Session, "lists", escaping)
    assert judge(lists).key.startswith("editor: ValueError escaped the handler")

    def writing_outside(self, request):
        (self.workspace.folder.parent / "stray.awn").write_text("1\n")
        return Response.of_json({})

    from fishgen.web.server import Response
    monkeypatch.setattr(Session, "lists", writing_outside)
    assert judge(lists).key == "editor: a file written outside the editor's folder"
    assert judge(bad_token).status == "ok"  # refused before the route: nothing written


def test_a_worker_near_its_memory_budget_is_replaced_and_no_case_is_lost(tmp_path):
    """With the headroom as large as the budget every worker retires after each batch: the run still
    covers every input, finds nothing, and says how many workers it replaced."""
    report = run(["species", "cubes"], seed=3, counts={"species": 250, "cubes": 250}, jobs=1,
                 findings_dir=tmp_path, budget_mb=1536, headroom_mb=1536)
    assert report.stats["species"].inputs == 250 and report.stats["cubes"].inputs == 250
    assert report.findings == {} and report.retired >= 4


def test_a_case_is_timed_by_its_cpu_not_by_the_machines_load():
    """A worker that waited three times its limit in wall time is not hung, nor one that waited a
    minute for a core (a niced run on a busy machine); one past its limit in CPU seconds is, and
    one sleeping past WALL_FACTOR times its limit is too."""
    import subprocess
    import sys
    import time

    from fishgen.fuzz.runner import GRACE, WALL_FACTOR, _clock, _hung

    sleeper = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(30)"])
    try:
        time.sleep(0.5)     # past the interpreter's start
        limit, now = 2.0, time.monotonic()
        clock = _clock(sleeper.pid)
        assert clock is not None
        cpu, waited = clock
        long_ago = now - WALL_FACTOR * limit - GRACE - 1
        assert not _hung(sleeper.pid, [0, now - 3 * limit, cpu, waited], now, limit)
        assert not _hung(sleeper.pid, [0, long_ago - 60, cpu, waited - 62], now, limit)
        assert _hung(sleeper.pid, [0, now - 3 * limit, cpu - limit - GRACE - 1, waited], now, limit)
        assert _hung(sleeper.pid, [0, long_ago, cpu, waited], now, limit)
    finally:
        sleeper.kill()
        sleeper.wait()
    before = _clock()
    end = time.process_time() + 0.3
    while time.process_time() < end:
        pass
    after = _clock()
    assert before is not None and after is not None and after[0] - before[0] >= 0.2


def test_a_replayed_case_shows_what_the_input_got(capsys):
    """It printed "error: " and a blank line: the refusal's own message is what one replays for."""
    from fishgen.fuzz.__main__ import replay
    from fishgen.fuzz.inputs import DEFAULT_CORPUS

    assert replay("species:1:5", DEFAULT_CORPUS) == 0
    shown = capsys.readouterr().out
    assert shown.startswith("species case 5 of seed 1: refused in one line: <fuzz>:") and "expected" in shown


def test_the_photo_target_makes_jpegs_as_cameras_save_them():
    """A photo's JPEG decoding and its 4:2:0 colour drawn again at full size are fuzzed: about one
    photo in seven is a JPEG (one in two hundred was), most in colour at half size."""
    import io
    from collections import Counter

    from PIL import Image, JpegImagePlugin

    from fishgen.fuzz.structured import photo_bytes

    seed = next(p for p in sorted((DEFAULT_CORPUS / "photo").rglob("*.png"))).read_bytes()
    rng = random.Random(3)
    kinds: Counter[str] = Counter()
    for _ in range(300):
        try:
            with Image.open(io.BytesIO(photo_bytes(seed, rng))) as im:
                if im.format == "JPEG":
                    kinds[f"{im.mode} {JpegImagePlugin.get_sampling(im)}"] += 1
        except Exception:   # truncated or changed bytes: the reader's to refuse
            pass
    assert sum(kinds.values()) >= 20 and kinds["RGB 2"] >= 4 and kinds["RGB 0"] >= 1, kinds


def test_a_fuzzed_jpeg_is_saved_as_a_camera_or_an_editor_might():
    """Every mode JPEG holds, every sampling of its colour, progressive or not, turned by EXIF or
    not; a photo with alpha loses it, as a JPEG must."""
    import io

    from PIL import Image, JpegImagePlugin

    from fishgen.fuzz.structured import _as_jpeg

    rng = random.Random(5)
    seen: dict[str, set] = {"mode": set(), "sampling": set(), "progressive": set(), "turned": set()}
    for _ in range(200):
        im, options = _as_jpeg(Image.new("RGBA", (17, 9), (200, 120, 40, 128)), rng)
        buf = io.BytesIO()
        im.save(buf, "JPEG", **options)
        with Image.open(buf) as back:
            seen["mode"].add(back.mode)
            seen["progressive"].add(bool(back.info.get("progressive")))
            seen["turned"].add(0x0112 in back.getexif())
            if back.mode == "RGB":
                seen["sampling"].add(JpegImagePlugin.get_sampling(back))
    assert seen == {"mode": {"RGB", "L", "CMYK"}, "sampling": {0, 1, 2}, "progressive": {False, True},
                    "turned": {False, True}}
