"""Exception types raised by graspdef.

Every error a user can cause (bad mesh, bad problem file, under-supported body, ...) is raised as a
subclass of :class:`GraspdefError` with a message that names the problem and where it is.  The CLI
turns these into one line on stderr and a non-zero exit status.
"""


class GraspdefError(Exception):
    """Base class of all errors graspdef raises on purpose."""


class MeshError(GraspdefError):
    """The control mesh is unusable (non-manifold, degenerate, not triangles, NaN, ...)."""


class ProblemError(GraspdefError):
    """A problem definition (file or object) is invalid."""


class ConfigError(ProblemError):
    """A configuration file or value is invalid: TOML syntax, an unknown or missing key, a value of
    the wrong type, range or dimension (graspdef.config, graspdef.units).  The message names the
    file, the table and the key."""


class SupportError(GraspdefError):
    """Supports are inconsistent or leave rigid-body modes free."""


class SolverError(GraspdefError):
    """A solve failed (singular, non-converged, residual too large)."""
