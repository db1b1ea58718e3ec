from __future__ import annotations

from pathlib import Path

import sim_fleet


def test_all_is_sorted_and_resolvable():
    names = sim_fleet.__all__
    assert names == sorted(names, key=lambda n: (not n.isupper(), n))
    for name in names:
        assert hasattr(sim_fleet, name), name


def test_only_the_endpoint_imports_pymavlink():
    package = Path(sim_fleet.__file__).parent
    importers = sorted(
        p.name
        for p in package.glob("*.py")
        if "from pymavlink" in p.read_text() or "import pymavlink" in p.read_text()
    )
    assert importers == ["mavlink_endpoint.py"]
