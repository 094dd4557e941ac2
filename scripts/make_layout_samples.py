"""Write the samples of the CSV layouts colregs9 reads besides DMA's, from the rows of the
MarineCadastre fixture (US public domain data): the same vessels and positions, in each
layout. Run from the repository root: ``python scripts/make_layout_samples.py``.

- ``marinecadastre2015_sample.csv``: the 2015-2017 layout (no TransceiverClass), dated 2016;
- ``marinecadastre2025_sample.csv.zst``: the 2025 layout (lower case, longitude first,
  zstd), dated 2025;
- ``exactearth_sample.csv``: exactEarth/Spire decoded messages: a position message (1 or
  18) per row, one static message (5 or 24) per vessel, a base station (4) and a binary
  broadcast (8);
- ``aishub_sample.csv``: an AISHub web service CSV (human-readable values);
- ``kystverket_sample.csv``: the Norwegian semicolon CSV (``mmsi;lon;lat;date_time_utc;...``).

Every sample has a few rows that the readers reject or leave out on purpose (named below), so
that the tests see each reason.
"""

from __future__ import annotations

import csv
import io
from pathlib import Path

import pyarrow as pa

ROOT = Path(__file__).resolve().parent.parent
AIS = ROOT / "fixtures" / "ais"
SOURCE = AIS / "marinecadastre_2023-01-11_sample.csv"
FIRST_ROWS = 34
CLASS_B_ROWS = 6


def _rows() -> list[dict[str, str]]:
    """The source's first 34 rows and the first 6 Class B rows after them, in file order."""
    with SOURCE.open(newline="") as handle:
        rows = list(csv.DictReader(handle))
    class_b = [i for i, r in enumerate(rows) if i >= FIRST_ROWS and r["TransceiverClass"] == "B"]
    chosen = sorted([*range(FIRST_ROWS), *class_b[:CLASS_B_ROWS]])
    return [rows[i] for i in chosen]


def _write(path: Path, header: list[str], rows: list[list[str]], delimiter: str = ",") -> None:
    buffer = io.StringIO()
    writer = csv.writer(buffer, delimiter=delimiter, lineterminator="\n")
    writer.writerow(header)
    writer.writerows(rows)
    data = buffer.getvalue().encode()
    if path.suffix == ".zst":
        with pa.CompressedOutputStream(str(path), "zstd") as out:
            out.write(data)
    else:
        path.write_bytes(data)
    print(f"{path.relative_to(ROOT)}: {len(rows)} rows")


def _year(stamp: str, year: int, sep: str = "T") -> str:
    return f"{year}{stamp[4:10]}{sep}{stamp[11:]}"


def marinecadastre2015(rows: list[dict[str, str]]) -> None:
    header = list(rows[0])[:-1]
    body = [[r[c] if c != "BaseDateTime" else _year(r[c], 2016) for c in header] for r in rows]
    body.append(["367000001", "2016-01-11T00:00:00", "91.0", "181.0"] + [""] * 12)  # no position
    body.append(["12345", "2016-01-11T00:00:00", "40.0", "-70.0"] + [""] * 12)  # invalid MMSI
    _write(AIS / "marinecadastre2015_sample.csv", header, body)


def marinecadastre2025(rows: list[dict[str, str]]) -> None:
    names = ["MMSI", "BaseDateTime", "LON", "LAT", "SOG", "COG", "Heading", "VesselName"]
    names += ["IMO", "CallSign", "VesselType", "Status", "Length", "Width", "Draft", "Cargo"]
    names += ["TransceiverClass"]
    header = ["mmsi", "base_date_time", "longitude", "latitude", "sog", "cog", "heading"]
    header += ["vessel_name", "imo", "call_sign", "vessel_type", "status", "length", "width"]
    header += ["draft", "cargo", "transceiver"]
    body = [[r[c] if c != "BaseDateTime" else _year(r[c], 2025, " ") for c in names] for r in rows]
    body.append(body[0][:])  # an exact duplicate
    bad_time = body[1][:]
    bad_time[1] = "2025-13-45 99:00:00"  # a time that does not parse
    body.append(bad_time)
    _write(AIS / "marinecadastre2025_sample.csv.zst", header, body)


_EXACTEARTH_NAMES = (
    "MMSI,Message_ID,Repeat_indicator,Time,Millisecond,Region,Country,Base_station,"
    "Online_data,Group_code,Sequence_ID,Channel,Data_length,Vessel_Name,Call_sign,IMO,"
    "Ship_Type,Dimension_to_Bow,Dimension_to_stern,Dimension_to_port,Dimension_to_starboard,"
    "Draught,Destination,AIS_version,Navigational_status,ROT,SOG,Accuracy,Longitude,Latitude,"
    "COG,Heading,Regional,Maneuver,RAIM_flag"
)
EXACTEARTH_HEADER = _EXACTEARTH_NAMES.split(",")


