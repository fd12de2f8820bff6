"""Independent reference: the linear Nitsche matrix as first implemented (linear theory only),
kept to check graspdef.problem.nitsche at rest."""
import numpy as np
import scipy.sparse as sp

from graspdef.problem.supports import EdgeSupport
from graspdef.shell.kinematics import strain_jacobian
from graspdef.shell.materials import plane_stress_tensor

_CORNERS = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])


def linear_nitsche_matrix(shell, supports: list, ev, gamma: float = 20.0,
                   n_points: int = 3) -> sp.csr_matrix:
    """Symmetric Nitsche terms that impose a zero rotation about supported edges (linear theory).

    For each edge with a fixed rotation and each Gauss point on its limit curve::

        -int [ m_nn(u) theta(v) + m_nn(v) theta(u) ] ds + int gamma D / h theta(u) theta(v) ds

    with the bending moment m_nn = m^ab nu_a nu_b, the rotation theta = n . du/dnu about the edge,
    the outward conormal nu, D = E t^3 / (12 (1 - nu^2)) and h the edge length.  Consistent: the
    exact solution satisfies the weak form, so nothing is regularised (Nitsche 1971; for Kirchhoff
    plates e.g. Embar, Dolbow & Harari 2010).  ``gamma`` must make the form coercive; the solver's
    inertia check reports it if it does not.
    """
    x = shell.rest_positions
    xv = np.asarray(shell.vertices, dtype=float)
    mesh = shell.mesh
    mat = shell.material
    thick = np.broadcast_to(np.asarray(shell.thickness, float), (mesh.n_real_faces,))
    t_gl, w_gl = np.polynomial.legendre.leggauss(n_points)
    taus, wts = 0.5 * (t_gl + 1.0), 0.5 * w_gl
    rows, cols, vals = [], [], []
    for sup in supports:
        if not isinstance(sup, EdgeSupport) or not sup.directions()[1]:
            continue
        ab = mesh.boundary_edges
        mask = np.asarray(sup.where(xv[ab[:, 0]]), bool) & np.asarray(sup.where(xv[ab[:, 1]]), bool)
        for e in np.flatnonzero(mask):
            a, b = ab[e]
            f = int(mesh.boundary_faces[e])
            tri = mesh.faces[f]
            i = int(np.flatnonzero(tri == a)[0])
            pts = (1 - taus)[:, None] * _CORNERS[i] + taus[:, None] * _CORNERS[(i + 1) % 3]
            st, N, dN, ddN = ev.basis(f, pts)
            X = x[st]
            S = len(st)
            h = float(np.linalg.norm(x[b] - x[a]))
            t = thick[f]
            Dplate = mat.E * t ** 3 / (12.0 * (1.0 - mat.nu ** 2))
            chart_e = _CORNERS[(i + 1) % 3] - _CORNERS[i]
            for q in range(len(taus)):
                y = np.concatenate([dN[q], ddN[q]], axis=1).T @ X               # (5, 3)
                a1, a2 = y[0], y[1]
                n = np.cross(a1, a2)
                n /= np.linalg.norm(n)
                te = chart_e[0] * a1 + chart_e[1] * a2
                ds = np.linalg.norm(te)
                tvec = te / ds
                nu_out = np.cross(tvec, n)
                A = np.array([[a1 @ a1, a1 @ a2], [a1 @ a2, a2 @ a2]])
                nu_cov = np.array([nu_out @ a1, nu_out @ a2])
                nu_con = np.linalg.solve(A, nu_cov)
                Ainv = np.linalg.inv(A)
                H = plane_stress_tensor(mat.E, mat.nu, np.array([Ainv[0, 0], Ainv[1, 1], Ainv[0, 1]]))
                J = strain_jacobian(y[None])[0]                                  # (6, 5, 3)
                Dm = np.concatenate([dN[q], ddN[q]], axis=1)                     # (S, 5)
                dkappa = np.einsum("iKa,sK->isa", J[3:], Dm).reshape(3, 3 * S)   # d kappa_voigt / du
                m_voigt = (t ** 3 / 12.0) * H @ dkappa                           # (3, 3S): m^11, m^22, m^12
                m_nn = (m_voigt[0] * nu_cov[0] ** 2 + m_voigt[1] * nu_cov[1] ** 2
                        + 2.0 * m_voigt[2] * nu_cov[0] * nu_cov[1])
                theta = ((dN[q] @ nu_con)[:, None] * n[None, :]).ravel()         # (3S,)
                w = wts[q] * ds
                Ke = w * (-(np.outer(m_nn, theta) + np.outer(theta, m_nn)) + gamma * Dplate / h * np.outer(theta, theta))
                dofs = (3 * st[:, None] + np.arange(3)).ravel()
                rows.append(np.repeat(dofs, len(dofs)))
                cols.append(np.tile(dofs, len(dofs)))
                vals.append(Ke.ravel())
    n = shell.n_dofs
    if not rows:
        return sp.csr_matrix((n, n))
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n))
