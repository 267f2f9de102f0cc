"""UN R157 test points from the C&C Preventable boundaries (JAMA Annex G, G.5.7).

Per ODD ego speed (and, for cut-in, relative speed):

- cut-in and cut-out, Vy in ``vy_fine`` steps (0.1 m/s): on the boundary, +1 m and +2 m;
- cut-in and cut-out, Vy in ``vy_coarse`` steps (0.5 m/s): boundary +10 m and +30 m;
- cut-in only, Vy in ``vy_coarse`` steps: one point 5 m inside the Unpreventable side;
- deceleration (G.5.7 is silent; our addition): every (Ve0, Gx_max) of the ODD grid at the
  ``thw_s`` following gap.

The boundary is the gap the offsets are added to: dx0 for cut-in, dx0_f for cut-out. It is
rounded up to ``resolution_m`` (0.1 m), so the "boundary" point is the smallest gap on that
grid that is Preventable. For the cut-in it is the upper end of the exact colliding regions
(:mod:`hiyari.risk.cc.regions`): the gaps below it need not all collide (the ego may pass
before the other car enters), so the Unpreventable point goes 5 m below the boundary when
that gap collides, else to the middle of the highest colliding interval. Each point's
``expected`` verdict is the C&C driver's own outcome there, exact: for the cut-in whether the
gap lies in a colliding region (:func:`cut_in_expected`), else the evaluator's verdict:
``"preventable"`` (the automated system must not collide) or ``"unpreventable"`` (collision
allowed; Annex G asks only that the system keeps braking).

Dropped, and counted in :class:`PointSet.skipped`: infeasible Vy at low speed (Vy above
Vo0 x tan(max_heading_deg)), cut-ins with Vo0 <= 0, combinations with no Preventable gap at
all (boundary ``inf``), Unpreventable points where no gap collides, points with a negative
gap, and cut-out points where the lead itself would hit the stopped vehicle (Annex G
excludes them).

Files: CSV (one row per point, empty cell = not applicable) and JSON (``{"format":
"hiyari-r157-points", "version": 1, "params": {...}, "config": {...}, "points": [...]}``).
:func:`load_points` reads either back into :class:`R157Point` objects.
"""

from __future__ import annotations

import csv
import json
import math
from collections import Counter
from dataclasses import asdict, dataclass, field, fields
from pathlib import Path

import numpy as np

from hiyari.atomic import atomic_path
from hiyari.errors import HiyariError
from hiyari.risk.cc.boundary import (
    Grid,
    ceil_to_resolution,
    check_speed_grid,
    check_vy_grid,
    cut_out_boundary,
)
from hiyari.risk.cc.evaluator import (
    cut_in_setup,
    cut_out_lead_clear_gap,
    cut_out_setup,
    decel_setup,
    run_chunked,
)
from hiyari.risk.cc.model import CCParams
from hiyari.risk.cc.regions import Regions, cut_in_regions
from hiyari.risk.cc.trajectory import cut_in_tracks, cut_out_tracks, decel_tracks
from hiyari.units import KMH_PER_MPS

FORMAT = "hiyari-r157-points"
VERSION = 1
SCENARIOS = ("cut-in", "cut-out", "decel")
PREVENTABLE = "preventable"
UNPREVENTABLE = "unpreventable"
_DEFAULT = CCParams()


@dataclass(frozen=True)
class R157Point:
    """One concrete test scenario. ``None`` = not applicable to this scenario type.

    ``scenario``: "cut-in" | "cut-out" | "decel"; ``point``: where it lies ("boundary",
    "boundary+1m", ..., "boundary-5m", "thw" for deceleration); speeds in km/h and m/s;
    ``dx0_m``: ego front to other vehicle 1's rear; ``vy_mps``: its lateral velocity;
    ``gx_max_g``: its deceleration (decel only); ``dx0_f_m``: vehicle 1's front to the stopped
    vehicle 2's rear (cut-out only); ``boundary_m``: the boundary gap the point derives from
    (dx0 for cut-in, dx0_f for cut-out); ``offset_m``: gap - boundary; ``expected``:
    "preventable" / "unpreventable"; ``cc_min_gap_m``: the C&C driver's minimum gap there.
    """

    id: str
    scenario: str
    point: str
    ve0_kmh: float
    ve0_mps: float
    vo0_kmh: float
    vo0_mps: float
    dx0_m: float
    vy_mps: float | None
    gx_max_g: float | None
    dx0_f_m: float | None
    boundary_m: float | None
    offset_m: float | None
    expected: str
    cc_min_gap_m: float

    @property
    def must_not_collide(self) -> bool:
        """True for points in the Preventable region."""
        return self.expected == PREVENTABLE


