from __future__ import annotations

from pathlib import Path

import matplotlib
import pytest
from hypothesis import settings

from fixture_files import FIXTURES, NMEA, SANDIEGO_AIS, SANDIEGO_ENC

matplotlib.use("Agg")
# No time limit per example: Hypothesis' deadline is a timed assertion, and on a loaded
# machine (CI, two cores) a 90 ms example took 258 ms and failed the run.
settings.register_profile("colregs9", deadline=None)
settings.load_profile("colregs9")


@pytest.fixture(scope="session")
def fixtures_dir() -> Path:
    return FIXTURES


@pytest.fixture(scope="session")
def sandiego_replay(tmp_path_factory: pytest.TempPathFactory):
    """The San Diego replay on its ENC without figures, shared by the modules that read it
    (read only: no test writes into its report)."""
    from colregs9_cli.jobs.replay import run_replay

    out = tmp_path_factory.mktemp("sandiego")
    return run_replay([SANDIEGO_AIS], chart_paths=[SANDIEGO_ENC], out_dir=out, plots=False)


@pytest.fixture(scope="session")
def dma_nmea_replay(tmp_path_factory: pytest.TempPathFactory):
    """The replay of the DMA NMEA log (five minutes, no chart) without figures, shared by the
    modules that read it (read only)."""
    from colregs9_cli.jobs.replay import run_replay

    out = tmp_path_factory.mktemp("dma_nmea")
    return run_replay([NMEA], out_dir=out, plots=False)
