"""The grasp chain's solve stage (graspdef.pipeline.grasp.solve_shell) when a path stops."""
import numpy as np
import pytest

from graspdef.errors import SolverError
from graspdef.pipeline import grasp as G
from graspdef.solve.nonlinear import NonlinearSolution, PathStopped


def _setup():
    return G.ShellSetup(problem=object(), mapping=None, fingertips=[], free=True, probes={},
                        residual_F=np.zeros(3), residual_M=np.zeros(3))


def test_no_equilibrium_at_zero_load_is_one_clear_error(monkeypatch):
    """A path that stops before its first point (no equilibrium even unloaded, e.g. the air cannot
    be balanced) has nothing to record: SolverError naming the solver's reason, not an IndexError
    deep in the run record (what a stopped gas pre-load gave before)."""
    def stop(problem, opt, progress=None):
        raise PathStopped("no equilibrium at zero load: Newton did not converge", NonlinearSolution(problem, opt))

    monkeypatch.setattr(G, "solve_nonlinear", stop)
    with pytest.raises(SolverError, match="no equilibrium to record: no equilibrium at zero load"):
        G.solve_shell(_setup(), "nonlinear", 5)


def test_a_path_stopped_later_is_returned_as_far_as_it_got(monkeypatch):
    """A path that converged some points keeps them (Solved.completed False, the reason kept)."""
    def stop(problem, opt, progress=None):
        sol = NonlinearSolution(problem, opt)
        sol.path.append(object())
        raise PathStopped("the load path stopped at load factor 0.5", sol)

    monkeypatch.setattr(G, "solve_nonlinear", stop)
    s = G.solve_shell(_setup(), "nonlinear", 5)
    assert not s.completed and "0.5" in s.stop_reason and len(s.sol.path) == 1
