"""The paper's manoeuvrability estimator (section "Assessing vessel manoeuvrability").

1. Rate of swing (eq. ``rate_of_swing``): ``δ_swing = 360 / (2π r_turn)`` deg/m, from the 14
   reference vessels of the paper's Table "Overview of vessels used for calculation of rate of
   swing" (package data ``data/turning_circles.csv``), scaled (eq. ``rate_of_swing_scaled``) to
   ``δ' = α·δ_swing`` with α ∈ [0, 1]. For real AIS, the ``length-scaled`` model gives each
   vessel the turning radius of IMO MSC.137(76)'s turning-ability bound, ``r_turn = 2.5·L``
   (``SwingModel`` and ``target_rate_of_swing_deg_per_m``).
2. Turning arcs (eqs. ``pprime``, ``p'_body``, ``psi'``, ``r``): with ``r = 1/δ'`` (δ' in rad/m)
   and path length ``l_k = v·k·Δt`` for k = 1 … horizon/Δt, the heading change is
   ``ψ'_k = l_k·δ'`` and the body-frame offset ``r·[sin ψ', ±(1 − cos ψ')]`` (forward,
   starboard; + for the clockwise, starboard turn). It is rotated by the course into
   (north, east). k = 0, the present position, is not projected: the arcs are the future
   positions, as in the paper. A vessel at rest (v = 0) projects every k onto its present
   position, so the estimator then checks the ellipse where she lies.
3. Comfort zones (the paper's ellipse, with docs/design.md §5's correction of its typo): an ellipse
   with semi-axis ``a = domain_length_factor·L`` along the heading at that point and
   ``b = domain_breadth_factor·B`` across it, as a 32-vertex polygon inscribed in the ellipse.
4. A projected position is restricted when its ellipse is not properly inside the navigable
   water: it touches or crosses the boundary of the feasible depth contour, in the paper's
   words. The verdict over both arcs follows a ``RestrictionPolicy``.

Unknown chart coverage is three-valued, never "clear": no chart, or the target's present
position outside the chart, gives ``UNKNOWN``. A projected position is covered only when its
whole ellipse lies inside the chart's coverage without touching its edge (the edge of a chart
is not the edge of the water); an uncovered one may be either red or blue. The verdict is
``RESTRICTED`` when the policy holds on the covered red positions alone, ``NOT_RESTRICTED``
when it fails even if every uncovered position were red, and ``UNKNOWN`` in between.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from enum import StrEnum
from importlib import resources
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd
import shapely
from numpy.typing import ArrayLike, NDArray

from ..config import dataclass_from_table
from ..errors import ParameterError

if TYPE_CHECKING:
    from ..charts.water import Chart, WaterIndex
    from .vessel_defaults import VesselDimensions

ELLIPSE_VERTICES = 32
# Consecutive projected positions tested together by the coarse distance filter.
_CHUNK_POINTS = 12
# The most projected positions per arc (horizon_s / step_s): each is a 33-vertex ellipse
# tested against the chart, for every target at every assessment (the paper: 180).
MAX_STEPS_PER_ARC = 10_000


class SwingModel(StrEnum):
    """How a target's rate of swing δ_swing is chosen (before scaling by α)."""

    FIXED = "fixed"
    NEAREST_LENGTH = "nearest-length"
    LOWER_BOUND = "lower-bound"
    LENGTH_SCALED = "length-scaled"


# IMO resolution MSC.137(76), Standards for ship manoeuvrability (2002), section 5.3.1: "the
# tactical diameter should not exceed 5 ship lengths in the turning circle manoeuvre" (35°
# rudder, or the maximum if less, deep water). The steady turning circle lies inside the
# tactical diameter, so half of it bounds the turning radius of a ship that meets the standard.
IMO_TACTICAL_DIAMETER_LENGTHS = 5.0
TURN_RADIUS_LENGTHS = IMO_TACTICAL_DIAMETER_LENGTHS / 2.0


