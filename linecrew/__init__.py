"""The operator's tools, on the top floor: the ``linecrew`` console script,
its client commands, launchers (up, demo, compose), chaos runs, benchmarks
and reports. The processes' shared runtime is :mod:`linecrew_runtime`."""
