"""Raw NMEA AIS logs (``!AIVDM``/``!BSVDM``/...), decoded with pyais, in the canonical schema.

Timestamps, kept to the millisecond. A sentence can carry up to three times (``TimeSource``):

- ``tag_block``: a tag block ``c:`` on its own line (``\\s:rORBCOMM,c:1384257600*hh\\!AIVDM,...``)
  or on a stand-alone tag block line just before it: the receiver's time of reception;
- ``pghp``: a Gatehouse ``$PGHP,1,Y,M,D,h,m,s,ms,...`` line (the DMA feed, just before it;
  exactEarth's satellite feeds, near it, with their origin, e.g. ``1AIS_S``, in the fields
  after the time, and any field after the milliseconds is accepted): the base station's or
  satellite's time of reception, with milliseconds. Its 14th field is the checksum of the
  sentence it times, and nmea_pghp.py pairs the two by it (the ``$PGHP`` right before a
  sentence with its checksum, else the nearest within 15 lines); one without that field
  times the next sentence;
- ``arrival``: a trailing ``,<unix time>`` after the checksum: when the line reached the
  archive, which for satellite data is minutes to hours after the observation.

The observation wins over the arrival: by default ``tag_block``, then ``pghp``, then
``arrival`` (``DEFAULT_TIME_SOURCES``; ``read_nmea``'s ``time_sources`` changes the order or
leaves a source out). A whole-second observation time gives way to the other observation
source's time of the same second with milliseconds (DMA lines carry a ``c:`` in seconds and a
``$PGHP`` with milliseconds). Each message's source is counted in the ledger
(``time_sources``), and in a log with ``$PGHP`` lines how it found its ``$PGHP``
(``pghp_pairing``: ``matched`` by checksum, ``adjacent`` without one, ``unmatched``; and the
``pghp_unmatched`` lines that timed no sentence). A stand-alone tag block line gives its time
to the next sentence line only (AIS or not). A tag block whose checksum fails gives no time;
so does a ``$PGHP`` line whose checksum or date fails. ``c:`` and trailing values above 1e11
are taken as milliseconds. A message with no time from the sources in use is rejected as
unparseable: without a time it cannot be placed in a track. A reader that needs no time
(``read_nmea``'s ``keep_timeless``: ``colregs9 stats``, whose dimension statistics need none)
keeps such messages with a null timestamp and counts them under the time source ``none``;
``NmeaCounts.timeless`` counts them either way, so that a caller can tell a log in which no
line has a time.

Multi-sentence messages are reassembled per (sentence tag, channel, sequential id, fragment
count), so interleaved messages on other channels or ids do not disturb each other. A group
must arrive in order 1, 2, ..., n; a gap or a repeat marks the group broken, and a broken or
unfinished group counts once as ``incomplete_multipart``. Accepting fragments out of order
would let the tail of an older message complete a newer one with the same recycled id (0-9),
which decodes into a plausible but wrong message. The message takes the times of its first
fragment and of the ``$PGHP`` of the whole message (else the time of its first later fragment
that has one) and the line number of its first fragment. A sentence that fails its checksum
is one unparseable row by itself (its fragment header cannot be trusted), so the rest of its
message then counts as incomplete.

Accounting. A row is one AIS message after reassembly, and each becomes exactly one output
row or one reject: positions (1, 2, 3, 18, 19, 27), statics (5, 24), ``not_a_vessel`` (4, 9,
11, 21), ``unsupported_message_type`` (other defined types) or ``unparseable`` (bad
checksum, malformed, a payload too short for the fields read, a type outside 1-27, no time).
Other NMEA sentences (``$PSTT``, ``$GPRMC``, ...) and tag-block lines are not AIS messages
and are not rows; any other non-blank line is an unparseable row. Invalid MMSIs and missing
positions are left to the pipeline, which counts them.

Static join. Positions get ship type, dimensions, draught, name, call sign and IMO from the
static reports of the same MMSI (types 5, 24 and the static part of 19), field by field,
from the report nearest in time that has that field. Nearest rather than latest: over a long
log the draught changes between voyages, and the nearest report is the one that was in
force; a per-field choice because type 24 part A carries only the name and part B only the
rest, so the nearest whole report would often have the field empty. The antenna offsets A,
B, C, D (``to_bow_m`` ...) are the exception: all four come from the nearest report with any
of them, never A from one message and B from another. A position's own values (type 19) win
over joined ones. The tables and the join are built in nmea_tables.py. The join needs every
static, which may come after the position, so the whole input is collected and yielded as
one batch: fine for logs of a few million lines (peak about 1 kB per message while decoding,
measured on the DMA fixture), not for months of raw feed — split those by day.

Not available -> null: lat outside ±90 (91), lon outside ±180 (181), SOG 102.3 (type 27: 63),
COG and heading 360 and above (360, 511; type 27: 511), rate of turn -128 and ±127 (turning
fast with no turn indicator: no rate is known), dimension 0, draught 0, ship type 0, IMO 0,
empty text. The rate of turn is (raw / 4.733)² deg/min with the sign of raw. Type 27 (the
long-range broadcast of SOLAS ships) is "Class A". A, B, C, D are cleaned by
``clean.offset_parts`` (A = C = 0 with B, D > 0: no reference point, the vessel B long and D
wide). A length (A+B) or breadth (C+D) beyond what ships have (``vessels.MAX_LENGTH_M``,
``MAX_BREADTH_M``) is dropped too, with the message's four offsets, and the message (with a
valid MMSI) counted once in the ledger as ``implausible_dimension`` (AIS cannot encode a
draught beyond ``MAX_DRAUGHT_M``).
"""