class RestrictionPolicy(StrEnum):
    """When the red positions on the two arcs make the target restricted (event d3)."""

    ANY = "any"
    BOTH_SIDES = "both-sides"
    STARBOARD = "starboard"


class Restriction(StrEnum):
    """The estimator's verdict; ``UNKNOWN`` where the chart cannot tell."""

    RESTRICTED = "true"
    NOT_RESTRICTED = "false"
    UNKNOWN = "unknown"


class Arc(StrEnum):
    CLOCKWISE = "cw"
    COUNTER_CLOCKWISE = "ccw"


def _positive(name: str, value: float, unit: str) -> None:
    if not (math.isfinite(value) and value > 0.0):
        raise ParameterError(f"{name} {value} {unit} is not positive; give a value > 0")


@dataclass(frozen=True)
class ManoeuvrabilityParams:
    """Parameters of the estimator; defaults are the paper's Table "Simulation parameters",
    but for the swing model: ``length-scaled`` (a turning radius of 2.5 L, IMO MSC.137(76))
    suits real AIS, where vessels of 5 m to 400 m meet; the paper's ``fixed`` 0.2 deg/m gives
    every vessel a 716 m radius (with α 0.4), a setting for its case study, which keeps it
    (``data/demo/greenhopper.toml``).

    ``swing_deg_per_m`` is the rate of swing of the ``fixed`` model (the paper: 0.2 deg/m);
    ``horizon_s`` is the look-ahead (the paper's TCPA_act, 180 s) at ``step_s``. ``alpha``
    scales every model's δ_swing alike: it is the fraction of the vessel's hard-over turning
    ability that the arcs use (the paper's eq. ``rate_of_swing_scaled``).
    """

    swing_model: SwingModel = SwingModel.LENGTH_SCALED
    swing_deg_per_m: float = 0.2
    alpha: float = 0.4
    horizon_s: float = 180.0
    step_s: float = 1.0
    domain_length_factor: float = 1.0
    domain_breadth_factor: float = 1.5
    ukc_m: float = 0.0
    policy: RestrictionPolicy = RestrictionPolicy.ANY

    def __post_init__(self) -> None:
        try:
            object.__setattr__(self, "swing_model", SwingModel(self.swing_model))
            object.__setattr__(self, "policy", RestrictionPolicy(self.policy))
        except ValueError as exc:
            raise ParameterError(
                f"{exc}; swing_model is one of {', '.join(SwingModel)} and policy one of "
                f"{', '.join(RestrictionPolicy)}"
            ) from None
        if not (math.isfinite(self.alpha) and 0.0 <= self.alpha <= 1.0):
            raise ParameterError(
                f"alpha {self.alpha} is outside [0, 1]; the rate of swing scale α must be "
                "between 0 and 1 (the paper uses 0.4)"
            )
        _positive("swing_deg_per_m", self.swing_deg_per_m, "deg/m")
        _positive("horizon_s", self.horizon_s, "s")
        _positive("step_s", self.step_s, "s")
        _positive("domain_length_factor", self.domain_length_factor, "")
        _positive("domain_breadth_factor", self.domain_breadth_factor, "")
        if self.step_s > self.horizon_s:
            raise ParameterError(
                f"step_s {self.step_s} s is longer than horizon_s {self.horizon_s} s; "
                "give a step no longer than the horizon"
            )
        positions = self.horizon_s / self.step_s
        if positions > MAX_STEPS_PER_ARC:
            raise ParameterError(
                f"horizon_s {self.horizon_s:g} s / step_s {self.step_s:g} s would project "
                f"{positions:.3g} positions on each arc, more than {MAX_STEPS_PER_ARC}; give a "
                "longer step_s or a shorter horizon_s (the paper: 180 s in steps of 1 s)"
            )
        if not (math.isfinite(self.ukc_m) and self.ukc_m >= 0.0):
            raise ParameterError(
                f"ukc_m {self.ukc_m} m is negative; the under-keel clearance must be >= 0"
            )

    @property
    def steps(self) -> int:
        """Projected positions per arc: horizon / step, rounded."""
        return max(1, round(self.horizon_s / self.step_s))

    @classmethod
    def from_table(cls, table: dict[str, Any], where: str) -> ManoeuvrabilityParams:
        """From a ``[manoeuvrability]`` TOML table; unknown keys and bad values are errors."""
        return dataclass_from_table(cls, table, where)


