"""Parameter sweeps: a grid of grasp cases (objects x forces x materials x contact models x mesh
levels) run in parallel on dask.distributed -- an embedded LocalCluster by default, or a cluster
given by ``tcp://HOST:PORT`` -- resumable, gathered into one results table (``graspdef sweep``).

dask is imported only when a sweep runs (the ``sweep`` extra)."""
from .spec import BUILTIN_MATERIALS as BUILTIN_MATERIALS
from .spec import Case as Case
from .spec import SweepSpec as SweepSpec
from .spec import load_spec as load_spec
from .spec import parse_spec as parse_spec
from .run import SweepError as SweepError
from .run import SweepOutcome as SweepOutcome
from .run import gather as gather
from .run import run_sweep as run_sweep
