"""`fishgen view` embeds only files from the asset's folder and serves only its one page."""
from __future__ import annotations

import base64
import http.client
import json
import os
import shutil
import signal
import subprocess
import sys
import threading

import pytest

from fishgen.errors import FishgenError
from fishgen.viewer.page import build_page, page_path
from tests.conftest import ROOT, run_cli
from tests.viewer.test_viewer_page import _payload

SECRET = b"top secret, not part of any asset\n"


@pytest.fixture
def nest(tmp_path):
    """``tmp_path/asset/`` for assets, with a secret file beside that folder (outside it)."""
    (tmp_path / "secret.txt").write_bytes(SECRET)
    folder = tmp_path / "asset"
    folder.mkdir()
    return folder


def _gltf(folder, *uris: str):
    doc = {"asset": {"version": "2.0"}, "buffers": [{"uri": u, "byteLength": 1} for u in uris]}
    path = folder / "a.gltf"
    path.write_text(json.dumps(doc))
    return path


def _refused(asset, ref):
    with pytest.raises(FishgenError) as err:
        build_page(asset)
    message = str(err.value)
    assert message.startswith(str(asset)) and repr(ref) in message, message
    result = run_cli("view", asset, "--no-serve")
    assert result.returncode == 2 and "Traceback" not in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1 and repr(ref) in result.stderr
    assert not page_path(asset).exists()


@pytest.mark.parametrize("ref", ["../secret.txt", "%2e%2e/secret.txt", "..\\secret.txt",
                                 "/etc/hostname", "file:///etc/hostname", "http://example.com/a.bin",
                                 "C:/Windows/win.ini"])
def test_gltf_reference_outside_the_folder_is_refused(nest, ref):
    _refused(_gltf(nest, ref), ref)


def test_gltf_symlink_leading_out_of_the_folder_is_refused(nest):
    os.symlink(nest.parent / "secret.txt", nest / "inside.bin")
    _refused(_gltf(nest, "inside.bin"), "inside.bin")