def rate_of_swing_deg_per_m(turn_radius_m: ArrayLike) -> NDArray[np.float64]:
    """The paper's eq. ``rate_of_swing``: heading change per metre on the turning circle."""
    return 360.0 / (2.0 * np.pi * np.asarray(turn_radius_m, dtype=float))


@functools.cache
def _reference_table() -> pd.DataFrame:
    with resources.files("colregs9_cli").joinpath("data/turning_circles.csv").open("rb") as f:
        table = pd.read_csv(f)
    table["rate_of_swing_deg_per_m"] = rate_of_swing_deg_per_m(table["turn_radius_m"])
    return table


@functools.cache
def _reference_lengths_and_rates() -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    table = _reference_table()
    return table["length_m"].to_numpy(), table["rate_of_swing_deg_per_m"].to_numpy()


def reference_vessels() -> pd.DataFrame:
    """The paper's 14 reference vessels with their ``rate_of_swing_deg_per_m``."""
    return _reference_table().copy()


def target_rate_of_swing_deg_per_m(length_m: float | None, params: ManoeuvrabilityParams) -> float:
    """δ_swing for a target, before the α scaling of the paper's eq. ``rate_of_swing_scaled``.

    - ``fixed``: ``params.swing_deg_per_m``; the paper's simulations use 0.2 deg/m.
    - ``nearest-length``: the reference vessel closest in length, the paper's idea of
      "comparing against the turning circles of vessels of similar dimensions". Ties go to
      the slower-turning vessel; an unknown length falls back to ``lower-bound``.
    - ``lower-bound``: the table's minimum, 360/(2π·740.8 m) ≈ 0.077 deg/m (the 363.6 m bulk
      carrier). The paper reads "≈ 0.1 deg/m" off its figure as the lower bound; the table's
      exact minimum is used here.
    - ``length-scaled``: ``360 / (2π · 2.5·L)``, the turning radius of ``imo_turn_radius_m``,
      so that a vessel turns in proportion to her size (a 12 m yacht 30 m, a 300 m ship
      750 m). An unknown length falls back to ``lower-bound``, as for ``nearest-length``; in a
      replay the length is never unknown, since ``core.vessel_defaults`` fills it in (and
      names it in ``defaulted``). A length that is not positive is a ``ParameterError``.
    """
    if params.swing_model is SwingModel.FIXED:
        return params.swing_deg_per_m
    if (
        params.swing_model is SwingModel.LENGTH_SCALED
        and length_m is not None
        and math.isfinite(length_m)
    ):
        _positive("target length_m", length_m, "m")
        return float(rate_of_swing_deg_per_m(imo_turn_radius_m(length_m)))
    lengths, rates = _reference_lengths_and_rates()
    if (
        params.swing_model is SwingModel.LOWER_BOUND
        or length_m is None
        or not np.isfinite(length_m)
    ):
        return float(rates.min())
    gap = np.abs(lengths - length_m)
    nearest = gap == gap.min()
    return float(rates[nearest].min())


def imo_turn_radius_m(length_m: ArrayLike) -> NDArray[np.float64]:
    """The hard-over turning radius of the ``length-scaled`` model: ``2.5 · L``.

    Half of MSC.137(76)'s largest tactical diameter, 5 L (``TURN_RADIUS_LENGTHS``). The
    standard measures L between perpendiculars in deep water; AIS gives the length overall,
    a few per cent longer, so the radius errs to the wide side. The standard covers ships
    of 100 m and over: for small craft the same ratio is an extrapolation.
    """
    return TURN_RADIUS_LENGTHS * np.asarray(length_m, dtype=float)