_FLOAT_FIELDS = [
    f.name for f in fields(R157Point) if f.name not in ("id", "scenario", "point", "expected")
]


@dataclass(frozen=True)
class R157Config:
    """The ODD grid and the Annex G placement rules (speeds in km/h, Vy in m/s, gaps in m)."""

    ve0_kmh: Grid = Grid(20, 60, 10)
    dv_kmh: Grid = Grid(0, 60, 10)
    vy_fine: Grid = Grid(0.1, 3.0, 0.1)
    vy_coarse: Grid = Grid(0.5, 3.0, 0.5)
    near_offsets_m: tuple[float, ...] = (0.0, 1.0, 2.0)
    far_offsets_m: tuple[float, ...] = (10.0, 30.0)
    unpreventable_offset_m: float = -5.0
    gx_max_g: Grid = Grid(0.1, 1.0, 0.1)
    scenarios: tuple[str, ...] = SCENARIOS
    resolution_m: float = 0.1

    def __post_init__(self) -> None:
        unknown = sorted(set(self.scenarios) - set(SCENARIOS))
        if unknown or not self.scenarios:
            raise HiyariError(
                f"scenarios: expected some of {', '.join(SCENARIOS)}, got {', '.join(unknown) or 'none'}"
            )
        if self.resolution_m <= 0:
            raise HiyariError(f"resolution_m must be > 0, got {self.resolution_m}")

    def as_dict(self) -> dict:
        """JSON-friendly description (grids as "start:stop:step")."""
        out: dict[str, object] = {}
        for f in fields(self):
            value = getattr(self, f.name)
            out[f.name] = str(value) if isinstance(value, Grid) else value
        return out


@dataclass
class PointSet:
    """Generated points plus what was dropped and why (reason -> count)."""

    points: list[R157Point]
    skipped: Counter = field(default_factory=Counter)
    params: CCParams = _DEFAULT
    config: R157Config = field(default_factory=R157Config)

    def counts(self) -> dict[str, int]:
        """Points per (scenario, expected verdict)."""
        return dict(Counter(f"{p.scenario} {p.expected}" for p in self.points))


def _label(offset: float) -> str:
    return "boundary" if offset == 0 else f"boundary{offset:+g}m"


def _vy_offsets(config: R157Config, with_unpreventable: bool) -> list[tuple[np.ndarray, float]]:
    """(Vy values, offset) pairs of the G.5.7 placement."""
    pairs = [(config.vy_fine.values(), off) for off in config.near_offsets_m]
    pairs += [(config.vy_coarse.values(), off) for off in config.far_offsets_m]
    if with_unpreventable:
        pairs.append((config.vy_coarse.values(), config.unpreventable_offset_m))
    return pairs


def _kmh_id(v: float) -> str:
    return f"{v:g}"


