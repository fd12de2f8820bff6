"""Loop subdivision: refinement rules, the box-spline patch basis and exact evaluation near
extraordinary vertices, and the ghost layer that gives open surfaces complete stencils."""