def scaled_rate_of_swing_deg_per_m(length_m: float | None, params: ManoeuvrabilityParams) -> float:
    """δ' = α·δ_swing (deg/m), the rate of swing the turning arcs actually use."""
    return params.alpha * target_rate_of_swing_deg_per_m(length_m, params)


def arc_turn_radius_m(length_m: float | None, params: ManoeuvrabilityParams) -> float:
    """The radius of the turning arcs projected for a vessel: ``1 / δ'`` with δ' in rad/m.

    ``inf`` when α = 0 (the arcs run straight ahead). For ``length-scaled`` it is
    ``2.5·L / α``; for ``fixed`` it is the same for every vessel (the paper: 716.2 m).
    """
    rate = scaled_rate_of_swing_deg_per_m(length_m, params)
    return 1.0 / math.radians(rate) if rate > 0.0 else math.inf


@dataclass(frozen=True)
class TurningArcs:
    """Projected positions: the clockwise arc (k = 1…n) then the counter-clockwise arc."""

    arc: NDArray[np.str_]
    step: NDArray[np.int64]
    path_length_m: NDArray[np.float64]
    north_m: NDArray[np.float64]
    east_m: NDArray[np.float64]
    heading_deg: NDArray[np.float64]
    turn_radius_m: float


def turning_arcs(
    north_m: float,
    east_m: float,
    course_deg: float,
    speed_mps: float,
    rate_of_swing_deg_per_m: float,
    horizon_s: float,
    step_s: float,
) -> TurningArcs:
    """Both arcs from (p, ψ, v) at the scaled rate ``δ'`` (deg/m) over the horizon.

    A rate of 0 (α = 0) means an infinite radius: both arcs run straight ahead.
    """
    steps = max(1, round(horizon_s / step_s))
    k = np.arange(1, steps + 1)
    path_m = speed_mps * step_s * k
    rate_rad_per_m = math.radians(rate_of_swing_deg_per_m)
    if rate_rad_per_m > 0.0:
        radius_m = 1.0 / rate_rad_per_m
        turn_rad = path_m * rate_rad_per_m
        forward_m = radius_m * np.sin(turn_rad)
        starboard_m = radius_m * (1.0 - np.cos(turn_rad))
    else:
        radius_m = math.inf
        turn_rad = np.zeros_like(path_m)
        forward_m = path_m
        starboard_m = np.zeros_like(path_m)
    forward_m = np.concatenate([forward_m, forward_m])
    starboard_m = np.concatenate([starboard_m, -starboard_m])
    course_rad = math.radians(course_deg)
    cos_c, sin_c = math.cos(course_rad), math.sin(course_rad)
    turn_deg = np.degrees(turn_rad)
    return TurningArcs(
        arc=np.repeat(np.array([Arc.CLOCKWISE.value, Arc.COUNTER_CLOCKWISE.value]), steps),
        step=np.concatenate([k, k]),
        path_length_m=np.concatenate([path_m, path_m]),
        north_m=north_m + forward_m * cos_c - starboard_m * sin_c,
        east_m=east_m + forward_m * sin_c + starboard_m * cos_c,
        heading_deg=np.mod(course_deg + np.concatenate([turn_deg, -turn_deg]), 360.0),
        turn_radius_m=radius_m,
    )


@functools.lru_cache(maxsize=64)
def _unit_ellipse(a_m: float, b_m: float, n_vertices: int) -> tuple[NDArray, NDArray]:
    """Body-frame (forward, starboard) vertices, closed, inscribed in the ellipse."""
    t_rad = np.linspace(0.0, 2.0 * np.pi, n_vertices + 1)
    forward_m, starboard_m = a_m * np.cos(t_rad), b_m * np.sin(t_rad)
    forward_m[-1], starboard_m[-1] = forward_m[0], starboard_m[0]
    forward_m.flags.writeable = starboard_m.flags.writeable = False
    return forward_m, starboard_m


