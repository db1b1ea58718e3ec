"""``python -m sim_fleet``."""

import sys

from sim_fleet.main import main

sys.exit(main())
