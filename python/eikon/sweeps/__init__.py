"""eikon.sweeps: many renders of one kind on Dask distributed (`eikon sweep`, eikon.sweep).
docs/sweep.md."""
from .run import main, sweep  # noqa: F401
from .spec import Sweep, SweepError  # noqa: F401
