"""Capped reads take what a file holds, never the cap: a small file under a tight address-space limit
(a fuzz worker's, a container's) still reads."""
from __future__ import annotations

import io
import subprocess
import sys

import pytest

from fishgen.reading import read_capped, unheeded


def test_a_file_under_the_cap_is_read_whole_and_one_over_says_so(tmp_path):
    small = tmp_path / "s.txt"
    small.write_bytes(b"x" * 100)
    with small.open("rb") as handle:
        assert read_capped(handle, 1000) == b"x" * 100
    with small.open("rb") as handle:
        assert len(read_capped(handle, 50)) == 51      # one byte over: too big
    assert read_capped(io.BytesIO(b"abc"), 10) == b"abc"   # no descriptor


@pytest.mark.skipif(sys.platform != "linux", reason="RLIMIT_AS as Linux has it")
def test_reading_a_small_file_reserves_no_more_than_it_holds(tmp_path):
    """Under an address-space limit only 256 MiB above what the interpreter holds, a 1 KB file read
    with a 1 GiB cap: read(cap + 1) would ask for the whole GiB first and fail."""
    small = tmp_path / "s.txt"
    small.write_bytes(b"y" * 1024)
    script = (
        "import resource, sys\n"
        "from fishgen.reading import read_capped\n"
        "used = int(open('/proc/self/statm').read().split()[0]) * resource.getpagesize()\n"
        "resource.setrlimit(resource.RLIMIT_AS, (used + (256 << 20), used + (256 << 20)))\n"
        f"data = read_capped(open({str(small)!r}, 'rb'), 1 << 30)\n"
        "print(len(data))\n")
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert done.returncode == 0 and done.stdout.strip() == "1024", done.stderr


def test_only_pillows_tag_reader_goes_unsaid():
    """Warnings from Pillow's EXIF and TIFF tag reader (a damaged EXIF block: "Corrupt EXIF data",
    "Tag data larger than file", ...) are not said, by the command line or as a batch job's note;
    any other warning is, Pillow's others too."""
    reader = "/usr/lib/python3/site-packages/PIL/TiffImagePlugin.py"
    assert unheeded(UserWarning, reader)     # whatever it says: "Corrupt EXIF data", "Tag data larger…"
    assert not unheeded(UserWarning, "/x/fishgen/clouds/parser.py")        # a cube file's warning
    assert not unheeded(UserWarning, "/usr/lib/python3/PIL/Image.py")       # Pillow's others
    assert not unheeded(DeprecationWarning, reader)
