"""Parameters of the replay: the ``[replay]`` table of a query TOML, composed of the core
stages' own parameters.

One table holds every knob of the tracks → encounters → rule 9 chain, so that a query file
states the replay in one place; each core stage takes only its part (``TrackParams``,
``EncounterParams``, ``ConductParams``, ``Rule9Params``, ``DimensionDefaults``). A key that
a stage also has takes that stage's default. Defaults are the paper's Table "Simulation
parameters" (time step 1 s, TCPA_act 3 min, CPA_req 150 m) and docs/design.md §5.

``[colregs]`` (sector angles, course source) is ``ColregsParams`` in ``colregs.py``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Any, TypeVar

from ..config import dataclass_from_table
from ..core.ais_claims import NavStatusParams
from ..core.audit import ConductParams
from ..core.channel_audit import ChannelAuditParams
from ..core.colregs import ColregsParams, colregs_params_from_table
from ..core.interactions import InteractionParams
from ..core.manoeuvrability import ManoeuvrabilityParams
from ..core.pair import PairParams
from ..core.pair_search import EncounterParams
from ..core.passing import PassingParams
from ..core.rule9 import Rule9Params
from ..core.tracks import TrackParams
from ..core.vessel_defaults import DimensionDefaults
from ..errors import ParameterError
from ..query import Query
from ..vessels import MAX_BREADTH_M, MAX_DRAUGHT_M, MAX_LENGTH_M

T = TypeVar("T")

# The most steps one vessel may have in a slab's window: 13 float columns of 8 bytes make a
# gigabyte per vessel at 1e7.
MAX_STEPS_PER_SLAB = 1e7
# A slab holds at least this many steps and lasts at least SLAB_MIN_S: shorter slabs only
# multiply the work per slab (a fixture of five minutes in slabs of a nanosecond would be
# billions of slabs). A week is the longest: memory grows with the slab, results do not.
SLAB_MIN_STEPS = 2
SLAB_MIN_S = 30.0
SLAB_MAX_S = 7 * 86_400.0
# The least candidate range: below a metre the pair search's grid would be finer than any
# AIS position.
CANDIDATE_RANGE_MIN_M = 1.0


def _stage_part(params: Any, stage: type[T]) -> T:
    """A stage's parameters from the ``[replay]`` keys of the same names."""
    return stage(**{f.name: getattr(params, f.name) for f in fields(stage)})  # type: ignore[arg-type]


