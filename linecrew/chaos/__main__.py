"""``python -m linecrew.chaos``."""

import sys

from linecrew.chaos.main import main

sys.exit(main())