from __future__ import annotations

import re
from collections import Counter
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass
from datetime import UTC, datetime
from functools import lru_cache, reduce
from operator import xor
from typing import cast

from pyais.exceptions import AISBaseException
from pyais.messages import (
    AISSentence,
    MessageType1,
    MessageType5,
    MessageType18,
    MessageType19,
    MessageType24PartA,
    MessageType24PartB,
    MessageType24PartBAuxiliaryCraft,
    MessageType27,
    NMEASentenceFactory,
    Payload,
    TagBlock,
)

from .batch import AisBatch
from .ledger import RejectReason, RejectsLedger
from .nmea_pghp import Pairing, Pghp, PghpMatcher
from .nmea_tables import NO_TIME_MS, POSITION_TYPES, NmeaColumns, nmea_batch
from .time_sources import DEFAULT_TIME_SOURCES, TimeSource

STATIC_TYPES = frozenset({5, 24})
NOT_A_VESSEL_TYPES = frozenset({4, 9, 11, 21})  # base station, SAR aircraft, UTC reply, AtoN

_EXAMPLE_CHARS = 160
_MAX_UNIX_S = 4_102_444_800  # 2100-01-01: larger values are not plausible receive times
_UNIX_MS_THRESHOLD = 1e11  # above this a c: value is milliseconds
_TRAILER_SEPARATORS = re.compile(r"[,\s]+")


# A message's time: milliseconds since the epoch, and its source.
_Stamp = tuple[int, TimeSource]
# A message waiting for its $PGHP: the sentence (reassembled), its first line, the times of
# its first sentence, the time of a later fragment, the raw text.
_MessagePayload = tuple[AISSentence, int, dict[TimeSource, int], _Stamp | None, str]
NO_TIME_SOURCE = "none"


@dataclass
class NmeaCounts:
    """What a read found besides the ledger: the AIS messages that had no time."""

    timeless: int = 0


def _bits_through(cls: type[Payload], last_field: str) -> int:
    """Payload bits needed to hold every field of ``cls`` up to and including ``last_field``."""
    total = 0
    for attribute in cls.fields():
        total += attribute.metadata["width"]
        if attribute.name == last_field:
            return total
    raise ValueError(f"{cls.__name__} has no field {last_field}")


def _required_bits() -> dict[int, int]:
    # pyais decodes a truncated field from the bits it has, so a short payload gives a wrong
    # MMSI or position instead of None; we require every bit of the fields we read.
    type1 = _bits_through(MessageType1, "heading")
    return {
        1: type1,
        2: type1,
        3: type1,
        18: _bits_through(MessageType18, "heading"),
        19: _bits_through(MessageType19, "to_starboard"),
        27: _bits_through(MessageType27, "course"),
        5: _bits_through(MessageType5, "draught"),
        24: _bits_through(MessageType24PartA, "shipname"),
    }