def ellipse_polygons(
    north_m: ArrayLike,
    east_m: ArrayLike,
    heading_deg: ArrayLike,
    a_m: float,
    b_m: float,
    n_vertices: int = ELLIPSE_VERTICES,
) -> NDArray[np.object_]:
    """Ellipses (semi-axis ``a_m`` along the heading, ``b_m`` across) as shapely polygons.

    Coordinates are built with numpy and turned into polygons in one shapely call; x is east.
    """
    north = np.atleast_1d(np.asarray(north_m, dtype=float))
    east = np.atleast_1d(np.asarray(east_m, dtype=float))
    heading_rad = np.radians(np.atleast_1d(np.asarray(heading_deg, dtype=float)))
    forward_m, starboard_m = _unit_ellipse(float(a_m), float(b_m), n_vertices)
    cos_h, sin_h = np.cos(heading_rad), np.sin(heading_rad)
    count, ring = len(north), len(forward_m)
    # (x, y) = (east, north) interleaved, written in place: the layout from_ragged_array takes.
    coords = np.empty((count, ring, 2))
    np.multiply.outer(sin_h, forward_m, out=coords[:, :, 0])
    coords[:, :, 0] += np.multiply.outer(cos_h, starboard_m)
    coords[:, :, 0] += east[:, None]
    np.multiply.outer(cos_h, forward_m, out=coords[:, :, 1])
    coords[:, :, 1] -= np.multiply.outer(sin_h, starboard_m)
    coords[:, :, 1] += north[:, None]
    # One ragged-array call builds every ring and polygon, faster than shapely.polygons
    # (figures: tests/benchmarks/README.md).
    return shapely.from_ragged_array(
        shapely.GeometryType.POLYGON,
        coords.reshape(-1, 2),
        (np.arange(0, count * ring + 1, ring), np.arange(count + 1)),
    )


def restricted_flags(
    index: WaterIndex,
    north_m: NDArray[np.float64],
    east_m: NDArray[np.float64],
    heading_deg: NDArray[np.float64],
    a_m: float,
    b_m: float,
    n_vertices: int = ELLIPSE_VERTICES,
) -> NDArray[np.bool_]:
    """True where the ellipse at a position is not properly inside the navigable water.

    Exact for the polygonal ellipses, and vectorised. A position whose centre is outside the
    water is restricted. Runs of ``_CHUNK_POINTS`` consecutive positions whose bounding circle,
    widened by the ellipse's outer radius max(a, b), stays clear of the water's boundary are
    decided by one prepared distance query and the run's centre (all clear if it is in the
    water). Only the positions left build their ellipses, all tested in one
    ``shapely.contains_properly`` call.
    (Per-position distance filters were measured and cost more than they save.)
    """
    n = len(north_m)
    if n == 0 or shapely.is_empty(index.boundary):
        return ~np.asarray(shapely.contains_xy(index.water, east_m, north_m), dtype=bool)
    # A hair outside, so that rounding never calls a touching polygon clear.
    outer_m = max(a_m, b_m) * (1.0 + 1e-9)
    starts = np.arange(0, n, _CHUNK_POINTS)
    chunk = np.arange(n) // _CHUNK_POINTS
    counts = np.diff(np.append(starts, n))
    centre_east = np.add.reduceat(east_m, starts) / counts
    centre_north = np.add.reduceat(north_m, starts) / counts
    spread_m = np.maximum.reduceat(
        np.hypot(east_m - centre_east[chunk], north_m - centre_north[chunk]), starts
    )
    near_chunks = shapely.dwithin(
        index.boundary,
        shapely.points(np.column_stack([centre_east, centre_north])),
        spread_m + outer_m,
    )
    # A far run lies in one face of the boundary: in the water or not, as its centre is.
    far = ~near_chunks
    centre_in_water = np.ones(len(starts), dtype=bool)
    centre_in_water[far] = shapely.contains_xy(index.water, centre_east[far], centre_north[far])
    restricted = ~centre_in_water[chunk]
    near = np.flatnonzero(near_chunks[chunk])
    inside = np.asarray(shapely.contains_xy(index.water, east_m[near], north_m[near]), dtype=bool)
    restricted[near[~inside]] = True
    exact = near[inside]
    if len(exact):
        ellipses = ellipse_polygons(
            north_m[exact], east_m[exact], heading_deg[exact], a_m, b_m, n_vertices
        )
        restricted[exact] = ~shapely.contains_properly(index.water, ellipses)
    return restricted