def _cut_in_points(config: R157Config, p: CCParams, skipped: Counter) -> list[R157Point]:
    ve_list, dv_list = config.ve0_kmh.values(), config.dv_kmh.values()
    rows = []
    for vys, off in _vy_offsets(config, with_unpreventable=True):
        ve, dv, vy = (a.ravel() for a in np.meshgrid(ve_list, dv_list, vys, indexing="ij"))
        rows.append((ve, np.round(ve - dv, 9), vy, np.full(ve.size, off)))
    ve, vo, vy, off = (np.concatenate(c) for c in zip(*rows, strict=True))
    tan = math.tan(math.radians(p.max_heading_deg))
    moving = vo > 0
    skipped["cut-in: Vo0 <= 0"] += int((~moving).sum())
    feasible = moving & (vy <= vo / KMH_PER_MPS * tan + 1e-9)
    skipped["cut-in: Vy infeasible at Vo0"] += int((moving & ~feasible).sum())
    ve, vo, vy, off = ve[feasible], vo[feasible], vy[feasible], off[feasible]
    v_e, v_o = ve / KMH_PER_MPS, vo / KMH_PER_MPS
    regions = cut_in_regions(v_e, v_o, vy, p)
    boundary = ceil_to_resolution(regions.upper, config.resolution_m)
    finite = np.isfinite(boundary)
    # a boundary that is itself a colliding gap (the one-point interval [0, 0] of a car cutting
    # in at the ego's speed from touching its front) moves a grid step up: the boundary point
    # is on the Preventable side
    edge = finite & regions.contains(np.where(finite, boundary, 0.0))
    boundary = np.where(edge, np.round(boundary + config.resolution_m, 9), boundary)
    skipped["cut-in: no Preventable gap (boundary inf)"] += int((~finite).sum())
    dx0 = np.round(boundary + off, 9)
    inside = off < 0
    if inside.any():
        dx0[inside] = _unpreventable_gap(regions.rows(inside), dx0[inside], config.resolution_m)
        with np.errstate(invalid="ignore"):  # inf - inf where there is no boundary
            off = np.where(inside, np.round(dx0 - boundary, 9), off)
    nothing = finite & np.isnan(dx0)
    skipped["cut-in: no colliding gap for the Unpreventable point"] += int(nothing.sum())
    ok = finite & (dx0 >= 0)
    skipped["cut-in: negative gap"] += int((finite & (dx0 < 0)).sum())
    ve, vo, vy, off, v_e, v_o, boundary, dx0 = (
        a[ok] for a in (ve, vo, vy, off, v_e, v_o, boundary, dx0)
    )
    expected = regions.rows(ok).contains(dx0)
    result = run_chunked(lambda *a: cut_in_setup(*a, p), [v_e, v_o, dx0, vy], p)
    return [
        R157Point(
            id=f"cut-in/ve{_kmh_id(ve[i])}/vo{_kmh_id(vo[i])}/vy{vy[i]:g}/{_label(off[i])}",
            scenario="cut-in",
            point=_label(off[i]),
            ve0_kmh=float(ve[i]),
            ve0_mps=float(v_e[i]),
            vo0_kmh=float(vo[i]),
            vo0_mps=float(v_o[i]),
            dx0_m=float(dx0[i]),
            vy_mps=float(vy[i]),
            gx_max_g=None,
            dx0_f_m=None,
            boundary_m=float(boundary[i]),
            offset_m=float(off[i]),
            expected=UNPREVENTABLE if expected[i] else PREVENTABLE,
            cc_min_gap_m=float(result.min_gap_m[i]),
        )
        for i in range(ve.size)
    ]


def _unpreventable_gap(regions: Regions, wanted: np.ndarray, resolution: float) -> np.ndarray:
    """``wanted`` where it collides, else the middle of the highest colliding interval (on
    the ``resolution`` grid when one of its gaps is strictly inside; nan if none)."""
    last = np.maximum(regions.count - 1, 0)[:, None]
    lo = np.take_along_axis(regions.lo, last, 1)[:, 0]
    hi = np.take_along_axis(regions.hi, last, 1)[:, 0]
    mid = np.round(np.round(0.5 * (lo + hi) / resolution) * resolution, 9)
    mid = np.where(regions.contains(mid), mid, 0.5 * (lo + hi))
    return np.where(regions.contains(wanted), wanted, mid)