# pyais's decode() is typed as the union of every message class (and misses the auxiliary
# craft variant of type 24 part B); the message type fixes which of these it returns.
_PositionMessage = MessageType1 | MessageType18 | MessageType19 | MessageType27
_StaticMessage = (
    MessageType5 | MessageType24PartA | MessageType24PartB | MessageType24PartBAuxiliaryCraft
)
_Type24Message = MessageType24PartA | MessageType24PartB | MessageType24PartBAuxiliaryCraft

_REQUIRED_BITS = _required_bits()
_TYPE24_PART_B_BITS = _bits_through(MessageType24PartB, "to_starboard")
_ROT_OFFSET_BITS = _bits_through(MessageType1, "status")  # the 8-bit turn field follows


@dataclass
class _Fragments:
    """An open multi-sentence group."""

    sentences: list[AISSentence]
    line_no: int
    available: dict[TimeSource, int]  # the first fragment's times; its $PGHP comes at the end
    adjacent: Pghp | None  # the $PGHP right before the first fragment
    raw: list[str]
    broken: bool = False
    later: _Stamp | None = None  # the time of the first later fragment that has one

    def add(self, sentence: AISSentence, stamp: _Stamp | None, raw: str) -> None:
        if sentence.frag_num != len(self.sentences) + 1:
            self.broken = True
        self.sentences.append(sentence)
        self.raw.append(raw)
        if self.later is None:
            self.later = stamp


_STATIC_ONLY = (
    "ship_type",
    "to_bow",
    "to_stern",
    "to_port",
    "to_starboard",
    "draught",
    "name",
    "callsign",
    "imo",
)


