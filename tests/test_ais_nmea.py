"""The raw NMEA reader: input forms, reassembly, sentinels, accounting and the static join."""

from __future__ import annotations

import functools
import gzip
import itertools
from collections.abc import Iterator
from datetime import UTC, datetime, timedelta
from functools import reduce
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pyais import encode_dict
from pyais.util import compute_checksum

from colregs9_cli.ais.batch import AisBatch
from colregs9_cli.ais.clean import SHIP_TYPE_CATEGORIES
from colregs9_cli.ais.ledger import RejectReason, RejectsLedger
from colregs9_cli.ais.nmea import pghp_time_ms, read_nmea
from colregs9_cli.ais.time_sources import DEFAULT_TIME_SOURCES, TimeSource
from colregs9_cli.errors import InputFileError

NOON = 1_384_257_600  # 2013-11-12 12:00:00 UTC


def _read(
    lines: list[str], time_sources: tuple[TimeSource, ...] = DEFAULT_TIME_SOURCES
) -> tuple[AisBatch, RejectsLedger]:
    ledger = RejectsLedger()
    batches = list(read_nmea(lines, "log.nmea", ledger, time_sources))
    assert len(batches) == 1
    batch = batches[0]
    # Every message is one output row or one reader reject.
    assert (
        ledger.rows_read
        == batch.positions.num_rows + batch.statics.num_rows + ledger.rejected_total
    )
    return batch, ledger


def _checksum(body: str) -> str:
    return f"{reduce(lambda acc, char: acc ^ ord(char), body, 0):02X}"


def _tag(body: str) -> str:
    return f"\\{body}*{_checksum(body)}\\"


def _pghp(when: datetime) -> str:
    body = f"PGHP,1,{when:%Y,%m,%d,%H,%M,%S},{when.microsecond // 1000},219,,2190067,1,00"
    return f"${body}*{_checksum(body)}"


def _sentences(channel: str = "A", seq_id: int | None = None, **fields: object) -> list[str]:
    return encode_dict(fields, sentence_type="VDM", radio_channel=channel, seq_id=seq_id)


def _position(mmsi: int = 219000001, **fields: object) -> str:
    values: dict[str, object] = {"type": 1, "mmsi": mmsi, "lat": 57.05, "lon": 9.92}
    values.update(fields)
    (sentence,) = _sentences(**values)
    return sentence


def _type5(
    mmsi: int = 219000001, seq_id: int = 3, channel: str = "A", **fields: object
) -> list[str]:
    values: dict[str, object] = {
        "type": 5,
        "mmsi": mmsi,
        "shipname": "TEST SHIP",
        "callsign": "OXAB",
        "imo": 9123456,
        "ship_type": 70,
        "to_bow": 30,
        "to_stern": 10,
        "to_port": 4,
        "to_starboard": 6,
        "draught": 5.2,
    }
    values.update(fields)
    return _sentences(channel=channel, seq_id=seq_id, **values)


def _at(seconds: int, sentence: str) -> str:
    return f"{sentence},{NOON + seconds}"


def _rows(table: object) -> list[dict[str, object]]:
    return table.to_pylist()  # type: ignore[attr-defined]


# -- input forms ----------------------------------------------------------------------------


def test_pghp_line_stamps_the_next_sentence_to_the_millisecond() -> None:
    when = datetime(2013, 11, 12, 12, 0, 7, 979_000, tzinfo=UTC)
    batch, ledger = _read([_tag("si:AISD"), _pghp(when), _position()])
    (row,) = _rows(batch.positions)
    assert row["timestamp"] == when
    assert ledger.time_sources == {"pghp": 1}
    assert row["mmsi"] == 219000001
    assert row["mobile_type"] == "Class A"


def test_tag_block_c_on_the_same_line() -> None:
    batch, _ = _read([_tag(f"s:rORBCOMM,c:{NOON + 42}") + _position()])
    assert _rows(batch.positions)[0]["timestamp"] == datetime(2013, 11, 12, 12, 0, 42, tzinfo=UTC)


def test_tag_block_c_in_milliseconds_and_alone_on_the_line_before() -> None:
    batch, _ = _read([_tag(f"c:{(NOON + 5) * 1000 + 900}"), _position()])
    assert _rows(batch.positions)[0]["timestamp"] == datetime(
        2013, 11, 12, 12, 0, 5, 900_000, tzinfo=UTC
    )


def test_trailing_unix_time_after_the_checksum() -> None:
    batch, ledger = _read([f"{_position()},{NOON + 61}.75"])
    assert _rows(batch.positions)[0]["timestamp"] == datetime(
        2013, 11, 12, 12, 1, 1, 750_000, tzinfo=UTC
    )
    assert ledger.time_sources == {"arrival": 1}


def test_a_unix_time_after_a_space_is_the_arrival_time() -> None:
    batch, ledger = _read([f"{_position()} {NOON + 61}.011"])
    assert _rows(batch.positions)[0]["timestamp"] == datetime(
        2013, 11, 12, 12, 1, 1, 11_000, tzinfo=UTC
    )
    assert ledger.time_sources == {"arrival": 1}


def test_a_byte_order_mark_before_the_first_sentence_is_ignored() -> None:
    with_bom, _ = _read(["\ufeff" + _at(0, _position(219000001)), _at(1, _position(219000002))])
    assert [r["mmsi"] for r in _rows(with_bom.positions)] == [219000001, 219000002]


def test_ais_sentences_written_with_a_dollar_are_read() -> None:
    dollar = "$" + _position(219000002)[1:]
    batch, ledger = _read([_at(0, _position(219000001)), _at(1, dollar)])
    assert [r["mmsi"] for r in _rows(batch.positions)] == [219000001, 219000002]
    assert ledger.rejected_total == 0


def test_a_tag_block_with_a_bad_checksum_gives_no_time_and_says_why() -> None:
    body = f"s:r1,c:{NOON}"
    bad = f"\\{body}*{int(_checksum(body), 16) ^ 1:02X}\\"
    batch, ledger = _read([bad + _position()])
    assert batch.positions.num_rows == 0
    (example,) = ledger.examples[RejectReason.UNPARSEABLE.value]
    assert "no tag block c: with a valid checksum" in example
    good, _ = _read([_tag(body) + _position()])
    assert good.positions.num_rows == 1


