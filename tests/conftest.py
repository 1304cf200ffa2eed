"""Shared fixtures: every test session uses its own derivation cache directory."""

from __future__ import annotations

import os
import tempfile

import pytest

_CACHE = tempfile.mkdtemp(prefix="brakesqueal-test-cache-")
os.environ.setdefault("BRAKESQUEAL_CACHE_DIR", _CACHE)


@pytest.fixture(scope="session")
def rng():
    import numpy as np

    return np.random.default_rng(20261122)