def _policy_holds(
    policy: RestrictionPolicy, flags: NDArray[np.bool_], clockwise: NDArray[np.bool_]
) -> bool:
    starboard = bool(flags[clockwise].any())
    port = bool(flags[~clockwise].any())
    if policy is RestrictionPolicy.ANY:
        return starboard or port
    if policy is RestrictionPolicy.BOTH_SIDES:
        return starboard and port
    return starboard


def verdict(
    policy: RestrictionPolicy,
    arc: NDArray[np.str_],
    restricted: NDArray[np.bool_],
    covered: NDArray[np.bool_],
    start_covered: bool,
) -> Restriction:
    """Three-valued verdict: uncovered positions are neither red nor blue (module docstring)."""
    if not start_covered:
        return Restriction.UNKNOWN
    clockwise = arc == Arc.CLOCKWISE.value
    if _policy_holds(policy, restricted & covered, clockwise):
        return Restriction.RESTRICTED
    if _policy_holds(policy, restricted | ~covered, clockwise):
        return Restriction.UNKNOWN
    return Restriction.NOT_RESTRICTED


@dataclass(frozen=True)
class ManoeuvrabilityAssessment:
    """One estimate: every projected position, its flag, and the verdict under ``policy``.

    ``rate_of_swing_deg_per_m`` is the scaled δ' and ``turn_radius_m`` = 1/δ' (rad/m).
    ``restricted`` is the geometric flag (ellipse not inside navigable water); ``covered``
    tells whether the position's whole ellipse is inside the chart. ``ellipses`` is built on
    first use.
    """

    restriction: Restriction
    policy: RestrictionPolicy
    rate_of_swing_deg_per_m: float
    turn_radius_m: float
    arc: NDArray[np.str_]
    step: NDArray[np.int64]
    north_m: NDArray[np.float64]
    east_m: NDArray[np.float64]
    heading_deg: NDArray[np.float64]
    restricted: NDArray[np.bool_]
    covered: NDArray[np.bool_]
    length_m: float
    breadth_m: float
    draught_m: float
    a_m: float
    b_m: float

    @functools.cached_property
    def ellipses(self) -> NDArray[np.object_]:
        return ellipse_polygons(self.north_m, self.east_m, self.heading_deg, self.a_m, self.b_m)


@dataclass(frozen=True)
class VesselState:
    """The vessel's state in the run's local frame; ``course_deg`` is a grid course."""

    north_m: float
    east_m: float
    course_deg: float
    speed_mps: float


def _check_target(**values: float) -> None:
    for name, value in values.items():
        if not math.isfinite(value):
            raise ParameterError(f"target {name} {value} is not a finite number")
    for name in ("length_m", "breadth_m"):
        _positive(f"target {name}", values[name], "m")
    for name in ("draught_m", "speed_mps"):
        if values[name] < 0.0:
            raise ParameterError(f"target {name} {values[name]} is negative; give a value >= 0")


