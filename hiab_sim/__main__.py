"""Allow ``python -m hiab_sim``."""

import sys

from hiab_sim.cli import main

sys.exit(main())