def test_a_tag_block_c_beats_a_pending_pghp_time() -> None:
    pghp = _pghp(datetime(2013, 11, 12, 13, 0, 0, tzinfo=UTC))
    batch, _ = _read([pghp, _tag(f"c:{NOON}") + _position()])
    assert _rows(batch.positions)[0]["timestamp"] == datetime(2013, 11, 12, 12, 0, 0, tzinfo=UTC)


def test_a_whole_second_tag_block_gives_way_to_the_pghp_milliseconds_of_its_second() -> None:
    # The DMA layout of dma-ais: "\\c:<seconds>\\" on the sentence and a $PGHP before it.
    fine = datetime(2013, 11, 12, 12, 0, 18, 375_000, tzinfo=UTC)
    batch, ledger = _read([_pghp(fine), _tag(f"c:{NOON + 18}") + _position()])
    assert _rows(batch.positions)[0]["timestamp"] == fine
    assert ledger.time_sources == {"pghp": 1}
    # Another second is another observation: the tag block's order holds.
    later = datetime(2013, 11, 12, 12, 0, 19, 375_000, tzinfo=UTC)
    batch, _ = _read([_pghp(later), _tag(f"c:{NOON + 18}") + _position()])
    assert _rows(batch.positions)[0]["timestamp"] == datetime(2013, 11, 12, 12, 0, 18, tzinfo=UTC)
    # A $PGHP left out of the sources in use lends no milliseconds.
    batch, _ = _read(
        [_pghp(fine), _tag(f"c:{NOON + 18}") + _position()],
        time_sources=(TimeSource.TAG_BLOCK,),
    )
    assert _rows(batch.positions)[0]["timestamp"] == datetime(2013, 11, 12, 12, 0, 18, tzinfo=UTC)


def test_bare_sentence_without_any_time_is_unparseable_with_an_example() -> None:
    batch, ledger = _read([_position()])
    assert batch.positions.num_rows == 0
    assert ledger.rows_read == 1
    assert ledger.rejects == {RejectReason.UNPARSEABLE.value: 1}
    (example,) = ledger.examples[RejectReason.UNPARSEABLE.value]
    assert example.startswith("log.nmea:1: no time")
    assert _position() in example


def test_pghp_time_is_used_by_the_next_sentence_only() -> None:
    # DMA's $PSTT status line sits between a $PGHP and the next AIS sentence: the $PGHP
    # stamped the $PSTT, so the AIS sentence after it has no time.
    pghp = _pghp(datetime(2013, 11, 12, 12, 0, 0, tzinfo=UTC))
    pstt = "$PSTT,30A,20131112,120000*6D"
    batch, ledger = _read(
        [pghp, _position(mmsi=219000001), _position(mmsi=219000002), pghp, pstt, _position()]
    )
    assert [row["mmsi"] for row in _rows(batch.positions)] == [219000001]
    assert ledger.rejects == {RejectReason.UNPARSEABLE.value: 2}


# -- reassembly -----------------------------------------------------------------------------


def test_two_fragment_type5_is_reassembled_into_one_static_row() -> None:
    fragments = _type5()
    assert len(fragments) == 2
    batch, ledger = _read([_at(0, fragments[0]), fragments[1]])
    assert ledger.rows_read == 1
    assert batch.positions.num_rows == 0
    (row,) = _rows(batch.statics)
    assert row == {
        "timestamp": datetime(2013, 11, 12, 12, 0, 0, tzinfo=UTC),
        "mmsi": 219000001,
        "ship_type": "Cargo",
        "length_m": 40.0,
        "breadth_m": 10.0,
        "to_bow_m": 30.0,
        "to_stern_m": 10.0,
        "to_port_m": 4.0,
        "to_starboard_m": 6.0,
        "draught_m": 5.2,
        "name": "TEST SHIP",
        "callsign": "OXAB",
        "imo": 9123456,
    }


def test_interleaved_fragments_of_different_messages() -> None:
    first = _type5(mmsi=219000001, seq_id=1, channel="A")
    second = _type5(mmsi=219000002, seq_id=2, channel="A", draught=3.0)
    third = _type5(mmsi=219000003, seq_id=1, channel="B", draught=7.5)
    lines = [_at(0, first[0]), _at(1, second[0]), _at(2, third[0]), third[1], first[1], second[1]]
    batch, ledger = _read(lines)
    assert ledger.rejected_total == 0
    got = {(row["mmsi"], row["draught_m"], row["timestamp"].second) for row in _rows(batch.statics)}
    assert got == {(219000001, 5.2, 0), (219000002, 3.0, 1), (219000003, 7.5, 2)}


def test_orphan_and_unfinished_fragments_are_incomplete() -> None:
    head, tail = _type5(seq_id=4)
    lines = [
        _at(0, tail),  # a last fragment whose first never came
        _at(1, head),  # a first fragment restarted by the next one with the same id
        _at(2, head),
        tail,  # completes the second start
        _at(3, head),  # never finished
    ]
    batch, ledger = _read(lines)
    assert batch.statics.num_rows == 1
    assert _rows(batch.statics)[0]["timestamp"].second == 2
    assert ledger.rows_read == 4
    assert ledger.rejects == {RejectReason.INCOMPLETE_MULTIPART.value: 3}
    assert ledger.examples[RejectReason.INCOMPLETE_MULTIPART.value][0].startswith(
        "log.nmea:1: fragments 2 of 2"
    )


def test_a_gap_or_a_repeat_breaks_the_group_once() -> None:
    first, second, third = _sentences(seq_id=9, type=8, mmsi=219000001, data=b"x" * 90)
    complete = [_at(0, first), second, third]
    repeated = [_at(1, first), second, second, third]
    gap = [_at(2, first), third]
    batch, ledger = _read(complete + repeated + gap)
    assert batch.positions.num_rows == batch.statics.num_rows == 0
    assert ledger.rows_read == 3
    assert ledger.rejects == {
        RejectReason.UNSUPPORTED_MESSAGE.value: 1,  # the complete type 8
        RejectReason.INCOMPLETE_MULTIPART.value: 2,
    }
    repeat_example, gap_example = ledger.examples[RejectReason.INCOMPLETE_MULTIPART.value]
    assert repeat_example.startswith("log.nmea:4: fragments 1,2,2,3 of 3: !AIVDM,3,1,9,A,")
    assert gap_example.startswith("log.nmea:8: fragments 1,3 of 3: !AIVDM,3,1,9,A,")


