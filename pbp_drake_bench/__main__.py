"""`python -m pbp_drake_bench`: the same as `pbp-drake bench`."""

import sys

from pbp_drake_bench.main import main

sys.exit(main())
