from __future__ import annotations

from pathlib import Path

import matplotlib
import pytest

from fixture_files import FIXTURES, SANDIEGO_AIS, SANDIEGO_ENC

matplotlib.use("Agg")


@pytest.fixture(scope="session")
def fixtures_dir() -> Path:
    return FIXTURES


@pytest.fixture(scope="session")
def sandiego_replay(tmp_path_factory: pytest.TempPathFactory):
    """The San Diego replay on its ENC without figures, shared by the modules that read it
    (read only: no test writes into its report)."""
    from colregs9_cli.replay import run_replay

    out = tmp_path_factory.mktemp("sandiego")
    return run_replay([SANDIEGO_AIS], chart_paths=[SANDIEGO_ENC], out_dir=out, plots=False)