def test_bad_checksum_is_unparseable_and_orphans_the_rest_of_its_message() -> None:
    single = _position()
    bad_single = single[:-2] + ("00" if single[-2:] != "00" else "11")
    head, tail = _type5(seq_id=6)
    bad_head = head[:-2] + ("00" if head[-2:] != "00" else "11")
    batch, ledger = _read([_at(0, bad_single), _at(1, bad_head), tail, "garbage line", ""])
    assert batch.positions.num_rows == 0
    assert batch.statics.num_rows == 0
    assert ledger.rejects == {
        RejectReason.UNPARSEABLE.value: 3,  # two bad checksums and the garbage line
        RejectReason.INCOMPLETE_MULTIPART.value: 1,
    }
    examples = ledger.examples[RejectReason.UNPARSEABLE.value]
    assert examples[0].startswith("log.nmea:1: checksum does not match: !AIVDM,1,1,")
    assert examples[2] == "log.nmea:4: not an NMEA sentence: garbage line"


# -- message types --------------------------------------------------------------------------


def test_message_types_are_sorted_into_rows_and_rejects() -> None:
    lines = [
        _at(0, _position()),
        _at(0, _sentences(type=4, mmsi=2190067)[0]),  # base station
        _at(0, _sentences(type=9, mmsi=111219001)[0]),  # SAR aircraft
        _at(0, _sentences(type=21, mmsi=992191001, name="BUOY")[0]),  # AtoN
        _at(0, _sentences(type=8, mmsi=219000001, data=b"\x00")[0]),  # binary broadcast
        _at(0, _sentences(type=18, mmsi=219000009, lat=57.0, lon=10.0)[0]),
        _at(0, _sentences(type=24, partno=0, mmsi=219000009, shipname="SMALL")[0]),
    ]
    batch, ledger = _read(lines)
    assert [row["mobile_type"] for row in _rows(batch.positions)] == ["Class A", "Class B"]
    assert batch.statics.num_rows == 1
    assert ledger.rejects == {
        RejectReason.NOT_A_VESSEL.value: 3,
        RejectReason.UNSUPPORTED_MESSAGE.value: 1,
    }


def test_truncated_payload_is_unparseable() -> None:
    fields = _position().split(",")
    body = ",".join([*fields[:5], fields[5][:20], "0"])[1:].split("*")[0]
    batch, ledger = _read([_at(0, f"!{body}*{_checksum(body)}")])
    assert batch.positions.num_rows == 0
    assert ledger.rejects == {RejectReason.UNPARSEABLE.value: 1}
    assert "payload has 120 bits, needs 137" in ledger.examples[RejectReason.UNPARSEABLE.value][0]


def test_empty_payload_and_undefined_message_type_are_unparseable() -> None:
    bodies = ["AIVDM,1,1,,A,,0", "AIVDM,1,1,,A,h000000000000000000000000000,0"]
    _, ledger = _read([_at(0, f"!{body}*{_checksum(body)}") for body in bodies])
    assert ledger.rejects == {RejectReason.UNPARSEABLE.value: 2}
    empty, type48 = ledger.examples[RejectReason.UNPARSEABLE.value]
    assert empty.startswith("log.nmea:1: empty payload: ")
    assert type48.startswith("log.nmea:2: no AIS message type 48: ")


# -- sentinels ------------------------------------------------------------------------------


def test_not_available_values_become_null() -> None:
    sentinels = _position(
        lat=91, lon=181, speed=102.3, course=360, heading=511, turn=-128, status=15
    )
    batch, _ = _read([_at(0, sentinels)])
    (row,) = _rows(batch.positions)
    for name in ("lat_deg", "lon_deg", "sog_kn", "cog_deg", "heading_deg", "rot_deg_per_min"):
        assert row[name] is None, name
    assert row["nav_status"] == 15  # "undefined" is a real ITU code, kept as is


def test_present_values_and_rate_of_turn() -> None:
    # encode_dict stores turn 5 deg/min as round(4.733 * sqrt(5)) = 11; the ITU formula
    # gives back (11 / 4.733)^2 = 5.4015 deg/min.
    moving = _position(
        lat=57.05, lon=9.92, speed=12.3, course=271.5, heading=270, turn=-5, status=0
    )
    batch, _ = _read([_at(0, moving)])
    (row,) = _rows(batch.positions)
    assert row["lat_deg"] == pytest.approx(57.05)
    assert row["lon_deg"] == pytest.approx(9.92)
    assert row["sog_kn"] == pytest.approx(12.3)
    assert row["cog_deg"] == pytest.approx(271.5)
    assert row["heading_deg"] == 270
    assert row["rot_deg_per_min"] == pytest.approx(-((11 / 4.733) ** 2))
    assert row["nav_status"] == 0
    assert row["length_m"] is None  # no static report for this vessel


def test_rate_of_turn_without_turn_indicator_is_null() -> None:
    batch, _ = _read([_at(0, _position(turn=127)), _at(0, _position(turn=-127))])
    assert [row["rot_deg_per_min"] for row in _rows(batch.positions)] == [None, None]


def test_long_range_type27_sentinels() -> None:
    absent = _sentences(type=27, mmsi=219000002, lat=91, lon=181, speed=63, course=511, status=5)[0]
    present = _sentences(
        type=27, mmsi=219000002, lat=57.1, lon=9.9, speed=62, course=359, status=5
    )[0]
    batch, _ = _read([_at(0, absent), _at(1, present)])
    first, second = _rows(batch.positions)
    assert (first["lat_deg"], first["lon_deg"], first["sog_kn"], first["cog_deg"]) == (
        None,
        None,
        None,
        None,
    )
    assert second["lat_deg"] == pytest.approx(57.1)
    assert (second["sog_kn"], second["cog_deg"], second["nav_status"]) == (62.0, 359.0, 5)
    assert second["heading_deg"] is None and second["mobile_type"] == "Class A"