@dataclass(frozen=True)
class ReplayParams:
    """The ``[replay]`` table.

    - ``step_s``: the replay time step Δt; tracks are resampled to multiples of it (UTC).
    - ``max_gap_s``: a track is split where two reports are more than this apart.
    - ``max_speed_kn``: a report whose implied speed from the previous kept report exceeds
      this is an implausible jump (see ``tracks.build_tracks``).
    - ``min_sog_kn``: vessels slower than this are not under way and form no candidate pairs.
    - ``candidate_range_m``: pairs closer than this (inclusive) are candidates (2 nm).
    - ``tcpa_act_s``, ``cpa_req_m``: an encounter triggers at the first step with
      ``0 <= TCPA <= tcpa_act_s`` and ``CPA < cpa_req_m``.
    - ``course_change_deg``, ``speed_change_frac``, ``speed_change_min_kn``: a vessel "acted"
      when her course changed by at least this many degrees, or her speed by at least this
      fraction of her speed at the trigger and at least ``speed_change_min_kn`` (SOG noise:
      0.6 to 0.98 kn is no action), before CPA.
    - ``course_judged_above_kn``: a course change counts only at speeds of at least this much,
      where COG means something (at 0.5 kn it is mostly GPS noise).
    - ``observed_gap_max_s``: course and speed are judged only at a vessel's reports and where
      interpolated across gaps of at most this much (``audit.py``): inside a longer gap a
      change has no time.
    - ``restricted_nav_statuses``: AIS navigational status codes that mean "restricted
      manoeuvrability" for event d2 of the rule 9 automaton (3 restricted manoeuvrability,
      4 constrained by her draught).
    - ``reassess_every_s``: after the trigger, a manoeuvrability estimate is made again only
      where G_d reaches D3 and the last one is at least this old (see ``replay.py``).
    - ``default_length_m``, ``default_breadth_m``, ``default_draught_m``: when given, used for
      every vessel that does not report the dimension; when not (the default), the value comes
      from the table of ``vessel_defaults.py`` by mobile type and ship type.
    - ``slab_s``: the replay works through time in slabs of this length (``slabs.py``);
      memory grows with it, the results do not depend on it.
    """

    # A key a stage also has takes the stage's default (tests/test_replay_params.py).
    step_s: float = TrackParams.step_s
    max_gap_s: float = TrackParams.max_gap_s
    max_speed_kn: float = TrackParams.max_speed_kn
    min_sog_kn: float = TrackParams.min_sog_kn
    candidate_range_m: float = EncounterParams.candidate_range_m
    tcpa_act_s: float = EncounterParams.tcpa_act_s
    cpa_req_m: float = EncounterParams.cpa_req_m
    course_change_deg: float = 15.0
    speed_change_frac: float = 0.25
    speed_change_min_kn: float = 1.0
    course_judged_above_kn: float = 2.0
    stopped_below_kn: float = ConductParams.stopped_below_kn
    observed_gap_max_s: float = ConductParams.observed_gap_max_s
    restricted_nav_statuses: frozenset[int] = Rule9Params.restricted_nav_statuses
    reassess_every_s: float = Rule9Params.reassess_every_s
    default_length_m: float | None = DimensionDefaults.length_m
    default_breadth_m: float | None = DimensionDefaults.breadth_m
    default_draught_m: float | None = DimensionDefaults.draught_m
    slab_s: float = 1800.0
    passing_open_m: float = PassingParams.open_m
    passing_open_frac: float = PassingParams.open_frac
    passing_follow_s: float = PassingParams.follow_s
    interaction_window_s: float = InteractionParams.interaction_window_s
    speed_span_s: float = InteractionParams.speed_span_s
    making_way_kn: float = InteractionParams.making_way_kn
    at_rest_min_s: float = InteractionParams.at_rest_min_s
    alongside_margin_m: float = InteractionParams.alongside_margin_m
    alongside_min_s: float = InteractionParams.alongside_min_s
    service_margin_m: float = InteractionParams.service_margin_m
    service_speed_kn: float = InteractionParams.service_speed_kn
    service_min_s: float = InteractionParams.service_min_s
    company_min_s: float = InteractionParams.company_min_s
    company_course_deg: float = InteractionParams.company_course_deg
    company_drift_m: float = InteractionParams.company_drift_m
    company_drift_frac: float = InteractionParams.company_drift_frac
    channel_along_within_deg: float = ChannelAuditParams.channel_along_within_deg
    channel_crossing_from_deg: float = ChannelAuditParams.channel_crossing_from_deg
    starboard_side_share: float = ChannelAuditParams.starboard_side_share
    starboard_side_min_s: float = ChannelAuditParams.starboard_side_min_s
    lane_crossing_within_deg: float = ChannelAuditParams.lane_crossing_within_deg
    channel_confined_within_lengths: float = ChannelAuditParams.channel_confined_within_lengths
    channel_narrow_within_lengths: float = ChannelAuditParams.channel_narrow_within_lengths

    @property
    def tracks(self) -> TrackParams:
        return TrackParams(self.step_s, self.max_gap_s, self.max_speed_kn, self.min_sog_kn)

    @property
    def encounters(self) -> EncounterParams:
        return EncounterParams(
            self.min_sog_kn, self.candidate_range_m, self.tcpa_act_s, self.cpa_req_m, self.passing
        )

    @property
    def conduct(self) -> ConductParams:
        return _stage_part(self, ConductParams)

    @property
    def interactions(self) -> InteractionParams:
        return _stage_part(self, InteractionParams)

    @property
    def channels(self) -> ChannelAuditParams:
        return _stage_part(self, ChannelAuditParams)

    @property
    def passing(self) -> PassingParams:
        return PassingParams(self.passing_open_m, self.passing_open_frac, self.passing_follow_s)

    @property
    def rule9(self) -> Rule9Params:
        return _stage_part(self, Rule9Params)

    @property
    def dimension_defaults(self) -> DimensionDefaults:
        return DimensionDefaults(
            self.default_length_m, self.default_breadth_m, self.default_draught_m
        )

    def __post_init__(self) -> None:
        _stage_part(self, InteractionParams)  # checks its own keys
        _stage_part(self, ChannelAuditParams)
        positive = (
            "step_s",
            "max_gap_s",
            "max_speed_kn",
            "candidate_range_m",
            "cpa_req_m",
            "course_change_deg",
            "speed_change_frac",
            "reassess_every_s",
            "passing_open_m",
            "passing_follow_s",
        )  # slab_s: its range below names --slab-minutes
        for name in positive:
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0.0):
                raise ParameterError(f"[replay] {name} = {value!r}: give a positive number")
        for name, most_m in (
            ("default_length_m", MAX_LENGTH_M),
            ("default_breadth_m", MAX_BREADTH_M),
            ("default_draught_m", MAX_DRAUGHT_M),
        ):
            value = getattr(self, name)
            if value is not None and not (math.isfinite(value) and 0.0 < value <= most_m):
                raise ParameterError(
                    f"[replay] {name} = {value!r}: give a number above 0 and at most "
                    f"{most_m:g} (a ship's), or leave it out to take defaults by ship type"
                )
        for name in (
            "min_sog_kn",
            "tcpa_act_s",
            "course_judged_above_kn",
            "speed_change_min_kn",
            "passing_open_frac",
        ):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0.0):
                raise ParameterError(f"[replay] {name} = {value!r}: give a number >= 0")
        if self.max_gap_s < self.step_s:
            raise ParameterError(
                f"[replay] max_gap_s = {self.max_gap_s} is shorter than step_s = {self.step_s}; "
                "give a gap of at least one step"
            )
        slab_min_s = max(SLAB_MIN_S, SLAB_MIN_STEPS * self.step_s)
        if not slab_min_s <= self.slab_s <= SLAB_MAX_S:
            raise ParameterError(
                f"[replay] slab_s = {self.slab_s:g} s (--slab-minutes {self.slab_s / 60.0:g}) is "
                f"outside [{slab_min_s:g}, {SLAB_MAX_S:g}] s; give a slab of at least "
                f"{SLAB_MIN_S:g} s and {SLAB_MIN_STEPS} steps (step_s = {self.step_s:g} s), and "
                "at most a week (30 minutes is the default)"
            )
        range_min_m = max(CANDIDATE_RANGE_MIN_M, self.cpa_req_m)
        if self.candidate_range_m < range_min_m:
            raise ParameterError(
                f"[replay] candidate_range_m = {self.candidate_range_m:g} m is below "
                f"{range_min_m:g} m (cpa_req_m = {self.cpa_req_m:g} m, and 1 m at the least); "
                "a pair must be a candidate before its CPA can trigger: give a range of at least "
                "that (2 nm, 3704 m, is the default)"
            )
        window_steps = (
            self.slab_s
            + 2.0 * (self.tcpa_act_s + self.passing_follow_s)
            + 60.0
            + 4.0 * self.max_gap_s
        ) / self.step_s
        if window_steps > MAX_STEPS_PER_SLAB:
            raise ParameterError(
                f"[replay] step_s = {self.step_s:g} s: a slab of {self.slab_s:g} s would hold "
                f"{window_steps:.3g} steps for each vessel, more than memory allows "
                f"({MAX_STEPS_PER_SLAB:.0e}); give a longer step_s (AIS reports come every 2 s "
                "at the most) or a shorter slab_s"
            )
        if self.course_change_deg > 180.0:
            raise ParameterError(
                f"[replay] course_change_deg = {self.course_change_deg}: a course change is at "
                "most 180°; give a value in (0, 180]"
            )
        bad = sorted(
            code
            for code in self.restricted_nav_statuses
            if isinstance(code, bool) or not isinstance(code, int) or not 0 <= code <= 15
        )
        if bad:
            raise ParameterError(
                f"[replay] restricted_nav_statuses contains {bad[0]!r}: AIS navigational "
                "status codes are integers 0–15"
            )


