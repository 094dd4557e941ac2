"""Hypothesis fuzzing of the AIS readers: whatever the bytes, a reader either reads them
(every row accounted for in the ledger) or raises one ``Colregs9Error``; never another
exception, never a Python warning."""

from __future__ import annotations

import gzip
import warnings
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from colregs9_cli.ais.load import load_ais
from colregs9_cli.errors import Colregs9Error

from fixture_files import DMA26, MARINECADASTRE, NMEA

DMA_LINES = DMA26.read_text().splitlines()
MARINECADASTRE_LINES = MARINECADASTRE.read_text().splitlines()[:40]
with gzip.open(NMEA, "rt", errors="replace") as _lines:
    NMEA_LINES = [next(_lines).rstrip("\n") for _ in range(60)]

_SETTINGS = settings(
    max_examples=60,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)


def _mutated(lines: list[str]) -> st.SearchStrategy[str]:
    """A real file's lines with some of them cut, garbled, repeated or replaced."""

    def mutate(line: str, how: int, at: int, junk: str) -> str:
        cut = at % (len(line) + 1)
        return [
            line,
            line[:cut],
            line[:cut] + junk + line[cut:],
            line.replace(",", junk, 1),
            junk,
            line + "," + junk,
        ][how]

    line = st.builds(
        mutate,
        st.sampled_from(lines[1:]),
        st.integers(0, 5),
        st.integers(0, 400),
        st.text(alphabet=st.characters(blacklist_categories=("Cs",)), min_size=0, max_size=12),
    )
    return st.lists(line, min_size=0, max_size=25).map(
        lambda body: "\n".join([lines[0], *body]) + "\n"
    )


def _read(path: Path) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a warning would reach the user's stderr
        try:
            data = load_ais([path])
        except Colregs9Error as exc:
            assert str(exc).strip() and "\n" not in str(exc).strip()
            return
    ledger = data.ledger.to_dict()
    assert data.ledger.balanced, ledger


@pytest.mark.parametrize(
    "lines", [DMA_LINES, MARINECADASTRE_LINES, NMEA_LINES], ids=["dma26", "marinecadastre", "nmea"]
)
def test_mutated_real_files_read_or_fail_cleanly(tmp_path: Path, lines: list[str]) -> None:
    @_SETTINGS
    @given(text=_mutated(lines))
    def check(text: str) -> None:
        path = tmp_path / "input.csv"
        path.write_text(text, encoding="utf-8", errors="surrogatepass")
        _read(path)

    check()


@_SETTINGS
@given(data=st.binary(min_size=1, max_size=400))
def test_random_bytes_read_or_fail_cleanly(tmp_path: Path, data: bytes) -> None:
    path = tmp_path / "input.bin"
    path.write_bytes(data)
    _read(path)


@_SETTINGS
@given(
    data=st.binary(min_size=0, max_size=200),
    header=st.sampled_from(
        [b"\x1f\x8b", b"PK\x03\x04", b"BZh", b"\xfd7zXZ\x00", b"\x28\xb5\x2f\xfd", b"PAR1"]
    ),
)
def test_corrupt_compressed_files_fail_cleanly(tmp_path: Path, data: bytes, header: bytes) -> None:
    path = tmp_path / "input.gz"
    path.write_bytes(header + data)
    _read(path)