def test_zero_dimensions_draught_and_ship_type_are_null() -> None:
    head, tail = _type5(
        to_bow=0, to_stern=12, to_port=3, to_starboard=3, draught=0, ship_type=0, imo=0
    )
    batch, _ = _read([_at(0, head), tail])
    (row,) = _rows(batch.statics)
    assert row["length_m"] is None  # A = 0: the length is not known
    assert row["breadth_m"] == 6.0
    assert row["draught_m"] is None
    assert row["ship_type"] is None
    assert row["imo"] is None


def test_type24_parts_and_type19_carry_their_own_statics() -> None:
    part_a = _sentences(type=24, partno=0, mmsi=219000009, shipname="SMALL")[0]
    part_b = _sentences(
        type=24,
        partno=1,
        mmsi=219000009,
        ship_type=37,
        callsign="OU1234",
        to_bow=5,
        to_stern=4,
        to_port=1,
        to_starboard=2,
    )[0]
    type19 = _sentences(
        type=19,
        mmsi=219000010,
        lat=57.0,
        lon=10.0,
        shipname="EXTENDED",
        ship_type=52,
        to_bow=20,
        to_stern=8,
        to_port=4,
        to_starboard=4,
    )[0]
    batch, _ = _read([_at(0, part_a), _at(1, part_b), _at(2, type19)])
    a, b = _rows(batch.statics)
    assert (a["name"], a["length_m"], a["breadth_m"], a["ship_type"]) == ("SMALL", None, None, None)
    assert (b["name"], b["length_m"], b["breadth_m"]) == (None, 9.0, 3.0)
    assert (b["ship_type"], b["callsign"]) == ("Pleasure", "OU1234")
    (position,) = _rows(batch.positions)
    assert position["mobile_type"] == "Class B"
    assert (position["name"], position["ship_type"]) == ("EXTENDED", "Tug")
    assert (position["length_m"], position["breadth_m"]) == (28.0, 8.0)


# -- static join ----------------------------------------------------------------------------


def test_join_takes_each_field_from_the_nearest_report_that_has_it() -> None:
    early = _type5(draught=4.0, seq_id=1)
    late = _type5(draught=6.0, seq_id=2, to_bow=0)  # a later report that lost its length
    name_only = _sentences(type=24, partno=0, mmsi=219000001, shipname="RENAMED")[0]
    lines = [
        _at(5, _position()),  # before every static report
        _at(10, early[0]),
        early[1],
        _at(80, _position()),
        _at(100, late[0]),
        late[1],
        _at(101, name_only),
        _at(150, _position()),
        _at(150, _position(mmsi=219000077)),  # a vessel with no static report
    ]
    batch, _ = _read(lines)
    rows = _rows(batch.positions)
    assert [row["draught_m"] for row in rows] == [4.0, 6.0, 6.0, None]
    # Length: the nearest report with a length is the early one, for every position.
    assert [row["length_m"] for row in rows] == [40.0, 40.0, 40.0, None]
    assert [row["name"] for row in rows] == ["TEST SHIP", "TEST SHIP", "RENAMED", None]
    assert [row["ship_type"] for row in rows] == ["Cargo", "Cargo", "Cargo", None]
    assert [row["imo"] for row in rows] == [9123456, 9123456, 9123456, None]


def test_type19_own_dimensions_win_over_joined_ones() -> None:
    head, tail = _type5(mmsi=219000010, to_bow=50, to_stern=50)
    type19 = _sentences(
        type=19,
        mmsi=219000010,
        lat=57.0,
        lon=10.0,
        ship_type=52,
        to_bow=20,
        to_stern=8,
        to_port=4,
        to_starboard=4,
    )[0]
    type18 = _sentences(type=18, mmsi=219000010, lat=57.0, lon=10.0)[0]
    batch, _ = _read([_at(0, head), tail, _at(1, type19), _at(2, type18)])
    own, joined = _rows(batch.positions)
    assert own["length_m"] == 28.0
    assert own["draught_m"] == 5.2  # not in type 19, so joined from type 5
    assert joined["length_m"] == 28.0  # the type 19 report is nearer than the type 5


# -- other contract points ------------------------------------------------------------------


def test_empty_input_gives_one_empty_batch() -> None:
    batch, ledger = _read([])
    assert batch.positions.num_rows == batch.statics.num_rows == ledger.rows_read == 0


def test_loader_errors_propagate() -> None:
    def truncated() -> Iterator[str]:
        yield _at(0, _position())
        raise InputFileError("log.nmea.gz: truncated gzip")

    with pytest.raises(InputFileError, match="truncated gzip"):
        list(read_nmea(truncated(), "log.nmea.gz", RejectsLedger()))


def test_ship_type_categories() -> None:
    assert 0 not in SHIP_TYPE_CATEGORIES
    expected = {
        30: "Fishing",
        31: "Towing",
        35: "Military",
        36: "Sailing",
        37: "Pleasure",
        45: "HSC",
    }
    expected |= {50: "Pilot", 51: "SAR", 52: "Tug", 53: "Port tender", 55: "Law enforcement"}
    expected |= {
        58: "Medical",
        60: "Passenger",
        69: "Passenger",
        70: "Cargo",
        84: "Tanker",
        99: "Other",
    }
    for code, text in expected.items():
        assert SHIP_TYPE_CATEGORIES[code] == text
    assert set(SHIP_TYPE_CATEGORIES) == set(range(1, 100))


_POOL = [
    _at(0, _position()),
    _at(1, _position(mmsi=219000002, lat=91)),
    *[_at(2, line) for line in _type5(seq_id=7)],
    *_type5(seq_id=8, channel="B"),
    _at(3, _sentences(type=4, mmsi=2190067)[0]),
    "$PGHP,1,2013,11,12,12,0,0,11,219,,2190067,1,62*26",
    _tag("si:AISD"),
    "not nmea",
    _position()[:-2] + "ZZ",
]


@settings(max_examples=60, deadline=None)
@given(st.lists(st.sampled_from(_POOL), max_size=25))
def test_every_message_is_a_row_or_a_reject(lines: list[str]) -> None:
    _read(lines)


