"""The rejects ledger: every input row is either used or counted here with a reason."""

from __future__ import annotations

from collections import Counter
from collections.abc import Mapping
from dataclasses import dataclass, field
from enum import StrEnum
from typing import Any

# The longest reject example quoted: a malformed line's text, and the first example of an
# error that names one.
EXAMPLE_CHARS = 300


class RejectReason(StrEnum):
    UNPARSEABLE = "unparseable"
    NO_POSITION = "position_not_available"
    INVALID_MMSI = "invalid_mmsi"
    NOT_A_VESSEL = "not_a_vessel"
    DUPLICATE = "duplicate"
    SPEED_JUMP = "speed_jump"
    INCOMPLETE_MULTIPART = "incomplete_multipart"
    UNSUPPORTED_MESSAGE = "unsupported_message_type"


class DropReason(StrEnum):
    """Why a value was dropped from a row that was kept (the row itself counts as used)."""

    IMPLAUSIBLE_DIMENSION = "implausible_dimension"
    # A reported SOG that the vessel's own positions contradict (tracks.py, rule 3a).
    SOG_CONTRADICTED = "sog_contradicted"


@dataclass
class RejectsLedger:
    """Counts of rows read, used, left out by the query, and rejected (by reason).

    ``rows_read == rows_used + rows_outside_query + rejected_total`` holds after every
    complete read. Rows outside the query are valid input that the query does not select;
    they are not rejects, but they are counted so that nothing disappears unaccounted.

    ``dropped`` counts rows read that kept their place but lost a value, by reason: a
    dimension beyond what ships have (``vessels.MAX_LENGTH_M`` ...) or not finite is
    dropped as ``implausible_dimension``: the row's position is good, its dimension goes into
    no statistic. These are not in the balance (the row is used, outside or rejected).
    """

    rows_read: int = 0
    rows_used: int = 0
    rows_outside_query: int = 0
    rejects: Counter[str] = field(default_factory=Counter)
    # Rows by the source of their time, where a layout has several (NMEA: nmea.TimeSource).
    time_sources: Counter[str] = field(default_factory=Counter)
    time_source_order: tuple[str, ...] = ()  # the precedence the reader used
    # How NMEA messages found their $PGHP line (nmea_pghp.Pairing), in logs that have any.
    pghp_pairing: Counter[str] = field(default_factory=Counter)
    # Examples of rejected rows, for the manifest: reason -> a few "file:line: value" strings.
    examples: dict[str, list[str]] = field(default_factory=dict)
    max_examples: int = 5
    dropped: Counter[str] = field(default_factory=Counter)
    dropped_examples: dict[str, list[str]] = field(default_factory=dict)

    def read(self, n: int = 1) -> None:
        self.rows_read += n

    def use(self, n: int = 1) -> None:
        self.rows_used += n

    def outside_query(self, n: int = 1) -> None:
        self.rows_outside_query += n

    def reject(self, reason: RejectReason, n: int = 1, example: str | None = None) -> None:
        if n <= 0:
            return
        self.rejects[reason.value] += n
        self._keep_example(self.examples, reason.value, example)

    def wants_example(self, reason: RejectReason | DropReason) -> bool:
        """Whether an example of ``reason`` would still be kept (to skip building it)."""
        kept = self.dropped_examples if isinstance(reason, DropReason) else self.examples
        return len(kept.get(reason.value, ())) < self.max_examples

    def drop(self, reason: DropReason, n: int = 1, example: str | None = None) -> None:
        """Count ``n`` rows that lost a value for ``reason`` (the rows are counted apart)."""
        if n <= 0:
            return
        self.dropped[reason.value] += n
        self._keep_example(self.dropped_examples, reason.value, example)

    def _keep_example(
        self, examples: dict[str, list[str]], reason: str, example: str | None
    ) -> None:
        if example is not None:
            bucket = examples.setdefault(reason, [])
            if len(bucket) < self.max_examples:
                bucket.append(example)

    def merge(self, part: RejectsLedger) -> None:
        """Add the counts, time sources and (up to ``max_examples``) examples of ``part``."""
        self.read(part.rows_read)
        self.use(part.rows_used)
        self.outside_query(part.rows_outside_query)
        for reason, count in part.rejects.items():
            self.rejects[reason] += count
        self.time_sources.update(part.time_sources)
        self.time_source_order = self.time_source_order or part.time_source_order
        self.pghp_pairing.update(part.pghp_pairing)
        self.dropped.update(part.dropped)
        for mine, theirs in (
            (self.examples, part.examples),
            (self.dropped_examples, part.dropped_examples),
        ):
            for reason, examples in theirs.items():
                bucket = mine.setdefault(reason, [])
                bucket.extend(examples[: max(0, self.max_examples - len(bucket))])

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> RejectsLedger:
        """The ledger ``to_dict`` gave (a dataset manifest keeps its inputs' ledgers);
        ``KeyError``, ``TypeError`` or ``ValueError`` for anything else."""
        ledger = cls(
            rows_read=int(data["rows_read"]),
            rows_used=int(data["rows_used"]),
            rows_outside_query=int(data["rows_outside_query"]),
            rejects=Counter({str(k): int(v) for k, v in data["rejects_by_reason"].items()}),
            time_sources=Counter({str(k): int(v) for k, v in data.get("time_sources", {}).items()}),
            time_source_order=tuple(str(s) for s in data.get("time_source_order", ())),
            pghp_pairing=Counter({str(k): int(v) for k, v in data.get("pghp_pairing", {}).items()}),
            examples={str(k): [str(e) for e in v] for k, v in data["reject_examples"].items()},
            dropped=Counter({str(k): int(v) for k, v in data.get("values_dropped", {}).items()}),
            dropped_examples={
                str(k): [str(e) for e in v]
                for k, v in data.get("values_dropped_examples", {}).items()
            },
        )
        if ledger.rejected_total != int(data["rows_rejected"]) or not ledger.balanced:
            raise ValueError("the ledger's counts do not add up")
        return ledger

    @property
    def rejected_total(self) -> int:
        return sum(self.rejects.values())

    @property
    def balanced(self) -> bool:
        return self.rows_read == self.rows_used + self.rows_outside_query + self.rejected_total

    def to_dict(self) -> dict[str, object]:
        return {
            "rows_read": self.rows_read,
            "rows_used": self.rows_used,
            "rows_outside_query": self.rows_outside_query,
            "rows_rejected": self.rejected_total,
            "rejects_by_reason": dict(sorted(self.rejects.items())),
            "reject_examples": dict(sorted(self.examples.items())),
            **(
                {
                    "time_sources": dict(sorted(self.time_sources.items())),
                    "time_source_order": list(self.time_source_order),
                }
                if self.time_sources
                else {}
            ),
            **(
                {"pghp_pairing": dict(sorted(self.pghp_pairing.items()))}
                if self.pghp_pairing
                else {}
            ),
            **(
                {
                    "values_dropped": dict(sorted(self.dropped.items())),
                    "values_dropped_examples": dict(sorted(self.dropped_examples.items())),
                }
                if self.dropped
                else {}
            ),
        }
