"""The public API example in graspdef's docstring runs and gives its stated number."""
import doctest

import graspdef


def test_package_docstring_example():
    result = doctest.testmod(graspdef)
    assert result.attempted >= 5 and result.failed == 0


def test_public_names():
    for name in ("Shell", "LinearElastic", "Problem", "PointLoad", "Pressure", "BodyForce",
                 "EdgeSupport", "PointSupport", "RigidModes", "solve_linear", "load_problem"):
        assert hasattr(graspdef, name)
