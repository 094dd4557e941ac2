"""Pairing Gatehouse ``$PGHP`` lines with the sentences they time, by checksum (nmea.py).

A ``$PGHP,1,<year>,<month>,<day>,<hour>,<minute>,<second>,<ms>,<country>,<region>,
<site MMSI>,<online flag or origin>,<checksum>*hh`` line times one sentence: its 14th field
is that sentence's checksum, two hex digits. For a multi-sentence message it is the checksum
of all its fragments together, i.e. the XOR of their checksums, as for all 69 in the DMA
fixture (the first fragment's own checksum matches once, where the second's is ``00``). DMA
writes the ``$PGHP`` just before its sentence. exactEarth's satellite logs for AMSA write it
before, after or a few lines away, several ``$PGHP`` lines and sentences interleaved, and
terrestrial sentences with no ``$PGHP`` among them: in two samples of 2012 (242 sentences,
180 ``$PGHP`` lines) only 44 sentences come right after their ``$PGHP``.

The rules, in order:

1. A ``$PGHP`` pairs with the sentence right after it (the next sentence line; stand-alone
   tag block lines do not count) when that sentence's checksum is its checksum field, or
   when it has no checksum field (empty, or not two hex digits): DMA's convention, and the
   only rule for a ``$PGHP`` without a checksum.
2. Every other ``$PGHP`` takes, in file order, the nearest sentence with its checksum that
   no ``$PGHP`` has taken, within ``WINDOW_LINES`` lines either side: the first found looking
   1 line after, 1 before, 2 after, 2 before, and so on. Of two sentences with the same
   checksum in the window the nearer wins, the following one on a tie.
3. DMA writes ``00`` as the checksum of the ``$PGHP`` before its base stations' own
   ``!xxVDO`` reports (473 of the 475 in the fixture). A ``$PGHP`` with ``00`` that rules 1
   and 2 left alone pairs with the sentence right after it, if that sentence found no
   ``$PGHP`` either.

``WINDOW_LINES`` is 15. In the two exactEarth samples, 151 sentences find their ``$PGHP``
within 15 lines (90 % within 5), each pair arriving at the archive within 0.7 s of each
other; a wider window adds a ``$PGHP`` 16 lines away whose sentence arrived 128 s earlier, a
different satellite pass. A sentence of the same checksum by chance (1 in 256) lies within
reach more often the wider the window, and rule 2 gives it to a ``$PGHP`` whose own
sentence is missing.

A sentence waits until no ``$PGHP`` can take it any more (at most ``2 * WINDOW_LINES``
lines), and units leave in the order they came, so the reader's rows and rejects keep the
order of the file. Every sentence line takes part (a ``$PSTT`` takes its ``$PGHP`` too, which
is then not left to time an AIS sentence); only AIS messages are counted (``Pairing``).
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from enum import StrEnum

WINDOW_LINES = 15
_PLACEHOLDER_CHECKSUM = 0  # DMA's "00" before a base station's own !xxVDO report


class Pairing(StrEnum):
    """The ledger's ``pghp_pairing`` counts: how each AIS message found its ``$PGHP``, and
    the ``$PGHP`` lines that timed none."""

    MATCHED = "matched"  # by checksum (rules 1 and 2)
    ADJACENT = "adjacent"  # by adjacency alone: no checksum field, or rule 3
    UNMATCHED = "unmatched"  # no $PGHP
    PGHP_UNMATCHED = "pghp_unmatched"  # a $PGHP line (with a valid time) that timed nothing


@dataclass(eq=False, slots=True)
class Pghp:
    """A ``$PGHP`` line with a valid time."""

    line_no: int
    time_ms: int
    checksum: int | None  # None: no checksum field; it times the next sentence
    paired: bool = False


# What the reader does with a sentence, message or reject (its payload) once its $PGHP is
# settled: called with the payload, the $PGHP that times it (None if none) and how it paired.
Release = Callable[[object, Pghp | None, Pairing], None]


@dataclass(eq=False, slots=True)
class _Unit:
    """A sentence, a whole multi-sentence message or a reject, waiting to leave in its turn.

    ``line_no`` is its first line, ``adjacent`` the ``$PGHP`` right before that line;
    ``checksum`` is None for what no ``$PGHP`` may take by checksum (a reject).
    """

    line_no: int
    adjacent: Pghp | None
    checksum: int | None
    release: Release | None
    payload: object
    pghp: Pghp | None = None
    pairing: Pairing = Pairing.UNMATCHED


class PghpMatcher:
    """The pairing rules of the module docstring, fed line by line in file order.

    Until the log's first ``$PGHP`` line, what comes can only be taken by a later one: it
    waits ``window`` lines in ``dormant`` as it was given, so that a log without ``$PGHP``
    lines builds no units.
    """

    def __init__(self, window_lines: int = WINDOW_LINES) -> None:
        self.window = window_lines
        self.adjacent: Pghp | None = None  # the $PGHP waiting for the next sentence line
        self.undecided: deque[Pghp] = deque()  # for rule 2, in line order
        self.open: dict[int, list[_Unit]] = {}  # units no $PGHP has taken, by checksum
        self.queue: deque[_Unit] = deque()  # units waiting to leave, in order
        self.dormant: deque[tuple[int, int | None, Release | None, object]] = deque()
        self.pghp_lines = 0
        self.pghp_paired = 0

    def pghp(self, line_no: int, time_ms: int, checksum: int | None) -> None:
        while self.dormant:  # the log's first $PGHP: what waited may be its sentence
            first, unit_checksum, release, payload = self.dormant.popleft()
            self._queue(_Unit(first, None, unit_checksum, release, payload))
        self.adjacent = Pghp(line_no, time_ms, checksum)
        self.pghp_lines += 1

    def take_adjacent(self) -> Pghp | None:
        """The ``$PGHP`` right before a sentence line, for what that line starts (``add``)."""
        adjacent, self.adjacent = self.adjacent, None
        return adjacent

    def skip_adjacent(self) -> None:
        """A line that starts nothing to time ends the wait of the ``$PGHP`` before it."""
        adjacent, self.adjacent = self.adjacent, None
        if adjacent is not None:
            self._undecided(adjacent)

    def add(
        self,
        line_no: int,
        adjacent: Pghp | None,
        checksum: int | None,
        release: Release | None,
        payload: object = None,
    ) -> None:
        """A sentence, message (``checksum`` its checksum) or reject (None) starting at
        ``line_no``: paired by rule 1 if it can be, released at once if nothing waits before
        it and no ``$PGHP`` can take it any more, else queued."""
        if not self.pghp_lines:
            self.dormant.append((line_no, checksum, release, payload))
            return
        how = self._rule_one(adjacent, checksum)
        if how is None and adjacent is not None and not adjacent.paired:
            self._undecided(adjacent)
        if not self.queue and (how is not None or checksum is None):
            if release is not None:
                release(payload, adjacent if how is not None else None, how or Pairing.UNMATCHED)
            return
        unit = _Unit(line_no, adjacent, checksum, release, payload)
        if how is not None:
            unit.pghp, unit.pairing = adjacent, how
        self._queue(unit)

    def advance(self, line_no: int) -> None:
        """Before line ``line_no``: decide the ``$PGHP`` lines whose window has been read
        and release what no ``$PGHP`` can take any more."""
        dormant = self.dormant
        while dormant and dormant[0][0] < line_no - self.window:
            _, _, release, payload = dormant.popleft()
            if release is not None:
                release(payload, None, Pairing.UNMATCHED)
        undecided = self.undecided
        while undecided and undecided[0].line_no < line_no - self.window:
            self._decide(undecided.popleft())
        queue = self.queue
        settled_before = line_no - 2 * self.window
        while queue:
            unit = queue[0]
            if unit.pghp is None and unit.checksum is not None and unit.line_no >= settled_before:
                return
            self._leave(queue.popleft())

    def finish(self) -> None:
        self.skip_adjacent()
        for _, _, release, payload in self.dormant:  # a log without $PGHP lines
            if release is not None:
                release(payload, None, Pairing.UNMATCHED)
        self.dormant.clear()
        while self.undecided:
            self._decide(self.undecided.popleft())
        while self.queue:
            self._leave(self.queue.popleft())

    @property
    def pghp_unmatched(self) -> int:
        return self.pghp_lines - self.pghp_paired

    def _rule_one(self, adjacent: Pghp | None, checksum: int | None) -> Pairing | None:
        if adjacent is None or adjacent.paired:
            return None
        if adjacent.checksum is None:
            how = Pairing.ADJACENT
        elif adjacent.checksum == checksum:
            how = Pairing.MATCHED
        else:
            return None
        adjacent.paired = True
        self.pghp_paired += 1
        return how

    def _queue(self, unit: _Unit) -> None:
        self.queue.append(unit)
        if unit.pghp is None and unit.checksum is not None:
            self.open.setdefault(unit.checksum, []).append(unit)

    def _pair(self, pghp: Pghp, unit: _Unit, how: Pairing) -> None:
        pghp.paired = True
        unit.pghp = pghp
        unit.pairing = how
        self.pghp_paired += 1

    def _decide(self, pghp: Pghp) -> None:
        """Rule 2: the nearest open unit with the checksum, the following one on a tie."""
        if pghp.paired or pghp.checksum is None:
            return
        candidates = self.open.get(pghp.checksum)
        if not candidates:
            return
        best: _Unit | None = None
        best_key = (self.window + 1, False)
        for unit in candidates:
            offset = unit.line_no - pghp.line_no
            key = (abs(offset), offset < 0)
            if key < best_key:
                best, best_key = unit, key
        if best is not None:
            candidates.remove(best)
            self._pair(pghp, best, Pairing.MATCHED)

    def _leave(self, unit: _Unit) -> None:
        """Release a unit; one no ``$PGHP`` took by checksum leaves the window (and rule 3)."""
        if unit.pghp is None and unit.checksum is not None:
            self.open[unit.checksum].remove(unit)
            adjacent = unit.adjacent
            if (
                adjacent is not None
                and not adjacent.paired
                and adjacent.checksum == _PLACEHOLDER_CHECKSUM
            ):
                self._pair(adjacent, unit, Pairing.ADJACENT)
        if unit.release is not None:
            unit.release(unit.payload, unit.pghp, unit.pairing)

    def _undecided(self, pghp: Pghp) -> None:
        """A ``$PGHP`` with a checksum that rule 1 did not pair waits for rule 2. It comes
        late after a multi-sentence message's first fragment: keep the line order."""
        if pghp.checksum is None:
            return
        undecided = self.undecided
        at = len(undecided)
        while at and undecided[at - 1].line_no > pghp.line_no:
            at -= 1
        undecided.insert(at, pghp)