def replay_params_from_table(table: dict[str, Any], where: str) -> ReplayParams:
    """``ReplayParams`` from a ``[replay]`` TOML table; ``where`` names it in messages."""
    return dataclass_from_table(ReplayParams, table, where)


REPLAY_KEYS: tuple[str, ...] = tuple(f.name for f in fields(ReplayParams))


def stage_tables(query: Query) -> tuple[ReplayParams, ColregsParams, ManoeuvrabilityParams]:
    """The query's ``[replay]``, ``[colregs]`` and ``[manoeuvrability]`` tables, each
    checked by its dataclass (a ``QueryError`` or ``ParameterError`` names the key)."""
    where = f"{query.source if query.source is not None else 'query'}"
    tables = query.tables
    return (
        replay_params_from_table(dict(tables.get("replay", {})), f"{where} [replay]"),
        colregs_params_from_table(dict(tables.get("colregs", {})), f"{where} [colregs]"),
        ManoeuvrabilityParams.from_table(
            dict(tables.get("manoeuvrability", {})), f"{where} [manoeuvrability]"
        ),
    )


@dataclass(frozen=True)
class ReplayRunParams:
    """Every parameter of one replay run, as written to run.json."""

    replay: ReplayParams
    colregs: ColregsParams
    manoeuvrability: ManoeuvrabilityParams
    own_mmsi: tuple[int, ...]

    @property
    def pair(self) -> PairParams:
        """What the evaluation of each pair reads (``core/pair.py``)."""
        return PairParams(
            colregs=self.colregs,
            manoeuvrability=self.manoeuvrability,
            encounters=self.replay.encounters,
            conduct=self.replay.conduct,
            rule9=self.replay.rule9,
            dimensions=self.replay.dimension_defaults,
            passing=self.replay.passing,
            interactions=self.replay.interactions,
            claims=NavStatusParams(),
            channels=self.replay.channels,
        )
