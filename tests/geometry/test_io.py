import numpy as np
import pytest

from graspdef.errors import MeshError, ProblemError
from graspdef.geometry.io import LENGTH_UNITS, length_scale, load_mesh, save_ply
from graspdef.geometry.primitives import hemisphere


@pytest.mark.parametrize("binary", [True, False])
def test_ply_round_trip_in_mm(tmp_path, binary):
    mesh = hemisphere(0.05, 4)
    magnitude = np.linalg.norm(mesh.vertices, axis=1)
    path = tmp_path / "shell.ply"
    save_ply(path, mesh.vertices, mesh.faces, units="mm", binary=binary,
             vertex_scalars={"displacement": magnitude})
    header = path.read_bytes().split(b"end_header")[0].decode()
    assert "comment units mm" in header.splitlines()
    assert "property double displacement" in header
    if not binary:  # the pole (0, 0, 0.05 m) is written in mm, its scalar unchanged
        first_vertex = path.read_text().split("end_header\n")[1].splitlines()[0]
        np.testing.assert_allclose([float(v) for v in first_vertex.split()], [0, 0, 50, 0.05])
    loaded = load_mesh(path, "mm")
    np.testing.assert_allclose(loaded.vertices, mesh.vertices, rtol=1e-15, atol=1e-18)
    np.testing.assert_array_equal(loaded.faces, mesh.faces)


def test_load_obj_in_inches(tmp_path):
    path = tmp_path / "tri.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    mesh = load_mesh(path, "in")
    np.testing.assert_allclose(mesh.vertices[1], [0.0254, 0, 0])


def test_missing_file(tmp_path):
    with pytest.raises(ProblemError, match="mesh file not found: .*nothing.ply"):
        load_mesh(tmp_path / "nothing.ply", "m")


def test_quads_rejected(tmp_path):
    path = tmp_path / "quad.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n")
    with pytest.raises(MeshError, match="faces must be triangles"):
        load_mesh(path, "m")


def test_unreadable_and_invalid_files(tmp_path):
    path = tmp_path / "junk.ply"
    path.write_text("not a mesh")
    with pytest.raises(MeshError, match="cannot read"):
        load_mesh(path, "m")
    path = tmp_path / "flipped.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 4 3\n")
    with pytest.raises(MeshError, match="inconsistent face orientation"):
        load_mesh(path, "m")


def test_units():
    assert length_scale("mm") == 1e-3 and LENGTH_UNITS["in"] == 0.0254
    with pytest.raises(ProblemError, match="unknown length unit 'ft'.*m, mm, cm, um, in"):
        length_scale("ft")


def test_save_ply_rejects_bad_scalars(tmp_path):
    mesh = hemisphere(1.0, 1)
    with pytest.raises(ProblemError, match="shape"):
        save_ply(tmp_path / "a.ply", mesh.vertices, mesh.faces, vertex_scalars={"u": [1.0]})
    with pytest.raises(ProblemError, match="name"):
        save_ply(tmp_path / "a.ply", mesh.vertices, mesh.faces,
                 vertex_scalars={"bad name": np.zeros(mesh.n_vertices)})


def test_atomic_folder_replaces_only_on_success(tmp_path):
    """A folder written through atomic_folder appears whole or not at all: an error inside the
    block leaves the previous folder untouched and no temporary folder behind."""
    from graspdef.runs.folder import atomic_folder

    out = tmp_path / "run"
    with atomic_folder(out) as d:
        (d / "a.txt").write_text("first")
    assert (out / "a.txt").read_text() == "first"
    with pytest.raises(RuntimeError):
        with atomic_folder(out) as d:
            (d / "a.txt").write_text("second")
            raise RuntimeError("boom")
    assert (out / "a.txt").read_text() == "first"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run"]
    with atomic_folder(out) as d:
        (d / "b.txt").write_text("third")
    assert sorted(p.name for p in out.iterdir()) == ["b.txt"]
