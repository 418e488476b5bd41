"""Shared fixtures: the default crane is loaded once per session."""

from __future__ import annotations

import pytest

from hiab_sim.crane.description import Crane
from hiab_sim.crane.loader import load_crane


@pytest.fixture(scope="session")
def crane() -> Crane:
    """The HIAB XS 031 preset."""
    return load_crane("xs031")
