from __future__ import annotations

from pathlib import Path

import matplotlib
import pytest

from fixture_files import FIXTURES

matplotlib.use("Agg")


@pytest.fixture(scope="session")
def fixtures_dir() -> Path:
    return FIXTURES