class _NmeaReader:
    def __init__(
        self,
        source_name: str,
        ledger: RejectsLedger,
        time_sources: Sequence[TimeSource],
        keep_timeless: bool = False,
        counts: NmeaCounts | None = None,
    ) -> None:
        self.source_name = source_name
        self.ledger = ledger
        self.keep_timeless = keep_timeless
        self.counts = counts if counts is not None else NmeaCounts()
        self.time_sources = tuple(TimeSource(s) for s in time_sources)
        self.pending: dict[TimeSource, int] = {}  # a tag block alone on the line before
        self.open_groups: dict[tuple[str, str, int | None, int], _Fragments] = {}
        self.positions = NmeaColumns()
        self.statics = NmeaColumns()
        self.matcher = PghpMatcher()
        self.pairings: Counter[Pairing] = Counter()
        # Bound once: called for every message.
        self._release_message = self._message_released
        self._release_reject = self._reject_released
        self._static_only_appends = tuple(getattr(self.positions, n).append for n in _STATIC_ONLY)

    # -- lines ------------------------------------------------------------------------------

    def feed(self, line_no: int, line: str) -> None:
        text = line.strip()
        if not text:
            return
        matcher = self.matcher
        if matcher.dormant or matcher.undecided or matcher.queue:
            matcher.advance(line_no)
        line_tag_ms: int | None = None
        if text[0] == "\\":
            end = text.find("\\", 1)
            if end < 0:
                self._unparseable(line_no, "tag block without closing backslash", text)
                return
            line_tag_ms = self._tag_block_time(text[1:end])
            text = text[end + 1 :].strip()
            if not text:
                if line_tag_ms is not None:
                    self.pending[TimeSource.TAG_BLOCK] = line_tag_ms
                return
        if text[0] not in "!$":
            self._unparseable(line_no, "not an NMEA sentence", line.strip())
            return
        # Some receivers and converters start AIS sentences with '$'; pyais reads them too.
        if text[3:6].upper() not in ("VDM", "VDO"):
            self._other_sentence(line_no, text)
            return
        sentence_text, arrival_ms = _split_time_suffix(text)
        available = self.pending
        self.pending = {}
        if line_tag_ms is not None:
            available[TimeSource.TAG_BLOCK] = line_tag_ms
        if arrival_ms is not None:
            available[TimeSource.ARRIVAL] = arrival_ms
        self._ais_sentence(line_no, sentence_text, available)

    def _other_sentence(self, line_no: int, text: str) -> None:
        self.pending.clear()
        if text[:6].upper() == "$PGHP,":
            self.matcher.skip_adjacent()
            parsed = parse_pghp(text)
            if parsed is not None:
                self.matcher.pghp(line_no, *parsed)
            return
        # Other sentences ($PSTT, ...) are no rows, but take their $PGHP like any sentence.
        self.matcher.add(line_no, self.matcher.take_adjacent(), _written_checksum(text), None)

    def _stamp(self, available: dict[TimeSource, int]) -> _Stamp | None:
        """The time of the first source in use that ``available`` has (and its finer twin)."""
        stamp = next(((available[s], s) for s in self.time_sources if s in available), None)
        return _finer_observation(stamp, available, self.time_sources)

    def _tag_block_time(self, tag_block: str) -> int | None:
        if "c:" not in tag_block:
            return None
        try:
            block = TagBlock(tag_block.encode("ascii"))
            block.init()
        except (UnicodeEncodeError, AISBaseException, ValueError, IndexError):
            return None
        if not block.is_valid:
            return None
        return _unix_ms(block.receiver_timestamp)

    def _ais_sentence(self, line_no: int, text: str, available: dict[TimeSource, int]) -> None:
        try:
            sentence = NMEASentenceFactory.produce(text.encode("ascii"))
        except (UnicodeEncodeError, AISBaseException, ValueError) as err:
            self._bad_sentence(line_no, f"malformed sentence ({err})", text)
            return
        if not isinstance(sentence, AISSentence):
            self._bad_sentence(line_no, "malformed sentence", text)
            return
        if not sentence.is_valid:
            self._bad_sentence(line_no, "checksum does not match", text)
            return
        if sentence.frag_cnt == 1:
            self._queue_message(
                sentence,
                line_no,
                available,
                self.matcher.take_adjacent(),
                None,
                text,
                sentence.checksum,
            )
            return
        key = (text[1:6].upper(), sentence.channel, sentence.seq_id, sentence.frag_cnt)
        group = self.open_groups.get(key)
        if sentence.frag_num == 1 or group is None:
            if group is not None:
                self._incomplete(group)
            adjacent = self.matcher.take_adjacent()
            group = _Fragments(
                [sentence], line_no, available, adjacent, [text], sentence.frag_num != 1
            )
            self.open_groups[key] = group
        else:
            self.matcher.skip_adjacent()
            group.add(sentence, self._stamp(available), text)
        if sentence.frag_num == sentence.frag_cnt:
            del self.open_groups[key]
            if group.broken:
                self._incomplete(group)
            else:
                self._queue_message(
                    AISSentence.assemble_from_iterable(group.sentences),
                    group.line_no,
                    group.available,
                    group.adjacent,
                    group.later,
                    " ".join(group.raw),
                    reduce(xor, (s.checksum for s in group.sentences)),
                )

    def _queue_message(
        self,
        sentence: AISSentence,
        line_no: int,
        available: dict[TimeSource, int],
        adjacent: Pghp | None,
        later: _Stamp | None,
        raw: str,
        checksum: int,
    ) -> None:
        payload = (sentence, line_no, available, later, raw)
        self.matcher.add(line_no, adjacent, checksum, self._release_message, payload)

    def _message_released(self, payload: object, pghp: Pghp | None, how: Pairing) -> None:
        """Decode a message once its $PGHP is settled: with the times of its first sentence
        (and the $PGHP's), else the first time of a later fragment."""
        sentence, line_no, available, later, raw = cast(_MessagePayload, payload)
        self.pairings[how] += 1
        if pghp is not None:
            available[TimeSource.PGHP] = pghp.time_ms
        self._message(sentence, line_no, self._stamp(available) or later, raw)

    def finish(self) -> None:
        for group in self.open_groups.values():
            self._incomplete(group)
        self.open_groups.clear()
        self.matcher.finish()
        if self.matcher.pghp_lines:
            self.pairings[Pairing.PGHP_UNMATCHED] = self.matcher.pghp_unmatched
            for pairing in Pairing:
                self.ledger.pghp_pairing[pairing.value] += self.pairings[pairing]

    # -- messages ---------------------------------------------------------------------------

    def _message(self, sentence: AISSentence, line_no: int, stamp: _Stamp | None, raw: str) -> None:
        self.ledger.read()
        msg_type = sentence.ais_id
        if stamp is None:
            self.counts.timeless += 1
            if not self.keep_timeless:
                used = ", ".join(s.value for s in self.time_sources)
                self._reject_message(
                    RejectReason.UNPARSEABLE,
                    line_no,
                    f"no time from the time sources in use ({used}): no valid $PGHP line "
                    "for it, no tag block c: with a valid checksum, no trailing unix time",
                    raw,
                )
                return
            self.ledger.time_sources[NO_TIME_SOURCE] += 1
            timestamp = NO_TIME_MS
        else:
            timestamp, source = stamp
            self.ledger.time_sources[source.value] += 1
        if not sentence.payload:
            self._reject_message(RejectReason.UNPARSEABLE, line_no, "empty payload", raw)
            return
        if msg_type in NOT_A_VESSEL_TYPES:
            self._reject_message(
                RejectReason.NOT_A_VESSEL, line_no, f"message type {msg_type}", raw
            )
            return
        if not 1 <= msg_type <= 27:
            self._reject_message(
                RejectReason.UNPARSEABLE, line_no, f"no AIS message type {msg_type}", raw
            )
            return
        if msg_type not in POSITION_TYPES and msg_type not in STATIC_TYPES:
            self._reject_message(
                RejectReason.UNSUPPORTED_MESSAGE, line_no, f"message type {msg_type}", raw
            )
            return
        n_bits = len(sentence.bv)
        if n_bits < _REQUIRED_BITS[msg_type]:
            self._reject_message(
                RejectReason.UNPARSEABLE,
                line_no,
                f"type {msg_type} payload has {n_bits} bits, needs {_REQUIRED_BITS[msg_type]}",
                raw,
            )
            return
        try:
            decoded = sentence.decode()
        except (AISBaseException, ValueError) as err:
            self._reject_message(RejectReason.UNPARSEABLE, line_no, f"undecodable ({err})", raw)
            return
        if msg_type == 24:
            partno = cast(_Type24Message, decoded).partno
            if partno not in (0, 1):
                self._reject_message(
                    RejectReason.UNPARSEABLE, line_no, f"type 24 part number {partno}", raw
                )
                return
            if partno == 1 and n_bits < _TYPE24_PART_B_BITS:
                self._reject_message(
                    RejectReason.UNPARSEABLE,
                    line_no,
                    f"type 24 part B payload has {n_bits} bits, needs {_TYPE24_PART_B_BITS}",
                    raw,
                )
                return
        if msg_type in POSITION_TYPES:
            self._add_position(cast(_PositionMessage, decoded), sentence, msg_type, timestamp)
            self.positions.line_no.append(line_no)
        else:
            _append_static(self.statics, cast(_StaticMessage, decoded), msg_type, timestamp)
            self.statics.line_no.append(line_no)

    def _add_position(
        self, decoded: _PositionMessage, sentence: AISSentence, msg_type: int, timestamp: int
    ) -> None:
        columns = self.positions
        columns.timestamp.append(timestamp)
        columns.mmsi.append(decoded.mmsi)
        columns.msg_type.append(msg_type)
        columns.lat.append(decoded.lat)
        columns.lon.append(decoded.lon)
        columns.sog.append(decoded.speed)
        columns.cog.append(decoded.course)
        columns.heading.append(getattr(decoded, "heading", None))
        status = getattr(decoded, "status", None)
        columns.nav_status.append(None if status is None else int(status))
        # pyais rounds the rate of turn to whole degrees per minute (raw 1-2 become 0), so we
        # read the raw field through pyais's bit vector and convert it in _positions_table.
        columns.rot_raw.append(
            sentence.bv.get_signed(_ROT_OFFSET_BITS, 8) if msg_type <= 3 else None
        )
        if msg_type == 19:
            _append_static_fields(columns, decoded)
        else:
            for append in self._static_only_appends:
                append(None)

    # -- rejects ----------------------------------------------------------------------------

    def _example(self, line_no: int, why: str, raw: str) -> str:
        shown = raw if len(raw) <= _EXAMPLE_CHARS else raw[:_EXAMPLE_CHARS] + "..."
        return f"{self.source_name}:{line_no}: {why}: {shown}"

    def _reject_message(self, reason: RejectReason, line_no: int, why: str, raw: str) -> None:
        self.ledger.reject(reason, example=self._example(line_no, why, raw))

    def _queue_reject(
        self, reason: RejectReason, line_no: int, why: str, raw: str, adjacent: Pghp | None = None
    ) -> None:
        """Count a reject in its turn, after the messages before it (file order)."""
        self.matcher.add(line_no, adjacent, None, self._release_reject, (reason, line_no, why, raw))

    def _reject_released(self, payload: object, _pghp: Pghp | None, _how: Pairing) -> None:
        reason, line_no, why, raw = cast(tuple[RejectReason, int, str, str], payload)
        self.ledger.read()
        self._reject_message(reason, line_no, why, raw)

    def _unparseable(self, line_no: int, why: str, raw: str) -> None:
        self._queue_reject(RejectReason.UNPARSEABLE, line_no, why, raw)

    def _bad_sentence(self, line_no: int, why: str, raw: str) -> None:
        """An AIS sentence line that cannot be read: no $PGHP can time it."""
        self.matcher.skip_adjacent()
        self._unparseable(line_no, why, raw)

    def _incomplete(self, group: _Fragments) -> None:
        have = ",".join(str(s.frag_num) for s in group.sentences)
        self._queue_reject(
            RejectReason.INCOMPLETE_MULTIPART,
            group.line_no,
            f"fragments {have} of {group.sentences[0].frag_cnt}",
            " ".join(group.raw),
            group.adjacent,
        )


