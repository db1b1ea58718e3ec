"""``python -m ground_station``."""

import sys

from ground_station.main import main

sys.exit(main())