# -- the real DMA fixture -------------------------------------------------------------------
#
# Expected numbers come from an independent script that does not use pyais or this module:
# it splits each !..VDM/!..VDO line on commas, verifies the XOR checksum, joins fragments by
# (tag, channel, sequence id, count), turns the payload into a bit string (char - 48, minus 8
# above 40, six bits each) and reads the type, MMSI and lat/lon fields at their ITU-R M.1371
# bit offsets. It finds 80,246 lines, 26,146 sentences (69 two-fragment type 5 messages, all
# complete, no bad checksum), so 26,077 messages: types 1: 20,044, 3: 4,151, 18: 493 (24,688
# positions of 1,438 MMSIs), 5: 69 and 24: 61 (30 part A, 31 part B; 130 statics of 122
# MMSIs), 4: 1,234 and 21: 25 (1,259 not vessels). SOURCES.md's "25,947 positions from 1,503
# MMSIs" and "2,216 from 129 vessels" in the Limfjord box count base stations and AtoNs too:
# 24,688 + 1,259 = 25,947 and 2,160 + 56 (two stations) = 2,216.


@pytest.fixture(scope="module")
def dma(fixtures_dir: Path) -> tuple[AisBatch, RejectsLedger]:
    with gzip.open(
        fixtures_dir / "ais" / "dma_nmea_2013-11-12_5min.txt.gz", "rt", encoding="ascii"
    ) as log:
        return _read(log.read().splitlines())


def test_dma_fixture_counts(dma: tuple[AisBatch, RejectsLedger]) -> None:
    batch, ledger = dma
    positions = batch.positions.to_pandas()
    assert ledger.rows_read == 26_077
    assert len(positions) == 24_688
    assert batch.statics.num_rows == 130
    assert ledger.rejects == {RejectReason.NOT_A_VESSEL.value: 1_259}
    assert ledger.rows_read == len(positions) + batch.statics.num_rows + ledger.rejected_total
    assert positions["mmsi"].nunique() == 1_438
    assert batch.statics.to_pandas()["mmsi"].nunique() == 122
    assert positions["mobile_type"].value_counts().to_dict() == {"Class A": 24_195, "Class B": 493}
    # Type 18 has no navigational status; every Class A report here has one.
    assert positions["nav_status"].notna().sum() == 24_195
    # $PGHP times to the millisecond (the first and last lines of the file)
    assert positions["timestamp"].min() == pd.Timestamp("2013-11-12 12:00:00.011", tz="UTC")
    assert positions["timestamp"].max() == pd.Timestamp("2013-11-12 12:04:59.979", tz="UTC")
    assert (positions["timestamp"].dt.microsecond % 1000 == 0).all()
    assert (positions["timestamp"].dt.microsecond != 0).mean() > 0.99
    assert dma[1].time_sources == {"pghp": 26_077}  # every message, DMA stamps each


def test_dma_fixture_limfjord_box(dma: tuple[AisBatch, RejectsLedger]) -> None:
    positions = dma[0].positions.to_pandas()
    box = positions[
        positions["lat_deg"].between(56.5, 57.2) & positions["lon_deg"].between(8.2, 10.4)
    ]
    assert len(box) == 2_160
    assert box["mmsi"].nunique() == 127


def test_dma_fixture_static_join(dma: tuple[AisBatch, RejectsLedger]) -> None:
    batch, _ = dma
    positions = batch.positions.to_pandas()
    # Independently: positions whose MMSI has a type 5 with draught > 0 (1,018 of 57 vessels)
    # or a type 5 / 24B with A > 0 and B > 0 (1,273 of 94); 96 static rows have a length.
    with_draught = positions[positions["draught_m"].notna()]
    assert (len(with_draught), with_draught["mmsi"].nunique()) == (1_018, 57)
    with_length = positions[positions["length_m"].notna()]
    assert (len(with_length), with_length["mmsi"].nunique()) == (1_273, 94)
    assert batch.statics.to_pandas()["length_m"].notna().sum() == 96
    # The fishing vessel 205550000 "O-156": its type 5 (lines 3846-3848, $PGHP 12:00:12)
    #   !BSVDM,2,1,3,B,5341id000000u0Ib220vo7GJ222222222222220N1p?5540Ht@1RDj2C,0*3B
    #   !BSVDM,2,2,3,B,Qp1lSmCQ4p88880,2*29
    # decodes by hand to A 15, B 15, C 5, D 5, draught 64 dm, ship type 30, IMO 0. Its first
    # position (12:00:05) comes before that report and must still get the dimensions.
    vessel = positions[positions["mmsi"] == 205550000]
    assert len(vessel) > 0
    assert vessel["timestamp"].min() < pd.Timestamp("2013-11-12 12:00:12", tz="UTC")
    assert set(vessel["length_m"]) == {15.0 + 15.0}
    assert set(vessel["breadth_m"]) == {5.0 + 5.0}
    assert set(vessel["draught_m"]) == {6.4}
    assert set(vessel["ship_type"]) == {"Fishing"}
    assert set(vessel["name"]) == {"O-156"}
    assert vessel["imo"].isna().all()


# --- satellite $PGHP and the precedence of time sources ----------------------------------


def _satellite_pghp(when: datetime) -> str:
    # exactEarth/AMSA style: the origin of the message (satellite) where DMA writes its site
    body = f"PGHP,1,{when:%Y,%m,%d,%H,%M,%S},{when.microsecond // 1000},,,1AIS_S,,"
    return f"${body}*{_checksum(body)}"


def test_satellite_pghp_keeps_the_observation_time_not_the_arrival() -> None:
    observed = datetime(2013, 11, 12, 12, 3, 14, 159_000, tzinfo=UTC)
    arrival = NOON + 3600 + 17 * 60  # 77 min later, as satellite feeds arrive
    batch, ledger = _read([_satellite_pghp(observed), f"{_position()},{arrival}"])
    (row,) = _rows(batch.positions)
    assert row["timestamp"] == observed
    assert ledger.time_sources == {"pghp": 1}


