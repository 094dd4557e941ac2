"""Times as the reports show them: UTC, to the second."""

from __future__ import annotations

# How a report writes a UTC time for people (tables, titles, progress), without the zone.
DISPLAY_TIME_FORMAT = "%Y-%m-%d %H:%M:%S"