def _append_static_fields(columns: NmeaColumns, decoded: Payload) -> None:
    ship_type = getattr(decoded, "ship_type", None)
    columns.ship_type.append(None if ship_type is None else int(ship_type))
    for name in ("to_bow", "to_stern", "to_port", "to_starboard"):
        getattr(columns, name).append(getattr(decoded, name, None))
    columns.draught.append(getattr(decoded, "draught", None))
    columns.name.append(getattr(decoded, "shipname", None))
    columns.callsign.append(getattr(decoded, "callsign", None))
    columns.imo.append(getattr(decoded, "imo", None))


def _append_static(
    columns: NmeaColumns, decoded: _StaticMessage, msg_type: int, timestamp: int
) -> None:
    columns.timestamp.append(timestamp)
    columns.mmsi.append(decoded.mmsi)
    columns.msg_type.append(msg_type)
    _append_static_fields(columns, decoded)


def _finer_observation(
    stamp: tuple[int, TimeSource] | None,
    available: dict[TimeSource, int],
    in_use: Sequence[TimeSource],
) -> tuple[int, TimeSource] | None:
    """A whole-second observation time gives way to the other observation source's time of
    the same second with milliseconds (a DMA line with ``c:`` seconds and a ``$PGHP``)."""
    if stamp is None or stamp[1] is TimeSource.ARRIVAL or stamp[0] % 1000:
        return stamp
    for source in (TimeSource.TAG_BLOCK, TimeSource.PGHP):
        finer = available.get(source) if source in in_use else None
        if finer is not None and finer % 1000 and finer // 1000 == stamp[0] // 1000:
            return finer, source
    return stamp


