"""Running a whole linecrew deployment locally: ``linecrew up`` and ``linecrew demo``."""