def cut_in_expected(points: list[R157Point], params: CCParams = _DEFAULT) -> list[str]:
    """The C&C verdict of cut-in points from the exact colliding regions of their (Ve0,
    Vo0, Vy): "unpreventable" where the gap lies in one, else "preventable"."""
    if not points:
        return []
    ve, vo, dx0, vy = (
        np.array([getattr(q, name) for q in points], dtype=float)
        for name in ("ve0_mps", "vo0_mps", "dx0_m", "vy_mps")
    )
    hit = cut_in_regions(ve, vo, vy, params).contains(dx0)
    return [UNPREVENTABLE if h else PREVENTABLE for h in hit]


def expected_verdicts(points: list[R157Point], params: CCParams = _DEFAULT) -> list[str]:
    """The C&C verdict of each point under ``params``: cut-in from the exact colliding
    regions (:func:`cut_in_expected`), cut-out and deceleration from the evaluator."""
    out: list[str | None] = [None] * len(points)
    for scenario in SCENARIOS:
        index = [i for i, q in enumerate(points) if q.scenario == scenario]
        if not index:
            continue
        chosen = [points[i] for i in index]
        if scenario == "cut-in":
            verdicts = cut_in_expected(chosen, params)
        else:
            col = {
                name: np.array([getattr(q, name) for q in chosen], dtype=float)
                for name in ("ve0_mps", "vy_mps", "dx0_f_m", "gx_max_g", "dx0_m")
                if all(getattr(q, name) is not None for q in chosen)
            }
            if scenario == "cut-out":
                setup = (cut_out_setup, [col["ve0_mps"], col["vy_mps"], col["dx0_f_m"]])
            else:
                setup = (decel_setup, [col["ve0_mps"], col["gx_max_g"], col["dx0_m"]])
            hit = run_chunked(lambda *a, f=setup[0]: f(*a, params), setup[1], params).collision
            verdicts = [UNPREVENTABLE if h else PREVENTABLE for h in hit]
        for i, verdict in zip(index, verdicts, strict=True):
            out[i] = verdict
    return out


def _cut_out_points(config: R157Config, p: CCParams, skipped: Counter) -> list[R157Point]:
    rows = []
    for vys, off in _vy_offsets(config, with_unpreventable=False):
        ve, vy = (a.ravel() for a in np.meshgrid(config.ve0_kmh.values(), vys, indexing="ij"))
        rows.append((ve, vy, np.full(ve.size, off)))
    ve, vy, off = (np.concatenate(c) for c in zip(*rows, strict=True))
    tan = math.tan(math.radians(p.max_heading_deg))
    feasible = (ve > 0) & (vy <= ve / KMH_PER_MPS * tan + 1e-9)
    skipped["cut-out: Vy infeasible at Vo0"] += int((~feasible).sum())
    ve, vy, off = ve[feasible], vy[feasible], off[feasible]
    v_e = ve / KMH_PER_MPS
    boundary = ceil_to_resolution(cut_out_boundary(v_e, vy, p), config.resolution_m)
    finite = np.isfinite(boundary)
    skipped["cut-out: no Preventable gap (boundary inf)"] += int((~finite).sum())
    dx0_f = np.round(boundary + off, 9)
    clear = cut_out_lead_clear_gap(v_e, vy, p)
    ok = finite & (dx0_f > 0) & (dx0_f >= clear - 1e-9)
    skipped["cut-out: lead would hit the stopped vehicle"] += int((finite & ~ok).sum())
    ve, vy, off, v_e, boundary, dx0_f = (a[ok] for a in (ve, vy, off, v_e, boundary, dx0_f))
    result = run_chunked(lambda *a: cut_out_setup(*a, p), [v_e, vy, dx0_f], p)
    return [
        R157Point(
            id=f"cut-out/ve{_kmh_id(ve[i])}/vy{vy[i]:g}/{_label(off[i])}",
            scenario="cut-out",
            point=_label(off[i]),
            ve0_kmh=float(ve[i]),
            ve0_mps=float(v_e[i]),
            vo0_kmh=float(ve[i]),
            vo0_mps=float(v_e[i]),
            dx0_m=float(p.thw_s * v_e[i]),
            vy_mps=float(vy[i]),
            gx_max_g=None,
            dx0_f_m=float(dx0_f[i]),
            boundary_m=float(boundary[i]),
            offset_m=float(off[i]),
            expected=UNPREVENTABLE if result.collision[i] else PREVENTABLE,
            cc_min_gap_m=float(result.min_gap_m[i]),
        )
        for i in range(ve.size)
    ]