def _split_time_suffix(text: str) -> tuple[str, int | None]:
    """``!AIVDM,...,0*5C,1384257600`` (or ``... 0*5C 1384257600``) -> (the sentence,
    1384257600000 ms): the last field after the checksum, comma- or space-separated."""
    star = text.rfind("*")
    if star < 0 or len(text) <= star + 3:
        return text, None
    rest = text[star + 3 :]
    if rest[0] != "," and not rest[0].isspace():
        return text, None
    return text[: star + 3], _unix_ms(_TRAILER_SEPARATORS.split(rest.strip(", \t"))[-1])


def _unix_ms(value: str | None) -> int | None:
    """A unix time in seconds (or milliseconds, above 1e11) as integer milliseconds."""
    if not value:
        return None
    try:
        seconds = float(value)
    except ValueError:
        return None
    if seconds > _UNIX_MS_THRESHOLD:
        seconds /= 1000.0
    if not 0 < seconds < _MAX_UNIX_S:
        return None
    return round(seconds * 1000.0)


def _nmea_checksum_ok(text: str) -> bool:
    star = text.rfind("*")
    if star < 1 or len(text) < star + 3:
        return False
    try:
        computed = reduce(xor, text[1:star].encode("ascii"), 0)
    except UnicodeEncodeError:
        return False
    return computed == _hex_byte(text[star + 1 : star + 3])


