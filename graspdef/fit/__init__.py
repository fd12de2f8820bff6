"""Material parameters from measurements (``graspdef fit``; docs/fit.md).

A measured force-displacement table (:func:`read_table`: CSV, units in the header, SI inside), a
forward model (parameters -> predicted displacements: an object's grasp chain,
:class:`ObjectModel`, or a shell problem, :class:`ShellModel`, or any callable) and a weighted
least-squares fit on log-parameters (:func:`fit`) that reports the values, residuals, standard
errors, correlations and when the data cannot separate the parameters."""
from .estimate import CONDITION_LIMIT, CORRELATION_LIMIT, FD_STEP, PARAMETERS, FitResult, fit, parse_names
from .models import OBJECT_POINTS, ObjectModel, ShellModel, half_approach, max_displacement, probe_along
from .table import MeasuredTable, read_table

__all__ = ["CONDITION_LIMIT", "CORRELATION_LIMIT", "FD_STEP", "OBJECT_POINTS", "PARAMETERS", "FitResult",
           "MeasuredTable", "ObjectModel", "ShellModel", "fit", "half_approach", "max_displacement", "parse_names",
           "probe_along", "read_table"]
