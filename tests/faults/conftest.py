"""Fixtures the fault tests share."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
import viser

from app.access import make_server


@pytest.fixture
def bare_server() -> Iterator[viser.ViserServer]:
    """A viser server as the dashboard's is made (app.access.make_server: our workarounds for
    viser installed), with nothing on it: no dashboard, no DDS."""
    server, _ = make_server("127.0.0.1", 0, None)
    try:
        yield server
    finally:
        server.stop()