def _decel_points(config: R157Config, p: CCParams) -> list[R157Point]:
    ve, gx = (
        a.ravel()
        for a in np.meshgrid(config.ve0_kmh.values(), config.gx_max_g.values(), indexing="ij")
    )
    v_e = ve / KMH_PER_MPS
    dx0 = p.thw_s * v_e
    result = run_chunked(lambda *a: decel_setup(*a, p), [v_e, gx, dx0], p)
    return [
        R157Point(
            id=f"decel/ve{_kmh_id(ve[i])}/gx{gx[i]:g}/thw{p.thw_s:g}",
            scenario="decel",
            point="thw",
            ve0_kmh=float(ve[i]),
            ve0_mps=float(v_e[i]),
            vo0_kmh=float(ve[i]),
            vo0_mps=float(v_e[i]),
            dx0_m=float(dx0[i]),
            vy_mps=None,
            gx_max_g=float(gx[i]),
            dx0_f_m=None,
            boundary_m=None,
            offset_m=None,
            expected=UNPREVENTABLE if result.collision[i] else PREVENTABLE,
            cc_min_gap_m=float(result.min_gap_m[i]),
        )
        for i in range(ve.size)
    ]


def generate_points(config: R157Config = R157Config(), params: CCParams = _DEFAULT) -> PointSet:
    """All R157 test points of ``config``'s ODD grid, in scenario order."""
    check_speed_grid(config.ve0_kmh, "Ve0")
    if config.ve0_kmh.start <= 0:
        raise HiyariError(f"Ve0 {config.ve0_kmh}: ego speeds must be > 0 km/h")
    check_speed_grid(config.dv_kmh, "Ve0 - Vo0")
    check_vy_grid(config.vy_fine, "Vy (fine)", params.lane_width_m)
    check_vy_grid(config.vy_coarse, "Vy (coarse)", params.lane_width_m)
    if config.gx_max_g.start <= 0 or config.gx_max_g.stop > params.road_mu:
        raise HiyariError(
            f"Gx_max {config.gx_max_g}: must lie in (0, {params.road_mu:g}] g (road friction μ)"
        )
    skipped: Counter = Counter()
    points: list[R157Point] = []
    if "cut-in" in config.scenarios:
        points += _cut_in_points(config, params, skipped)
    if "cut-out" in config.scenarios:
        points += _cut_out_points(config, params, skipped)
    if "decel" in config.scenarios:
        points += _decel_points(config, params)
    return PointSet(points, Counter({k: v for k, v in skipped.items() if v}), params, config)


def point_tracks(
    point: R157Point, t_s: np.ndarray, params: CCParams = _DEFAULT, side: int = 1
) -> dict:
    """Annex G trajectories of a point's other vehicles and the C&C reference ego
    (:mod:`hiyari.risk.cc.trajectory`), sampled at ``t_s`` (s)."""
    if point.scenario == "cut-in":
        return cut_in_tracks(
            point.ve0_mps, point.vo0_mps, point.dx0_m, point.vy_mps, t_s, params, side
        )
    if point.scenario == "cut-out":
        return cut_out_tracks(point.ve0_mps, point.vy_mps, point.dx0_f_m, t_s, params, side)
    return decel_tracks(point.ve0_mps, point.gx_max_g, t_s, params, dx0_m=point.dx0_m)


# ---------------------------------------------------------------- files


def _csv_cell(value: object) -> str:
    if value is None:
        return ""
    if isinstance(value, float):
        return repr(value)
    return str(value)


