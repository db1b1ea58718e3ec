"""``python -m onboard_agent``."""

import sys

from onboard_agent.main import main

sys.exit(main())