def assess_manoeuvrability(
    chart: Chart | None,
    state: VesselState,
    dimensions: VesselDimensions,
    params: ManoeuvrabilityParams,
) -> ManoeuvrabilityAssessment:
    """Project both arcs, place the comfort zones and check them against the chart."""
    north_m, east_m = state.north_m, state.east_m
    course_deg, speed_mps = state.course_deg, state.speed_mps
    length_m, breadth_m = dimensions.length_m, dimensions.breadth_m
    draught_m = dimensions.draught_m
    _check_target(
        north_m=north_m,
        east_m=east_m,
        course_deg=course_deg,
        speed_mps=speed_mps,
        length_m=length_m,
        breadth_m=breadth_m,
        draught_m=draught_m,
    )
    rate = scaled_rate_of_swing_deg_per_m(length_m, params)
    arcs = turning_arcs(
        north_m, east_m, course_deg, speed_mps, rate, params.horizon_s, params.step_s
    )
    a_m = params.domain_length_factor * length_m
    b_m = params.domain_breadth_factor * breadth_m
    if chart is None:
        covered = np.zeros(len(arcs.arc), dtype=bool)
        restricted = np.zeros(len(arcs.arc), dtype=bool)
        restriction = Restriction.UNKNOWN
    else:
        # No ellipse reaches farther from the start than the path sailed and its semi-axis.
        reach_m = speed_mps * params.step_s * params.steps + max(a_m, b_m)
        if chart.covers_disk(north_m, east_m, reach_m):
            covered, start_covered = np.ones(len(arcs.arc), dtype=bool), True
        else:
            # An ellipse that reaches past the chart is unknown, never red (``verdict``).
            covered = chart.covers_shapes(
                arcs.north_m,
                arcs.east_m,
                lambda rows: ellipse_polygons(
                    arcs.north_m[rows], arcs.east_m[rows], arcs.heading_deg[rows], a_m, b_m
                ),
                max(a_m, b_m),
            )
            start_covered = bool(chart.covers(north_m, east_m)[0])
        restricted = restricted_flags(
            chart.water_index(draught_m, params.ukc_m),
            arcs.north_m,
            arcs.east_m,
            arcs.heading_deg,
            a_m,
            b_m,
        )
        restriction = verdict(params.policy, arcs.arc, restricted, covered, start_covered)
    return ManoeuvrabilityAssessment(
        restriction=restriction,
        policy=params.policy,
        rate_of_swing_deg_per_m=rate,
        turn_radius_m=arcs.turn_radius_m,
        arc=arcs.arc,
        step=arcs.step,
        north_m=arcs.north_m,
        east_m=arcs.east_m,
        heading_deg=arcs.heading_deg,
        restricted=restricted,
        covered=covered,
        length_m=length_m,
        breadth_m=breadth_m,
        draught_m=draught_m,
        a_m=a_m,
        b_m=b_m,
    )


def unplaced_assessment(
    dimensions: VesselDimensions, params: ManoeuvrabilityParams
) -> ManoeuvrabilityAssessment:
    """The estimate for a vessel that has no place in the run's map frame (far beyond its
    reach, where no chart is): ``unknown``, with no projected positions."""
    length_m, breadth_m = dimensions.length_m, dimensions.breadth_m
    draught_m = dimensions.draught_m
    empty = np.empty(0, dtype=float)
    return ManoeuvrabilityAssessment(
        restriction=Restriction.UNKNOWN,
        policy=params.policy,
        rate_of_swing_deg_per_m=scaled_rate_of_swing_deg_per_m(length_m, params),
        turn_radius_m=arc_turn_radius_m(length_m, params),
        arc=np.empty(0, dtype=str),
        step=np.empty(0, dtype=np.int64),
        north_m=empty,
        east_m=empty,
        heading_deg=empty,
        restricted=np.empty(0, dtype=bool),
        covered=np.empty(0, dtype=bool),
        length_m=length_m,
        breadth_m=breadth_m,
        draught_m=draught_m,
        a_m=params.domain_length_factor * length_m,
        b_m=params.domain_breadth_factor * breadth_m,
    )
