"""The upper triangle of the KKT matrix that PARDISO factors, built by a compiled kernel
(graspdef.solve._kernels.kkt_upper_pattern), against the definition: the upper triangle of
[[K, s C^T], [s C, 0]] with the constraint block's zero diagonal stored explicitly."""
import numpy as np
import pytest
import scipy.sparse as sp

from graspdef.solve.sparse import _UpperMap, kkt_upper


def _random_system(n, m, seed, unsorted=False):
    rng = np.random.default_rng(seed)
    A = sp.random(n, n, density=0.2, random_state=rng, format="csr")
    K = (A + A.T + sp.eye(n)).tocsr()                       # symmetric, full diagonal
    C = sp.random(m, n, density=0.3, random_state=rng, format="csr")
    C.data[::3] = 0.0                                       # explicit zeros must stay zero
    if unsorted:                                            # columns of each row in reverse order
        K = sp.csr_matrix((K.data.copy(), K.indices.copy(), K.indptr.copy()), shape=K.shape)
        for i in range(n):
            a, b = K.indptr[i], K.indptr[i + 1]
            K.indices[a:b] = K.indices[a:b][::-1]
            K.data[a:b] = K.data[a:b][::-1]
        K.has_sorted_indices = False
    return K, C


@pytest.mark.parametrize("n, m, seed", [(1, 1, 0), (7, 2, 1), (40, 5, 2), (60, 0, 3)])
@pytest.mark.parametrize("unsorted", [False, True])
def test_upper_triangle_equals_the_definition(n, m, seed, unsorted):
    K, C = _random_system(n, m, seed, unsorted)
    s = 3.7
    U = kkt_upper(K, C, s)
    ref = sp.triu(sp.bmat([[K, s * C.T], [s * C, None]]) if m else K).toarray()
    assert U.shape == (n + m, n + m)
    np.testing.assert_array_equal(U.toarray(), ref)
    # every row's columns ascending when K's are (what PARDISO requires) and the zero diagonal of
    # the constraint block stored explicitly
    if not unsorted:
        for i in range(n + m):
            cols = U.indices[U.indptr[i]:U.indptr[i + 1]]
            assert np.all(np.diff(cols) > 0)
    for j in range(m):
        row = U.indices[U.indptr[n + j]:U.indptr[n + j + 1]]
        assert list(row) == [n + j]


def test_the_map_gathers_new_values_on_the_same_pattern():
    """A Newton iteration's K on the analysed pattern: only its values are gathered."""
    K, C = _random_system(30, 4, 5)
    mp = _UpperMap(K, C)
    K2 = K.copy()
    K2.data = np.random.default_rng(9).standard_normal(K.nnz)
    K2 = K2 + K2.T                                          # still symmetric, same pattern
    K2 = sp.csr_matrix((K2.tocsr()[K.nonzero()].A1, K.indices, K.indptr), shape=K.shape)
    assert mp.matches(K2)
    np.testing.assert_array_equal(mp.upper(K2, 2.0).toarray(), kkt_upper(K2, C, 2.0).toarray())
    np.testing.assert_array_equal(mp.upper(K2, 2.0).toarray(),
                                  sp.triu(sp.bmat([[K2, 2.0 * C.T], [2.0 * C, None]])).toarray())
