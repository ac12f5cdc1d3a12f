"""`python -m benchmarks`: the same as `horde bench`."""

import sys

from benchmarks.run import main

sys.exit(main())
