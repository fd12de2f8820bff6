import numpy as np
import pytest

from graspdef.geometry import TriMesh, ellipsoid


def make_egg(subdivisions: int = 5) -> TriMesh:
    """An ellipsoid (40 x 30 x 20 mm semi-axes) warped so that it has no symmetry at all: an
    ellipsoid or a sphere cannot test rotation recovery (../shared/MEASURED.md), an ellipsoid
    is ambiguous up to half-turns about its axes."""
    e = ellipsoid(0.04, 0.03, 0.02, subdivisions)
    x, y, z = e.vertices.T
    return TriMesh(np.c_[x, y * (1 + 4.0 * x), z * (1 + 5.0 * y) + 3.0 * x**2],
                   e.faces).validated("egg")


@pytest.fixture(scope="session")
def egg():
    return make_egg()
