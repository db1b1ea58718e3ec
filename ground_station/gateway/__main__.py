"""``python -m ground_station.gateway``."""

import sys

from ground_station.gateway.main import main

sys.exit(main())
