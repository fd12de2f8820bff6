"""The disk cache of control meshes (graspdef.scans.cache): a cached mesh is the computed one to the
bit, the key follows the file's content and every option, and a cache that is off, damaged or not
writable changes nothing but the time.  The scan is a synthetic star-shaped blob written in
millimetres (an icosphere with a bump), small enough to remesh in milliseconds."""
import logging
import shutil
from dataclasses import asdict

import numpy as np
import pytest
import trimesh

import graspdef.scans.cache as cache
from graspdef.geometry import TriMesh
from graspdef.scans import control_mesh, read_surface
from graspdef.scans.cache import CACHE_ENV, cache_dir, cached_control_mesh, control_mesh_key


def _write_blob(path, bump=0.2):
    """A closed star-shaped surface [mm] written as PLY: a 30 mm icosphere with a smooth bump."""
    sph = trimesh.creation.icosphere(subdivisions=3, radius=30.0)
    v = np.asarray(sph.vertices)
    r = 1.0 + bump * np.exp(-8 * (1 - v[:, 2] / 30.0))
    trimesh.Trimesh(v * r[:, None], sph.faces, process=False).export(path)
    return path


@pytest.fixture
def blob(tmp_path, monkeypatch):
    monkeypatch.setenv(CACHE_ENV, str(tmp_path / "cache"))
    return _write_blob(tmp_path / "blob.ply")


def _entries(tmp_path):
    return sorted((tmp_path / "cache" / "control_mesh").glob("*.npz"))


def test_cached_mesh_is_the_computed_one_and_is_read_back(blob, tmp_path, monkeypatch):
    """First call: computed and stored (one file); equal to control_mesh of the file to the bit,
    report included.  Second call: read from the cache (control_mesh is not called)."""
    scan = TriMesh(*read_surface(blob, "mm"))
    ref, ref_rep = control_mesh(scan, 80, "project")
    mesh, rep = cached_control_mesh(blob, "mm", 80, "project")
    assert len(_entries(tmp_path)) == 1
    assert np.array_equal(mesh.vertices, ref.vertices) and np.array_equal(mesh.faces, ref.faces)
    assert asdict(rep) == asdict(ref_rep)
    assert scan.n_vertices > mesh.n_vertices

    def refuse(*a, **k):
        raise AssertionError("remeshed although cached")
    monkeypatch.setattr(cache, "control_mesh", refuse)
    again, again_rep = cached_control_mesh(blob, "mm", 80, "project")
    assert np.array_equal(again.vertices, ref.vertices) and np.array_equal(again.faces, ref.faces)
    assert again.faces.dtype == np.int64 and again.vertices.dtype == np.float64
    assert asdict(again_rep) == asdict(ref_rep)


def test_key_follows_content_and_options(blob, tmp_path):
    """A copy elsewhere has the same key (content, not name); one moved vertex, another unit, face
    count, method or relaxation each give another."""
    k = control_mesh_key(blob, "mm", 80, "project", 0)
    copy = shutil.copy(blob, tmp_path / "copy.ply")
    assert control_mesh_key(copy, "mm", 80, "project", 0) == k
    moved = _write_blob(tmp_path / "moved.ply", bump=0.2000001)
    others = {control_mesh_key(moved, "mm", 80, "project", 0), control_mesh_key(blob, "m", 80, "project", 0),
              control_mesh_key(blob, "mm", 320, "project", 0), control_mesh_key(blob, "mm", 80, "auto", 0),
              control_mesh_key(blob, "mm", 80, "project", 5)}
    assert len(others) == 5 and k not in others


def test_off_writes_nothing(blob, tmp_path, monkeypatch):
    monkeypatch.setenv(CACHE_ENV, "off")
    assert cache_dir() is None
    mesh, _ = cached_control_mesh(blob, "mm", 80, "project")
    assert mesh.n_faces == 80 and not (tmp_path / "cache").exists()


def test_default_folder_is_the_users_cache(monkeypatch, tmp_path):
    monkeypatch.delenv(CACHE_ENV, raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert cache_dir() == tmp_path / "xdg" / "graspdef"


def test_damaged_entry_is_recomputed_and_replaced(blob, tmp_path, caplog):
    """A truncated entry: a warning, the computed mesh, and a readable entry in its place."""
    ref, _ = cached_control_mesh(blob, "mm", 80, "project")
    (entry,) = _entries(tmp_path)
    entry.write_bytes(entry.read_bytes()[:100])
    with caplog.at_level(logging.WARNING, logger="graspdef.scans.cache"):
        mesh, _ = cached_control_mesh(blob, "mm", 80, "project")
    assert "unreadable" in caplog.text
    assert np.array_equal(mesh.vertices, ref.vertices)
    assert cache._read(entry, control_mesh_key(blob, "mm", 80, "project", 0)) is not None


def test_unwritable_cache_warns_and_computes(blob, tmp_path, monkeypatch, caplog):
    """The cache folder's place is taken by a file: a warning, the mesh all the same."""
    (tmp_path / "notadir").write_text("x")
    monkeypatch.setenv(CACHE_ENV, str(tmp_path / "notadir"))
    with caplog.at_level(logging.WARNING, logger="graspdef.scans.cache"):
        mesh, rep = cached_control_mesh(blob, "mm", 80, "project")
    assert "cannot write" in caplog.text and mesh.n_faces == 80 and rep.method == "project"
    assert len(caplog.records) == 1                         # one line, not also "unreadable"


def test_errors_are_control_meshs(tmp_path, monkeypatch):
    """A missing file and a refused option give the uncached errors, and nothing is stored."""
    from graspdef.errors import ProblemError

    monkeypatch.setenv(CACHE_ENV, str(tmp_path / "cache"))
    with pytest.raises(ProblemError, match="scan file not found"):
        cached_control_mesh(tmp_path / "none.ply", "mm", 80, "project")
    blob = _write_blob(tmp_path / "blob.ply")
    with pytest.raises(ProblemError, match="20 \\* 4\\*\\*k"):
        cached_control_mesh(blob, "mm", 81, "project")
    assert not _entries(tmp_path)
