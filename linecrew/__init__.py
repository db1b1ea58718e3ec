"""Process plumbing shared by every linecrew process: the Zenoh bus layer,
structured logging, signal handling and the ``linecrew`` console script."""
