"""python3 -m eikon.sweeps SWEEP.json -o DIR (what `eikon sweep` runs)."""
import sys

try:
    import distributed  # noqa: F401
    import pandas  # noqa: F401
except ImportError as e:
    sys.exit(f"eikon: error: eikon sweep needs Dask distributed and pandas ({e.name} is missing; "
             "Debian: apt-get install python3-distributed python3-pandas)")
from eikon.sweeps.run import main

sys.exit(main())