def test_time_source_order_is_a_parameter() -> None:
    observed = datetime(2013, 11, 12, 12, 3, 14, tzinfo=UTC)
    lines = [_satellite_pghp(observed), f"{_position()},{NOON + 600}"]
    ledger = RejectsLedger()
    (batch,) = read_nmea(lines, "log.nmea", ledger, (TimeSource.ARRIVAL, TimeSource.PGHP))
    assert _rows(batch.positions)[0]["timestamp"] == datetime(2013, 11, 12, 12, 10, tzinfo=UTC)
    assert ledger.time_sources == {"arrival": 1}
    # leaving a source out: no time at all is unparseable, counted, never guessed
    ledger = RejectsLedger()
    (batch,) = read_nmea([_position() + f",{NOON}"], "log.nmea", ledger, (TimeSource.PGHP,))
    assert batch.positions.num_rows == 0 and ledger.rejects == {"unparseable": 1}


@pytest.mark.parametrize(
    "line",
    [
        "$PGHP,1,2013,11,12,12,0,7,979,219,,2190067,1,00*00",  # wrong checksum
        "$PGHP,1,2013,02,30,12,0,7,979",  # no such day (checksum added below)
        "$PGHP,1,2013,11,12,12,0,7",  # no milliseconds field
    ],
)
def test_a_bad_pghp_gives_no_time(line: str) -> None:
    if "*" not in line:
        line = f"{line}*{_checksum(line[1:])}"
    assert pghp_time_ms(line) is None


def test_pghp_time_ms_reads_dma_and_satellite_lines() -> None:
    dma = "$PGHP,1,2013,11,12,12,0,0,11,219,,2190067,1,62*26"  # the first line of the fixture
    assert pghp_time_ms(dma) == (NOON * 1000) + 11
    when = datetime(2020, 2, 29, 23, 59, 59, 999_000, tzinfo=UTC)
    assert pghp_time_ms(_satellite_pghp(when)) == round(when.timestamp() * 1000)


def test_a_query_sets_the_precedence_and_the_ledger_records_it(tmp_path) -> None:
    from types import MappingProxyType

    from colregs9_cli.ais.load import load_ais
    from colregs9_cli.query import Query

    observed = datetime(2013, 11, 12, 12, 3, 14, 159_000, tzinfo=UTC)
    second = _position()
    log = tmp_path / "satellite.nmea"
    log.write_text(
        "\n".join([_satellite_pghp(observed), f"{second},{NOON + 4000}"]) + "\n", encoding="ascii"
    )
    by_default = load_ais([log], fmt="nmea")
    assert by_default.positions["timestamp"].iloc[0] == observed
    assert by_default.ledger.to_dict()["time_sources"] == {"pghp": 1}
    assert by_default.ledger.to_dict()["time_source_order"] == ["tag_block", "pghp", "arrival"]
    arrival_first = Query(
        name="arrival",
        tables=MappingProxyType({"ingest": MappingProxyType({"nmea_time_sources": ["arrival"]})}),
    )
    data = load_ais([log], query=arrival_first, fmt="nmea")
    assert data.positions["timestamp"].iloc[0] == datetime(2013, 11, 12, 13, 6, 40, tzinfo=UTC)
    assert data.ledger.to_dict()["time_source_order"] == ["arrival"]


def test_an_invalid_mmsi_is_quoted_with_the_line_of_its_message(tmp_path: Path) -> None:
    from colregs9_cli.ais.load import load_ais

    log = tmp_path / "log.nmea"
    lines = [
        _at(0, _position()),
        _at(1, _position(mmsi=2190045)),  # line 2: seven digits, not a ship's MMSI
        *(_at(2, s) for s in _type5()),
        *(_at(3, s) for s in _type5(mmsi=11388, seq_id=4)),  # lines 5-6: a static report
    ]
    log.write_text("\n".join(lines) + "\n")
    ledger = load_ais([log]).ledger
    assert dict(ledger.rejects) == {"invalid_mmsi": 2}
    assert ledger.examples["invalid_mmsi"] == [
        f"{log}:2: MMSI 2190045",
        f"{log}:5: static report: MMSI 11388",
    ]


# --- $PGHP matched to its sentence by checksum (exactEarth/AMSA satellite logs) -----------
# exactEarth's logs for AMSA write each sentence's $PGHP with the sentence's checksum in its
# 14th field, before, after or a few lines away from it, and terrestrial sentences with no
# $PGHP among them; each line ends with its arrival at the archive in ms (docs: nmea_pghp.py):
#   $PGHP,1,2012,1,31,5,7,2,151,316,2,316000002,1AIS_S,51*77,1327992119157
#   !AIVDM,1,1,,B,IFICEMae<`HfcEV4M8aEWM<2VH1j6?;6<t9>,0*51,1327992119173

SAT_PASS = datetime(2012, 1, 31, 5, 7, 2, 151_000, tzinfo=UTC)
ARCHIVED_MS = round(SAT_PASS.timestamp() * 1000) + 90 * 60_000  # 1.5 h after the pass
SHUFFLE_REACH = 3  # a line moves at most 2 * 3 places: a $PGHP stays within 13 lines


def _ee_pghp(when: datetime, checksum: int | str) -> str:
    field = checksum if isinstance(checksum, str) else f"{checksum:02X}"
    body = (
        f"PGHP,1,{when.year},{when.month},{when.day},{when.hour},{when.minute},{when.second},"
        f"{when.microsecond // 1000},316,2,316000002,1AIS_S,{field}"
    )
    return f"${body}*{_checksum(body)}"


def _archived(line: str, index: int) -> str:
    return f"{line},{ARCHIVED_MS + index}"


def _distinct_positions(count: int, taken: set[int]) -> list[tuple[str, dict[str, object]]]:
    """Real type 1 and 18 sentences from pyais's encoder, no two with one checksum."""
    found: list[tuple[str, dict[str, object]]] = []
    step = 0
    while len(found) < count:
        step += 1
        fields: dict[str, object] = {
            "type": 18 if step % 3 == 0 else 1,
            "mmsi": 503_000_000 + step % 7,
            "lat": round(-33.0 - step * 0.0013, 4),
            "lon": round(151.2 + step * 0.0021, 4),
            "speed": 12.3,
            "course": 45.6,
        }
        (sentence,) = _sentences(channel="AB"[step % 2], **fields)
        checksum = compute_checksum(sentence)
        if checksum not in taken:
            taken.add(checksum)
            found.append((sentence, fields))
    return found