@pytest.mark.parametrize("ref", ["../secret.txt", "/etc/hostname"])
def test_obj_mtllib_outside_the_folder_is_refused(nest, ref):
    obj = nest / "a.obj"
    obj.write_text(f"mtllib {ref}\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    _refused(obj, ref)


@pytest.mark.parametrize("line", ["map_Kd ../secret.txt", "map_Kd -imfchan m ../secret.txt",
                                  "bump /etc/hostname"])
def test_mtl_texture_outside_the_folder_is_refused(nest, line):
    obj = nest / "a.obj"
    obj.write_text("mtllib a.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    (nest / "a.mtl").write_text(f"newmtl m\n{line}\n")
    _refused(obj, line.split()[-1])


def test_a_spaced_name_leading_out_of_the_folder_is_refused_not_skipped(nest):
    """`mtllib a b.mtl` where 'a b.mtl' links out of the folder (and 'a', 'b.mtl' are there): the
    whole name was tried quietly and the words read instead, losing the materials unsaid."""
    from fishgen.exchange.mesh_reader import read_mesh_file

    (nest.parent / "out.mtl").write_text("newmtl m\n")
    (nest / "a b.mtl").symlink_to(nest.parent / "out.mtl")
    (nest / "a").write_text("")
    (nest / "b.mtl").write_text("newmtl m\n")
    obj = nest / "t.obj"
    obj.write_text("mtllib a b.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    _refused(obj, "a b.mtl")
    with pytest.raises(FishgenError, match="leads outside it"):
        read_mesh_file(obj)


def test_inline_subfolder_and_percent_encoded_references_are_embedded(nest):
    (nest / "data").mkdir()
    (nest / "data" / "my skin.bin").write_bytes(b"\x01")
    asset = _gltf(nest, "data:application/octet-stream;base64,AA==", "data/my%20skin.bin")
    files = _payload(build_page(asset))["files"]
    assert set(files) == {"a.gltf", "data/my skin.bin"}
    assert base64.b64decode(files["data/my skin.bin"]) == b"\x01"


def test_an_obj_named_with_a_space_carries_its_mtl_and_texture(tmp_path):
    """`build -o "my fish.obj"` writes `mtllib my fish.mtl` and `map_Kd my fish_skin.png`, which
    trimesh and three.js read whole; the page took each word for a file (QA pass 10)."""
    from fishgen.exchange.mesh_reader import read_mesh_file

    obj = tmp_path / "my fish.obj"
    assert run_cli("build", ROOT / "params" / "bonybream.txt", "-o", obj).returncode == 0
    files = _payload(build_page(obj))["files"]
    assert set(files) == {"my fish.obj", "my fish.mtl", "my fish_skin.png", "my fish_skin_mask.png"}
    scene = read_mesh_file(obj)
    assert scene.images and all(image.rgba().shape[:2] == (256, 512) for image in scene.images)


# -- the server ------------------------------------------------------------------

class _Served:
    """Where a running `fishgen view` listens."""

    def __init__(self, port: int, token: str):
        self.server_address = ("127.0.0.1", port)
        self.token = token


@pytest.fixture
def server(tmp_path, viewer_assets):
    """The real `fishgen view --port 0` for a page in a folder that also holds other files."""
    folder = tmp_path / "site"
    (folder / "sub").mkdir(parents=True)
    (folder / "private.txt").write_bytes(SECRET)
    (folder / "sub" / "deeper.txt").write_bytes(SECRET)
    os.symlink(tmp_path / "site" / "private.txt", folder / "link.txt")
    shutil.copy(viewer_assets["cloud"], folder / "cloud.glb")
    page = folder / "cloud page.html"
    proc = subprocess.Popen([sys.executable, "-X", "faulthandler", "-u", "-m", "fishgen", "view",
                             str(folder / "cloud.glb"), "-o", str(page), "--port", "0"], cwd=ROOT,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        url = None
        for line in proc.stdout:
            if line.startswith("serving "):
                url = line.split()[1]
                break
        assert url is not None, proc.stderr.read()
        yield _Served(int(url.split(":")[2].split("/")[0]), url.split("token=")[1]), page
    finally:
        proc.terminate()
        _stops(proc)


def _stops(proc: subprocess.Popen) -> None:
    """The server exits on SIGTERM; if it has not within 30 s (a loaded machine once took over 10),
    fail with every thread's stack, which faulthandler prints on SIGABRT."""
    try:
        proc.wait(timeout=30)
    except subprocess.TimeoutExpired:
        proc.send_signal(signal.SIGABRT)
        try:
            _, err = proc.communicate(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()
            _, err = proc.communicate()
        pytest.fail(f"`fishgen view` did not exit within 30 s of SIGTERM; its threads:\n{err}")


def _get(srv, path, host=None, method="GET", token=True):
    conn = http.client.HTTPConnection("127.0.0.1", srv.server_address[1], timeout=10)
    if token:
        path += ("&" if "?" in path else "?") + f"token={srv.token}"
    try:
        conn.putrequest(method, path, skip_host=True)
        if host is not False:
            conn.putheader("Host", host or f"127.0.0.1:{srv.server_address[1]}")
        conn.endheaders()
        reply = conn.getresponse()
        return reply.status, reply.read()
    finally:
        conn.close()


def test_server_serves_the_page_at_root_and_at_its_name(server):
    srv, page = server
    for path in ("/", "/cloud%20page.html", "/?x=1"):
        status, body = _get(srv, path)
        assert status == 200 and body == page.read_bytes(), path
    port = srv.server_address[1]
    assert _get(srv, "/", host=f"localhost:{port}")[0] == 200
    assert _get(srv, "/", method="HEAD") == (200, b"")
    assert _get(srv, "/favicon.ico") == (204, b"")  # the page's icon is inline; a stray ask gets nothing


@pytest.mark.parametrize("path", ["/private.txt", "/link.txt", "/sub/", "/sub/deeper.txt", "/../secret",
                                  "/%2e%2e/private.txt", "//etc/hostname", "/bream.glb", "/index.html"])
def test_server_serves_nothing_else_from_the_folder(server, path):
    srv, _ = server
    status, body = _get(srv, path)
    assert status == 404 and SECRET not in body and b"Directory listing" not in body


def test_server_refuses_a_request_without_this_runs_token(server):
    srv, page = server
    for path in ("/", "/?token=", "/?token=" + srv.token[:-1] + ("B" if srv.token.endswith("A") else "A")):
        status, body = _get(srv, path, token=False)
        assert status == 403 and page.read_bytes()[:200] not in body, path


@pytest.mark.parametrize("host", ["evil.example:{port}", "127.0.0.1", "localhost:1",
                                  "127.0.0.1.nip.io:{port}", "", False])
def test_server_refuses_other_host_headers(server, host):
    srv, page = server
    if isinstance(host, str):
        host = host.format(port=srv.server_address[1]) or ""
    status, body = _get(srv, "/", host=host if host != "" else " ")
    assert status == 403 and page.read_bytes()[:200] not in body


def test_a_link_or_a_fifo_put_in_the_pages_place_is_not_served(tmp_path):
    """QA pass 15: `ln -sf secret page.html` while `view` served, and GET / returned the secret."""
    from fishgen.viewer.server import make_server

    page = tmp_path / "page.html"
    page.write_text("<p>page</p>")
    srv = make_server(page, 0)
    threading.Thread(target=srv.serve_forever, daemon=True).start()
    try:
        assert _get(srv, "/") == (200, b"<p>page</p>")
        page.unlink()
        (tmp_path / "secret.txt").write_bytes(SECRET)
        os.symlink(tmp_path / "secret.txt", page)
        status, body = _get(srv, "/")
        assert status == 404 and SECRET not in body
        page.unlink()
        os.mkfifo(page)        # a FIFO would hold a thread for good
        assert _get(srv, "/")[0] == 404
    finally:
        srv.shutdown()
        srv.server_close()