def _exactearth_row(**values: str) -> list[str]:
    return [values.get(name, "") for name in EXACTEARTH_HEADER]


def exactearth(rows: list[dict[str, str]]) -> None:
    body: list[list[str]] = []
    seen: set[str] = set()
    for index, r in enumerate(rows):
        class_b = r["TransceiverClass"] == "B"
        stamp = r["BaseDateTime"].replace("-", "").replace(":", "").replace("T", "_")
        millisecond = str((index * 137) % 1000)
        common = {"MMSI": r["MMSI"], "Time": stamp, "Millisecond": millisecond, "Channel": "A"}
        body.append(
            _exactearth_row(
                **common,
                Message_ID="18" if class_b else "1",
                Repeat_indicator="0",
                Navigational_status="" if class_b else str(int(float(r["Status"] or 15))),
                SOG=r["SOG"],
                Longitude=r["LON"],
                Latitude=r["LAT"],
                COG=r["COG"],
                Heading=str(int(float(r["Heading"]))) if r["Heading"] else "511",
            )
        )
        if r["MMSI"] in seen:
            continue
        seen.add(r["MMSI"])
        length = float(r["Length"] or 0)
        width = float(r["Width"] or 0)
        bow, port = round(length * 0.7), round(width / 2)
        body.append(
            _exactearth_row(
                **common,
                Message_ID="24" if class_b else "5",
                Repeat_indicator="0",
                Vessel_Name=r["VesselName"],
                Call_sign=r["CallSign"],
                IMO=r["IMO"].removeprefix("IMO"),
                Ship_Type=r["VesselType"],
                Dimension_to_Bow=str(bow),
                Dimension_to_stern=str(round(length) - bow) if length else "0",
                Dimension_to_port=str(port),
                Dimension_to_starboard=str(round(width) - port) if width else "0",
                Draught="" if class_b else r["Draft"],
            )
        )
    first = rows[0]["BaseDateTime"].replace("-", "").replace(":", "").replace("T", "_")
    # A base station (not a vessel) and a binary broadcast (an unsupported message type).
    body.append(
        _exactearth_row(
            MMSI="003669702",
            Message_ID="4",
            Time=first,
            Millisecond="0",
            Longitude="-76.3",
            Latitude="36.9",
        )
    )
    body.append(_exactearth_row(MMSI=rows[1]["MMSI"], Message_ID="8", Time=first, Millisecond="0"))
    _write(AIS / "exactearth_sample.csv", EXACTEARTH_HEADER, body)


def aishub(rows: list[dict[str, str]]) -> None:
    header = "MMSI,TIME,LONGITUDE,LATITUDE,COG,SOG,HEADING,ROT,NAVSTAT,IMO,NAME,CALLSIGN,TYPE"
    header += ",A,B,C,D,DRAUGHT,DEST,ETA"
    body = []
    for r in rows:
        length, width = float(r["Length"] or 0), float(r["Width"] or 0)
        bow, port = round(length * 0.7), round(width / 2)
        body.append(
            [
                r["MMSI"],
                r["BaseDateTime"].replace("T", " ") + " GMT",
                r["LON"],
                r["LAT"],
                r["COG"],
                r["SOG"],
                str(int(float(r["Heading"]))) if r["Heading"] else "511",
                "128",
                str(int(float(r["Status"] or 15))),
                r["IMO"].removeprefix("IMO") or "0",
                r["VesselName"],
                r["CallSign"],
                r["VesselType"] or "0",
                str(bow),
                str(round(length) - bow) if length else "0",
                str(port),
                str(round(width) - port) if width else "0",
                r["Draft"] or "0",
                "",
                "",
            ]
        )
    _write(AIS / "aishub_sample.csv", header.split(","), body)


def kystverket(rows: list[dict[str, str]]) -> None:
    header = "mmsi;lon;lat;date_time_utc;sog;cog;true_heading;nav_status;rot;message_nr;source"
    body = [
        [
            r["MMSI"],
            r["LON"],
            r["LAT"],
            r["BaseDateTime"].replace("T", " "),
            r["SOG"],
            r["COG"],
            str(int(float(r["Heading"]))) if r["Heading"] else "511",
            str(int(float(r["Status"] or 15))),
            "0",
            "18" if r["TransceiverClass"] == "B" else "1",
            "g",
        ]
        for r in rows
    ]
    _write(AIS / "kystverket_sample.csv", header.split(";"), body, delimiter=";")


def main() -> None:
    rows = _rows()
    marinecadastre2015(rows)
    marinecadastre2025(rows)
    exactearth(rows)
    aishub(rows)
    kystverket(rows)


if __name__ == "__main__":
    main()
