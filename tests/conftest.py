"""Process set-up of the test session: what ``graspdef`` does at start (graspdef.runtime), so the
tests run the solvers as the command line does."""
from graspdef import runtime


def pytest_configure(config):
    runtime.configure()
