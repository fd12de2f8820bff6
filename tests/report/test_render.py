"""Headless surface pictures: a PNG with the colour map's colours, any number of views, open and
closed surfaces, per-vertex and per-face scalars; bad input is refused with a clear message."""
from __future__ import annotations

import io

import numpy as np
import pytest
from PIL import Image

from graspdef.geometry import icosphere
from graspdef.report.render import render_surface


def _image(png: bytes) -> np.ndarray:
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).astype(int)


@pytest.fixture(scope="module")
def ball():
    m = icosphere(radius=0.03, subdivisions=3)
    v = m.vertices * np.array([1.0, 1.0, 0.8])
    return v, m.faces, np.linalg.norm(v - m.vertices, axis=1) * 1e3


def test_coloured_ball_three_views(ball):
    v, f, s = ball
    img = _image(render_surface(v, f, s, label="|u| [mm]", title="ball", dpi=80))
    h, w, _ = img.shape
    assert w > 2.5 * h                              # three panels side by side plus the colour bar
    colours = {tuple(c) for c in img.reshape(-1, 3)[::7]}
    assert len(colours) > 200
    sat = img.max(axis=2) - img.min(axis=2)
    assert np.mean(sat > 60) > 0.15                 # much of the picture is in colour-map hues


def test_plain_open_surface_and_face_scalars():
    m = icosphere(radius=1.0, subdivisions=2)
    keep = m.vertices[m.faces].mean(axis=1)[:, 2] > 0   # an open cap (the inside shows)
    f = m.faces[keep]
    img = _image(render_surface(m.vertices, f, views=[(20, 30)], dpi=60))
    assert img.std() > 10
    img2 = _image(render_surface(m.vertices, f, np.arange(len(f), dtype=float), views=["side", "top"],
                                 cmap="coolwarm", symmetric=True, dpi=60))
    assert img2.std() > 10


@pytest.mark.parametrize("kwargs, msg", [
    ({"scalars": np.zeros(5)}, "one value per vertex"),
    ({"views": ["nowhere"]}, "unknown view"),
    ({"views": []}, "no views"),
])
def test_bad_input(ball, kwargs, msg):
    v, f, _ = ball
    with pytest.raises(ValueError, match=msg):
        render_surface(v, f, **kwargs)


def test_bad_mesh():
    with pytest.raises(ValueError, match="faces refer"):
        render_surface(np.zeros((3, 3)), np.array([[0, 1, 3]]))
    with pytest.raises(ValueError, match="NaN"):
        render_surface(np.full((3, 3), np.nan), np.array([[0, 1, 2]]))