@functools.cache
def _satellite_log() -> tuple[list[str], dict[tuple[object, ...], datetime], int]:
    """40 satellite sentences each after its $PGHP (times out of order, as a satellite
    sends what it stored), 5 terrestrial ones without; every checksum different. Returns
    the lines, each position's observation time, and how many are satellite ones."""
    taken: set[int] = set()
    satellite = _distinct_positions(40, taken)
    terrestrial = _distinct_positions(5, taken)
    lines: list[str] = []
    times: dict[tuple[object, ...], datetime] = {}
    for n, (sentence, fields) in enumerate(satellite):
        when = SAT_PASS + pd.Timedelta(seconds=(n * 37) % 300, milliseconds=n * 7)
        lines += [_ee_pghp(when, compute_checksum(sentence)), sentence]
        times[(fields["mmsi"], fields["lat"], fields["lon"])] = when
        if n % 8 == 3:
            lines.append(terrestrial[n // 8][0])
    return [_archived(line, i) for i, line in enumerate(lines)], times, len(satellite)


def _shuffled(lines: list[str], offsets: list[int]) -> list[str]:
    """Each line moved by its offset (ties keep the order): a shuffle within a window."""
    order = sorted(range(len(lines)), key=lambda i: (i + offsets[i], i))
    return [lines[i] for i in order]


def _positions_by_report(batch: AisBatch) -> dict[tuple[object, ...], datetime]:
    return {
        (row["mmsi"], row["lat_deg"], row["lon_deg"]): row["timestamp"]
        for row in _rows(batch.positions)
    }


def _seeded_shuffle(lines: list[str]) -> list[str]:
    rng = np.random.default_rng(31)
    return _shuffled(lines, list(rng.integers(-SHUFFLE_REACH, SHUFFLE_REACH + 1, len(lines))))


def test_a_shuffled_satellite_log_gives_every_sentence_its_pghp_time() -> None:
    lines, times, satellite = _satellite_log()
    shuffled = _seeded_shuffle(lines)
    after = sum(
        1
        for prev, line in itertools.pairwise(shuffled)
        if prev.startswith("$PGHP") and line.split("*")[1][:2] == prev.split(",")[13][:2]
    )
    assert after < satellite * 0.7  # most $PGHP lines no longer right before their sentence
    batch, ledger = _read(shuffled)
    got = _positions_by_report(batch)
    assert {key: got[key] for key in times} == times  # every one its observation, none late
    terrestrial = [when for key, when in got.items() if key not in times]
    assert len(terrestrial) == 5
    assert all(when > SAT_PASS + pd.Timedelta(minutes=89) for when in terrestrial)  # arrival
    assert ledger.time_sources == {"pghp": satellite, "arrival": 5}
    assert ledger.pghp_pairing == {
        "matched": satellite,
        "adjacent": 0,
        "unmatched": 5,
        "pghp_unmatched": 0,
    }
    assert ledger.to_dict()["pghp_pairing"] == dict(sorted(ledger.pghp_pairing.items()))


def test_adjacency_alone_would_time_the_shuffled_log_wrongly() -> None:
    """What the checksum fixes: the line after each $PGHP is mostly another sentence."""
    lines, times, _ = _satellite_log()
    epoch = datetime(1970, 1, 1, tzinfo=UTC)
    # The same shuffled log with each $PGHP's checksum field emptied: it times the next line.
    blinded = [
        _ee_pghp(epoch + timedelta(milliseconds=pghp_time_ms(line) or 0), "")
        if line.startswith("$PGHP")
        else line
        for line in _seeded_shuffle(lines)
    ]
    batch, ledger = _read(blinded)
    got = _positions_by_report(batch)
    assert sum(got[key] != when for key, when in times.items()) > len(times) / 3
    assert ledger.pghp_pairing["adjacent"] > 0 and ledger.pghp_pairing["matched"] == 0


@settings(max_examples=30, deadline=None)
@given(st.data())
def test_any_shuffle_within_the_window_decodes_like_the_unshuffled_log(
    data: st.DataObject,
) -> None:
    lines, _, _ = _satellite_log()
    offsets = data.draw(
        st.lists(
            st.integers(-SHUFFLE_REACH, SHUFFLE_REACH), min_size=len(lines), max_size=len(lines)
        )
    )
    plain, plain_ledger = _read(lines)
    shuffled, ledger = _read(_shuffled(lines, offsets))
    columns = ["mmsi", "timestamp", "lat_deg", "lon_deg", "sog_kn", "cog_deg"]
    expected = plain.positions.to_pandas()[columns].sort_values(columns, ignore_index=True)
    got = shuffled.positions.to_pandas()[columns].sort_values(columns, ignore_index=True)
    pd.testing.assert_frame_equal(got, expected)
    assert ledger.time_sources == plain_ledger.time_sources
    assert ledger.pghp_pairing == plain_ledger.pghp_pairing


def test_an_unmatched_pghp_and_an_unmatched_sentence_are_counted() -> None:
    taken: set[int] = set()
    (mine, mine_fields), (orphan, _), (far, far_fields) = _distinct_positions(3, taken)
    # its sentence never reached the log (and not 00, which DMA writes before an own report)
    lost = next(c for c in range(1, 256) if c not in taken)
    lines = [
        _archived(_ee_pghp(SAT_PASS, compute_checksum(mine)), 0),
        _archived(mine, 1),
        # A $PGHP whose sentence is missing, right before a sentence with no $PGHP: the
        # checksums disagree, so neither times the other.
        _archived(_ee_pghp(SAT_PASS + pd.Timedelta(seconds=9), lost), 2),
        _archived(orphan, 3),
        # A $PGHP 16 lines before its sentence, with other sentences between (a station's
        # status lines here): beyond the window, both stay unmatched.
        _archived(_ee_pghp(SAT_PASS + pd.Timedelta(seconds=20), compute_checksum(far)), 4),
        *[
            status
            for status in (f"$PSTT,10A,{i}*{_checksum(f'PSTT,10A,{i}')}" for i in range(16))
            if compute_checksum(status) != compute_checksum(far)
        ][:15],
        _archived(far, 20),
    ]
    batch, ledger = _read(lines)
    got = _positions_by_report(batch)
    assert got[(mine_fields["mmsi"], mine_fields["lat"], mine_fields["lon"])] == SAT_PASS
    assert got[(far_fields["mmsi"], far_fields["lat"], far_fields["lon"])] > SAT_PASS + (
        pd.Timedelta(minutes=89)
    )
    assert ledger.time_sources == {"pghp": 1, "arrival": 2}
    assert ledger.pghp_pairing == {
        "matched": 1,
        "adjacent": 0,
        "unmatched": 2,
        "pghp_unmatched": 2,
    }


def _two_with_one_checksum() -> tuple[tuple[int, str], tuple[int, str]]:
    """Two position sentences (MMSI, sentence) of two vessels whose checksums are equal."""
    seen: dict[int, tuple[int, str]] = {}
    for mmsi in range(503_100_000, 503_102_000):
        sentence = _position(mmsi=mmsi, lat=-33.5, lon=151.5)
        checksum = compute_checksum(sentence)
        if checksum in seen:
            return seen[checksum], (mmsi, sentence)
        seen[checksum] = (mmsi, sentence)
    raise AssertionError("no two sentences with one checksum")


@pytest.mark.parametrize(
    ("before", "after", "winner"),
    [
        (1, 3, "earlier"),  # the nearer one wins
        (2, 2, "later"),  # a tie: the following one, where a $PGHP normally is
        (3, 1, "later"),
    ],
)
def test_two_sentences_with_the_pghps_checksum_in_the_window(
    before: int, after: int, winner: str
) -> None:
    (earlier_mmsi, earlier), (later_mmsi, later) = _two_with_one_checksum()
    checksum = compute_checksum(earlier)
    # sentences with no $PGHP between them, their checksums all different
    filler = [_position(mmsi=503_200_000 + i, lat=-34.0 - i / 100, lon=152.0) for i in range(6)]
    assert checksum not in {compute_checksum(f) for f in filler}
    lines = [earlier, *filler[: before - 1], _ee_pghp(SAT_PASS, checksum)]
    lines += [*filler[3 : 3 + after - 1], later]
    batch, ledger = _read([_archived(line, i) for i, line in enumerate(lines)])
    by_mmsi = {row["mmsi"]: row["timestamp"] for row in _rows(batch.positions)}
    timed = {"earlier": by_mmsi[earlier_mmsi], "later": by_mmsi[later_mmsi]}
    loser = "later" if winner == "earlier" else "earlier"
    assert timed[winner] == SAT_PASS
    assert timed[loser] > SAT_PASS + pd.Timedelta(minutes=89)  # its arrival
    assert ledger.pghp_pairing["matched"] == 1
    assert ledger.pghp_pairing["unmatched"] == len(lines) - 2


@pytest.mark.parametrize("where", ["right before", "after it", "first fragment's only"])
def test_a_multi_sentence_message_is_matched_by_the_xor_of_its_fragments(where: str) -> None:
    fragments = _type5(mmsi=503_300_000)
    whole = reduce(lambda acc, s: acc ^ compute_checksum(s), fragments, 0)
    assert whole != compute_checksum(fragments[0])
    other = _position(mmsi=503_300_001)
    lines = {
        "right before": [_ee_pghp(SAT_PASS, whole), *fragments, other],
        "after it": [*fragments, other, _ee_pghp(SAT_PASS, whole)],
        "first fragment's only": [_ee_pghp(SAT_PASS, compute_checksum(fragments[0])), *fragments],
    }[where]
    batch, ledger = _read([_archived(line, i) for i, line in enumerate(lines)])
    (static,) = _rows(batch.statics)
    if where == "first fragment's only":
        assert static["timestamp"] > SAT_PASS + pd.Timedelta(minutes=89)
        assert ledger.pghp_pairing["pghp_unmatched"] == 1
    else:
        assert static["timestamp"] == SAT_PASS
        assert ledger.pghp_pairing["matched"] == 1


def test_a_pghp_without_checksum_or_with_dmas_00_times_the_next_sentence() -> None:
    observed = datetime(2013, 11, 12, 12, 3, 14, 159_000, tzinfo=UTC)
    _, no_field = _read([_satellite_pghp(observed), _position()])
    assert no_field.pghp_pairing == {
        "matched": 0,
        "adjacent": 1,
        "unmatched": 0,
        "pghp_unmatched": 0,
    }
    # DMA writes 00 before its base stations' own !xxVDO reports (rule 3)
    own = _position(mmsi=219_000_123).replace("!AIVDM", "!BSVDO")
    own = f"{own.split('*')[0]}*{compute_checksum(own):02X}"
    assert compute_checksum(own) != 0
    batch, ledger = _read([_pghp(observed), own])
    assert _rows(batch.positions)[0]["timestamp"] == observed
    assert ledger.pghp_pairing["adjacent"] == 1


def test_dma_every_message_keeps_the_time_of_the_pghp_right_before_it(
    fixtures_dir: Path, dma: tuple[AisBatch, RejectsLedger]
) -> None:
    """The DMA fixture is read as before: worked out here by adjacency alone."""
    with gzip.open(
        fixtures_dir / "ais" / "dma_nmea_2013-11-12_5min.txt.gz", "rt", encoding="ascii"
    ) as log:
        lines = log.read().splitlines()
    expected: dict[int, int] = {}
    last: int | None = None
    for line_no, line in enumerate(lines, start=1):
        if line.startswith("$PGHP"):
            last = pghp_time_ms(line)
        elif line.startswith("!") or line.startswith("$"):
            fields = line.split(",")
            if line[3:6] in ("VDM", "VDO") and fields[2] == "1" and last is not None:
                expected[line_no] = last
            last = None
    batch, ledger = dma
    for table, table_lines in (
        (batch.positions, batch.position_lines),
        (batch.statics, batch.static_lines),
    ):
        assert table_lines is not None
        got = table.column("timestamp").cast("int64").to_pylist()
        assert got == [expected[int(n)] for n in table_lines]
    assert ledger.pghp_pairing == {
        "matched": 25_604,
        "adjacent": 473,  # the base stations' own !BSVDO/!AIVDO reports: 00 (rule 3)
        "unmatched": 0,
        "pghp_unmatched": 0,
    }