def pghp_time_ms(text: str) -> int | None:
    """The time of a Gatehouse ``$PGHP`` line in milliseconds, or None (``parse_pghp``)."""
    parsed = parse_pghp(text)
    return None if parsed is None else parsed[0]


def parse_pghp(text: str) -> tuple[int, int | None] | None:
    """The time of a Gatehouse ``$PGHP`` line in milliseconds and the checksum of the
    sentence it times (None if it gives none), or None if it gives no time.

    Fields: ``$PGHP,<type>,<year>,<month>,<day>,<hour>,<minute>,<second>,<millisecond>,...``.
    What follows the milliseconds varies by feed (DMA: country, region, site MMSI, online
    flag; satellite feeds: the origin, e.g. ``1AIS_S``) and is not read, up to the 14th field:
    the sentence's checksum (nmea_pghp.py). The line's own checksum must match and the date
    must exist.
    """
    if not _nmea_checksum_ok(text):
        return None
    fields = text[: text.rfind("*")].split(",")
    if len(fields) < 9:
        return None
    try:
        year, month, day, hour, minute, second, millisecond = map(int, fields[2:9])
    except ValueError:
        return None
    day_ms = _day_start_ms(year, month, day)
    if day_ms is None or not (
        0 <= hour < 24 and 0 <= minute < 60 and 0 <= second < 60 and 0 <= millisecond < 1000
    ):
        return None
    checksum = _hex_byte(fields[13]) if len(fields) > 13 else None
    return day_ms + ((hour * 60 + minute) * 60 + second) * 1000 + millisecond, checksum


@lru_cache(maxsize=256)
def _day_start_ms(year: int, month: int, day: int) -> int | None:
    """Midnight UTC of a date that exists, in milliseconds (a log's lines share a few)."""
    try:
        return round(datetime(year, month, day, tzinfo=UTC).timestamp()) * 1000
    except (ValueError, OverflowError):
        return None


def _hex_byte(digits: str) -> int | None:
    """Two hex digits (an NMEA checksum) as an int, else None."""
    if len(digits) != 2 or not digits.isalnum():  # int() would take "+1" or " 1"
        return None
    try:
        return int(digits, 16)
    except ValueError:
        return None


def _written_checksum(text: str) -> int | None:
    """The checksum a sentence line carries after its ``*`` (not checked)."""
    star = text.rfind("*")
    return None if star < 0 else _hex_byte(text[star + 1 : star + 3])


def read_nmea(
    lines: Iterable[str],
    source_name: str,
    ledger: RejectsLedger,
    time_sources: Sequence[TimeSource] = DEFAULT_TIME_SOURCES,
    keep_timeless: bool = False,
    counts: NmeaCounts | None = None,
) -> Iterator[AisBatch]:
    """Decode a raw NMEA AIS log into one batch of positions and static reports.

    ``lines`` are the log's text lines; ``source_name`` names the file in reject examples
    ("file:line: why: sentence"). Every AIS message is counted with ``ledger.read()`` and
    becomes one output row or one reject (see the module docstring for the rules).
    ``time_sources``: which times to use, in order of precedence. ``keep_timeless``: keep
    the messages without a time (null timestamp) instead of rejecting them; ``counts``
    receives how many there were either way.
    """
    reader = _NmeaReader(source_name, ledger, time_sources, keep_timeless, counts)
    ledger.time_source_order = tuple(s.value for s in reader.time_sources)
    for line_no, line in enumerate(lines, start=1):
        reader.feed(line_no, line.lstrip("\ufeff") if line_no == 1 else line)
    reader.finish()
    yield nmea_batch(reader.positions, reader.statics, source_name, ledger)
