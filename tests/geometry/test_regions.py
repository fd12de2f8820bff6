import numpy as np
import pytest

from graspdef.errors import ProblemError
from graspdef.geometry.regions import compile_predicate

POINTS = np.array([
    [0.0, 0.0, 0.0],
    [1.0, 1.0, 0.0],
    [-1.0, 0.6, 1.0],
    [0.05, 0.05, 0.0],
    [0.0, -0.5, 2e-10],
])


@pytest.mark.parametrize("expr, expected", [
    ("abs(x) < 1e-9 or y > 0.5*Ly", [1, 1, 1, 0, 1]),
    ("z == 0", [1, 1, 0, 1, 1]),
    ("z != 0", [0, 0, 1, 0, 0]),
    ("r < 0.1 and theta > 0", [0, 0, 0, 1, 0]),
    ("not (x < 0)", [1, 1, 0, 1, 1]),
    ("-1 < x <= 0.05", [1, 0, 0, 1, 1]),
    ("rho ** 2 > 1.5", [0, 1, 1, 0, 0]),
    ("theta == pi/4", [0, 1, 0, 1, 0]),
    ("max(x, y, z) >= 1 or min(x, y) < -0.9", [0, 1, 1, 0, 0]),
    ("hypot(x, y) == sqrt(x**2 + y**2) and atan2(y, x) == theta", [1, 1, 1, 1, 1]),
    ("sin(x) ** 2 + cos(x) ** 2 == 1", [1, 1, 1, 1, 1]),
    ("sqrt(y) > 0.5", [0, 1, 1, 0, 0]),
    ("1 < 2", [1, 1, 1, 1, 1]),
])
def test_predicates(expr, expected):
    predicate = compile_predicate(expr, "region", constants={"Ly": 1.0})
    mask = predicate(POINTS)
    assert mask.dtype == bool and mask.shape == (len(POINTS),)
    np.testing.assert_array_equal(mask, np.array(expected, dtype=bool))


def test_equality_tolerance():
    assert not compile_predicate("z == 0", "top", atol=1e-12)(POINTS)[4]
    assert compile_predicate("z == 0", "top", length_scale=1.0)(POINTS)[4]
    assert not compile_predicate("z == 0", "top", length_scale=1e-3)(POINTS)[4]


@pytest.mark.parametrize("expr, token", [
    ("xx < 0", "unknown name 'xx'"),
    ("__import__('os')", "unknown function '__import__'"),
    ("x.real", "'x.real'"),
    ("open('f')", "unknown function 'open'"),
    ("x[0] < 1", "'x\\[0\\]'"),
    ("(lambda: 1)() < 2", "lambda"),
    ("'a' < x", "constant 'a'"),
    ("x % 2 < 1", "'x % 2'"),
    ("x in y", "'x in y'"),
    ("sqrt(x, y) < 1", "'sqrt' takes 1"),
    ("abs(x=1) < 1", "positional"),
    ("x + 1", "where a condition is expected"),
    ("(x < 1) * 2 > 0", "where a number is expected"),
    ("x <", "syntax error"),
])
def test_rejects_unsafe_or_invalid(expr, token):
    with pytest.raises(ProblemError, match=f"^region 'left': .*{token}.* in "):
        compile_predicate(expr, "left")


def test_message_format():
    with pytest.raises(ProblemError) as info:
        compile_predicate("xx < 0", "left")
    assert str(info.value) == "region 'left': unknown name 'xx' in 'xx < 0'"


def test_bad_constants_and_points():
    with pytest.raises(ProblemError, match="shadows"):
        compile_predicate("x < L", "a", constants={"x": 1.0})
    with pytest.raises(ProblemError, match="must be a number"):
        compile_predicate("x < L", "a", constants={"L": "one"})
    with pytest.raises(ProblemError, match=r"shape \(n, 3\)"):
        compile_predicate("x < 1", "a")(np.zeros((3, 2)))