def write_points_csv(points: list[R157Point], path: str | Path) -> Path:
    """One row per point, columns as :class:`R157Point`; empty cell = not applicable."""
    path = Path(path)
    names = [f.name for f in fields(R157Point)]
    with atomic_path(path) as tmp, tmp.open("w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(names)
        for p in points:
            writer.writerow([_csv_cell(getattr(p, n)) for n in names])
    return path


def write_points_json(point_set: PointSet, path: str | Path) -> Path:
    """The points with the model parameters and the configuration that produced them."""
    doc = {
        "format": FORMAT,
        "version": VERSION,
        "params": point_set.params.as_dict(),
        "config": point_set.config.as_dict(),
        "skipped": dict(point_set.skipped),
        "points": [asdict(p) for p in point_set.points],
    }
    path = Path(path)
    with atomic_path(path) as tmp:
        tmp.write_text(json.dumps(doc, indent=1, allow_nan=False))
    return path


def _point_from_mapping(row: dict, where: str) -> R157Point:
    names = {f.name for f in fields(R157Point)}
    missing = sorted(names - set(row))
    if missing:
        raise HiyariError(f"{where}: missing field(s) {', '.join(missing)}")
    values: dict[str, object] = {}
    for name in names:
        raw = row[name]
        if name in _FLOAT_FIELDS:
            if raw is None or raw == "":
                values[name] = None
                continue
            try:
                values[name] = float(raw)
            except (TypeError, ValueError):
                raise HiyariError(f"{where}: {name} is not a number: {raw!r}") from None
            if not math.isfinite(values[name]):
                raise HiyariError(f"{where}: {name} is not finite: {raw!r}")
        else:
            values[name] = str(raw)
    point = R157Point(**values)
    if point.scenario not in SCENARIOS:
        raise HiyariError(f"{where}: unknown scenario {point.scenario!r}")
    if point.expected not in (PREVENTABLE, UNPREVENTABLE):
        raise HiyariError(f"{where}: expected must be {PREVENTABLE!r} or {UNPREVENTABLE!r}")
    required = {"cut-in": ["vy_mps"], "cut-out": ["vy_mps", "dx0_f_m"], "decel": ["gx_max_g"]}
    for name in required[point.scenario] + ["ve0_mps", "vo0_mps", "dx0_m", "cc_min_gap_m"]:
        if getattr(point, name) is None:
            raise HiyariError(f"{where}: {point.scenario} point without {name}")
    return point


def load_point_params(path: str | Path) -> CCParams | None:
    """The C&C model stored in a JSON points file (None for CSV, which carries none)."""
    path = Path(path)
    if path.suffix.lower() != ".json":
        return None
    doc = json.loads(path.read_text())  # load_points has refused broken files already
    try:
        return CCParams.from_dict(doc.get("params", {}))
    except (TypeError, HiyariError) as exc:
        raise HiyariError(f"{path}: bad 'params': {exc}") from None


def load_points(path: str | Path) -> list[R157Point]:
    """Read points written by :func:`write_points_csv` or :func:`write_points_json`."""
    path = Path(path)
    if not path.is_file():
        raise HiyariError(f"{path}: no such file")
    if path.suffix.lower() == ".json":
        try:
            doc = json.loads(path.read_text())
        except (json.JSONDecodeError, UnicodeDecodeError) as exc:
            raise HiyariError(f"{path}: not valid JSON ({exc})") from None
        if not isinstance(doc, dict) or doc.get("format") != FORMAT:
            raise HiyariError(f"{path}: not a {FORMAT} file")
        if doc.get("version") != VERSION:
            raise HiyariError(f"{path}: unsupported version {doc.get('version')!r}")
        rows = doc.get("points")
        if not isinstance(rows, list):
            raise HiyariError(f"{path}: 'points' is not a list")
        return [
            _point_from_mapping(r if isinstance(r, dict) else {}, f"{path}: point {i}")
            for i, r in enumerate(rows)
        ]
    try:
        with path.open(newline="") as fh:
            reader = csv.DictReader(fh)
            return [_point_from_mapping(r, f"{path}: line {i + 2}") for i, r in enumerate(reader)]
    except (UnicodeDecodeError, csv.Error) as exc:
        raise HiyariError(f"{path}: not a readable CSV ({exc})") from None
