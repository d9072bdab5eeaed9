"""`python -m pbp_drake.bench`: the same as `pbp-drake bench`."""

import sys

from pbp_drake.bench.main import main

sys.exit(main())
