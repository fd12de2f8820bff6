"""A region of control vertices and the rows of the shell's Hessians there (graspdef.shell.region).

The region's energy and volume visit only the faces whose stencils touch it, and their Hessians
must be the whole shell's rows of the region -- the same numbers up to the order of summation --
on regular and irregular (valence-5) faces alike; the region's own block is those rows' columns
of the region."""
import numpy as np
import pytest

from graspdef.geometry import sphere
from graspdef.shell.energy import ShellEnergy
from graspdef.shell.hyperelastic import NeoHookean
from graspdef.shell.model import Shell
from graspdef.shell.region import Region, vertex_rings
from graspdef.shell.volume import EnclosedVolume


def _deformed(sub=3):
    m = sphere(1.0, sub)
    sh = Shell(m.vertices, m.faces, NeoHookean(1e5), 0.02)
    X = sh.rest_positions
    rng = np.random.default_rng(3)
    x = X + 0.05 * np.sin(2 * X[:, [2, 0, 1]]) + 0.005 * rng.standard_normal(X.shape)
    return sh, x


@pytest.mark.parametrize("where", ["irregular", "regular"])
def test_region_rows_are_the_whole_hessians_rows(where):
    """Rings 2 around a valence-5 vertex (irregular faces in the region) and around a valence-6 one
    far from all of them (regular faces only):
    the region's shell-energy and enclosed-volume Hessians equal the rows of the whole shell's to
    round-off (1e-13 of the largest entry), its own block equals H[R, R], and the faces it visits
    are exactly those whose stencils touch R."""
    sh, x = _deformed()
    val = np.bincount(np.asarray(sh.mesh.faces).ravel(), minlength=sh.n_control)   # valence, on a closed mesh
    five = np.flatnonzero(val == 5)
    if where == "irregular":
        seed = int(five[0])
    else:                                  # the vertex farthest from every valence-5 one (4-5 edges)
        X = sh.rest_positions
        seed = int(np.argmax(np.linalg.norm(X[:, None] - X[five][None], axis=2).min(1)))
    reg = Region(sh, vertex_rings(sh, [seed], 2))
    H = ShellEnergy(sh).hessian(x)[2].tocsr()
    V = EnclosedVolume(sh).hessian(x, 3.0)[2].tocsr()
    Hr = reg.energy.hessian(x)[2]
    Vr = reg.volume.hessian(x, 3.0)[2]
    assert Hr.shape == (len(reg.dofs), sh.n_dofs)
    assert abs(Hr - H[reg.dofs]).max() <= 1e-13 * abs(H).max()
    assert abs(Vr - V[reg.dofs]).max() <= 1e-13 * abs(V).max()
    assert abs(reg.own_block(Hr) - H[reg.dofs][:, reg.dofs]).max() <= 1e-13 * abs(H).max()
    touching = sum(int(np.isin(g.stencils, reg.vertices).any(1).sum()) for g in sh.basis.groups)
    assert reg.n_faces == touching < sum(len(g.faces) for g in sh.basis.groups)
    irregular = [g for g in reg.view.basis.groups if g.stencils.shape[1] != 12]
    assert bool(irregular) == (where == "irregular")


def test_vertex_rings_grow_by_the_mesh_edges():
    """Ring 0 is the seeds; each ring adds the vertices one edge away, and no others."""
    sh, _ = _deformed(2)
    F = np.asarray(sh.mesh.faces)
    seed = 7
    one = vertex_rings(sh, [seed], 1)
    nbrs = set(F[(F == seed).any(1)].ravel())
    assert set(np.flatnonzero(one)) == nbrs
    assert np.flatnonzero(vertex_rings(sh, [seed], 0)).tolist() == [seed]
    two = vertex_rings(sh, [seed], 2)
    assert set(np.flatnonzero(two)) == set(F[np.isin(F, list(nbrs)).any(1)].ravel())


def test_an_empty_region_is_refused():
    sh, _ = _deformed(1)
    with pytest.raises(ValueError, match="non-empty"):
        Region(sh, np.zeros(sh.n_control, bool))
