"""Preventable boundaries of the C&C driver (JAMA Fig. 26, 28, 30) over grids of scenarios.

- cut-in, per (Ve0, Vo0, Vy): every interval of dx0 (ego front to the other's rear) at which
  the C&C driver collides (:mod:`hiyari.risk.cc.regions`), and the Preventable boundary: the
  smallest dx0 from which on it never collides (``inf`` where it collides at every large
  gap). Below the boundary the colliding gaps need not reach down to 0: at small gaps the
  ego may pass before the other car enters its lane.
- cut-out, per (Ve0, Vy): the smallest dx0_f (lead front to the stopped vehicle's rear) from
  which on it never collides, following at ``thw_s``; plus the gap below which the lead
  itself hits the stopped vehicle (Annex G excludes those).
- deceleration, per (Ve0, Gx_max): Preventable or not at ``thw_s``, the minimum gap, and the
  smallest initial gap that would be Preventable.

Driver-only cut-out and deceleration boundaries are exact closed forms (before braking the
ego holds Ve0, so the gap is dx0 minus a relative displacement that does not depend on dx0).
With the AEB variant the trigger depends on the gap, so those boundaries are found by a scan
of the gap (:class:`SearchOptions`) followed by bisection between the largest colliding scan
point and the next; a collision window narrower than the scan step could be missed. AEB
only ever adds braking, so the driver-only boundary bounds the search.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from hiyari.atomic import atomic_path
from hiyari.errors import HiyariError
from hiyari.risk.cc.evaluator import (
    cut_out_lead_clear_gap,
    cut_out_setup,
    decel_setup,
    run_chunked,
)
from hiyari.risk.cc.model import CCParams
from hiyari.risk.cc.regions import Regions, RegionSearch, cut_in_regions
from hiyari.units import KMH_PER_MPS

_DEFAULT = CCParams()


@dataclass(frozen=True)
class Grid:
    """Inclusive grid ``start``, ``start + step``, ... up to ``stop`` (units by context)."""

    start: float
    stop: float
    step: float

    def __post_init__(self) -> None:
        if not all(math.isfinite(v) for v in (self.start, self.stop, self.step)):
            raise HiyariError(f"grid {self.start}:{self.stop}:{self.step} is not finite")
        if self.step <= 0:
            raise HiyariError(f"grid {self.start}:{self.stop}:{self.step}: step must be > 0")
        if self.stop < self.start:
            raise HiyariError(f"grid {self.start}:{self.stop}:{self.step}: stop below start")
        if (self.stop - self.start) / self.step > 1e7:
            raise HiyariError(f"grid {self.start}:{self.stop}:{self.step} has too many points")

    def values(self) -> np.ndarray:
        """The grid points, rounded to 1e-9 so that 0.1-steps stay exact decimals."""
        n = int(math.floor((self.stop - self.start) / self.step + 1e-9)) + 1
        return np.round(self.start + self.step * np.arange(n), 9)

    @classmethod
    def parse(cls, text: str, name: str) -> Grid:
        """``"start:stop:step"`` or a single number (``name`` is for error messages)."""
        parts = text.split(":")
        try:
            numbers = [float(p) for p in parts]
        except ValueError:
            raise HiyariError(
                f"{name}: expected start:stop:step or a number, got {text!r}"
            ) from None
        if len(numbers) == 1:
            return cls(numbers[0], numbers[0], 1.0)
        if len(numbers) != 3:
            raise HiyariError(f"{name}: expected start:stop:step or a number, got {text!r}")
        try:
            return cls(*numbers)
        except HiyariError as exc:
            raise HiyariError(f"{name}: {exc}") from None

    def __str__(self) -> str:
        return f"{self.start:g}:{self.stop:g}:{self.step:g}"


MAX_SPEED_KMH = 300.0
"""Speeds above this are refused as outside the physics of road vehicles."""


def check_speed_grid(grid: Grid, name: str) -> None:
    """Refuse negative speeds (km/h) and speeds above ``MAX_SPEED_KMH``."""
    if grid.start < 0:
        raise HiyariError(f"{name}: speeds must be >= 0 km/h, got {grid.start:g}")
    if grid.stop > MAX_SPEED_KMH:
        raise HiyariError(f"{name}: {grid.stop:g} km/h is beyond {MAX_SPEED_KMH:g} km/h")


def check_vy_grid(grid: Grid, name: str, lane_width_m: float) -> None:
    """Refuse lateral speeds <= 0 or so large the lane change takes under 0.5 s."""
    if grid.start <= 0:
        raise HiyariError(f"{name}: lateral velocity must be > 0 m/s, got {grid.start:g}")
    if grid.stop > 2 * lane_width_m:
        raise HiyariError(
            f"{name}: {grid.stop:g} m/s would cross a {lane_width_m:g} m lane in under 0.5 s"
        )


def ceil_to_resolution(values: np.ndarray, resolution: float | None) -> np.ndarray:
    """Round up to the resolution grid (inf stays inf); small float noise is absorbed."""
    if resolution is None:
        return values
    with np.errstate(invalid="ignore"):
        steps = np.ceil(values / resolution - 1e-9)
    return np.where(np.isfinite(values), np.round(steps * resolution, 9) + 0.0, values)


def _scan_bisect(
    collides_at: Callable[[np.ndarray], np.ndarray], upper: np.ndarray, search: SearchOptions
) -> np.ndarray:
    """Per row, the sup of the colliding gaps in [0, upper] (0 if none, inf if it still
    collides at ``search.cap_m`` when the row has no finite upper bound)."""
    top = np.where(np.isfinite(upper), np.minimum(upper, search.cap_m), search.cap_m)
    step = np.maximum(search.scan_step_m, top / search.max_scans)
    n_scan = int(math.ceil(float(np.max(top / step, initial=0.0)))) + 1
    last_hit = np.full(upper.shape, -1.0)
    for i in range(n_scan):
        d = np.minimum(i * step, top)
        last_hit = np.where(collides_at(d), d, last_hit)
    unbounded = ~np.isfinite(upper) & (last_hit >= top)
    lo = np.maximum(last_hit, 0.0)
    hi = np.minimum(lo + step, top)
    todo = (last_hit >= 0) & ~unbounded
    while todo.any() and (hi - lo)[todo].max() > search.bisect_tol_m:
        mid = 0.5 * (lo + hi)
        hit = collides_at(mid)
        lo = np.where(todo & hit, mid, lo)
        hi = np.where(todo & ~hit, mid, hi)
    out = np.where(todo, hi, 0.0)
    return np.where(unbounded, np.inf, out)


@dataclass(frozen=True)
class SearchOptions:
    """How AEB-variant boundaries are searched (driver-only ones are closed-form).

    The gaps from 0 to the driver-only boundary (or ``cap_m``) are scanned at
    max(``scan_step_m``, range / ``max_scans``), then each change of outcome between scan
    points is bisected to ``bisect_tol_m``.
    """

    cap_m: float = 200.0
    scan_step_m: float = 0.5
    max_scans: int = 64
    bisect_tol_m: float = 1e-3

    def region_search(self) -> RegionSearch:
        """The AEB settings for :func:`~hiyari.risk.cc.regions.cut_in_regions`, which scans
        ``max_scans`` points across each driver-only colliding interval instead."""
        return RegionSearch(cap_m=self.cap_m, aeb_tol_m=self.bisect_tol_m)


def cut_in_boundary(
    ve0_mps: np.ndarray,
    vo0_mps: np.ndarray,
    vy_mps: np.ndarray,
    params: CCParams = _DEFAULT,
    search: SearchOptions = SearchOptions(),
) -> np.ndarray:
    """Cut-in Preventable boundary dx0 (m) per scenario: the upper end of the colliding gaps
    (:func:`~hiyari.risk.cc.regions.cut_in_regions`); ``inf`` where every large gap collides.

    Inputs are assumed checked (Vo0 <= Ve0, Vy > 0 and feasible), as in the grid builders.
    """
    return cut_in_regions(ve0_mps, vo0_mps, vy_mps, params, search.region_search()).upper


def cut_out_boundary(
    ve0_mps: np.ndarray,
    vy_mps: np.ndarray,
    params: CCParams = _DEFAULT,
    search: SearchOptions = SearchOptions(),
) -> np.ndarray:
    """Cut-out Preventable boundary dx0_f (m) per (Ve0, Vy), clipped at 0 (the driver stops
    behind the lead's original position); ``inf`` where no gap up to the cap is Preventable."""
    ve0, vy = (np.asarray(a, dtype=float) for a in (ve0_mps, vy_mps))
    p = params
    driver_only = replace(p, aeb=False)
    zeros = np.zeros_like(ve0)
    at_zero = run_chunked(lambda *a: cut_out_setup(*a, driver_only), [ve0, vy, zeros], driver_only)
    driver = np.maximum(-at_zero.min_gap_m, 0.0)
    if not p.aeb:
        return driver

    def collides(d: np.ndarray) -> np.ndarray:
        return run_chunked(lambda *a: cut_out_setup(*a, p), [ve0, vy, d], p).collision

    return _scan_bisect(collides, driver, search)


def decel_boundary_gap(
    ve0_mps: np.ndarray,
    gx_max_g: np.ndarray,
    params: CCParams = _DEFAULT,
    search: SearchOptions = SearchOptions(),
) -> np.ndarray:
    """Smallest initial gap dx0 (m) at which the C&C driver avoids a lead braking at Gx_max."""
    ve0, gx = (np.asarray(a, dtype=float) for a in (ve0_mps, gx_max_g))
    p = params
    driver_only = replace(p, aeb=False)
    zeros = np.zeros_like(ve0)
    at_zero = run_chunked(lambda *a: decel_setup(*a, driver_only), [ve0, gx, zeros], driver_only)
    driver = np.maximum(-at_zero.min_gap_m, 0.0)
    if not p.aeb:
        return driver

    def collides(d: np.ndarray) -> np.ndarray:
        return run_chunked(lambda *a: decel_setup(*a, p), [ve0, gx, d], p).collision

    return _scan_bisect(collides, driver, search)


# ---------------------------------------------------------------- datasheets over grids


def _write_csv(path: Path, header: list[str], columns: list[np.ndarray], fmt: list[str]) -> Path:
    with atomic_path(path) as tmp, tmp.open("w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(header)
        cols = [
            [f.format(v) if np.isfinite(v) else str(v) for v in c.tolist()]
            if f != "bool"
            else [str(bool(v)).lower() for v in c.tolist()]
            for c, f in zip(columns, fmt, strict=True)
        ]
        writer.writerows(zip(*cols, strict=True))
    return path


def floor_to_resolution(values: np.ndarray, resolution: float | None) -> np.ndarray:
    """Round down to the resolution grid (nan and inf stay); small float noise is absorbed."""
    if resolution is None:
        return values
    with np.errstate(invalid="ignore"):
        steps = np.floor(values / resolution + 1e-9)
    return np.where(np.isfinite(values), np.round(steps * resolution, 9) + 0.0, values)


def format_regions(regions: Regions, i: int) -> str:
    """``"lo:hi;lo:hi"`` of scenario ``i`` (empty when no gap collides)."""
    return ";".join(f"{lo:.3f}:{hi:.3f}" for lo, hi in regions.intervals(i))


@dataclass(frozen=True)
class CutInDatasheet:
    """Cut-in regions and boundaries on a grid: one row per feasible (Ve0, Vo0, Vy).

    ``regions``: the colliding dx0 intervals, exact; ``boundary_dx0_m``: their upper end
    rounded up to ``resolution_m`` (the smallest Preventable gap on that grid above them).
    """

    ve0_kmh: np.ndarray
    vo0_kmh: np.ndarray
    vy_mps: np.ndarray
    boundary_dx0_m: np.ndarray
    resolution_m: float | None
    params: CCParams
    regions: Regions

    @property
    def dv_kmh(self) -> np.ndarray:
        """Relative speed Ve0 - Vo0 (km/h)."""
        return np.round(self.ve0_kmh - self.vo0_kmh, 9)

    def grid_regions(self) -> Regions:
        """The colliding intervals widened to ``resolution_m`` (lo down, hi up): the grid
        gaps strictly inside collide, the ends are the nearest Preventable grid gaps."""
        return Regions(
            floor_to_resolution(self.regions.lo, self.resolution_m),
            ceil_to_resolution(self.regions.hi, self.resolution_m),
        )

    def write_csv(self, path: str | Path) -> Path:
        """One row per scenario: ``boundary_dx0_m`` (``inf`` = no Preventable gap above the
        colliding ones) and ``colliding_dx0_m``, every colliding interval as ``lo:hi``
        separated by ``;`` (exact; empty = no gap collides; lo = 0 includes dx0 = 0)."""
        path = Path(path)
        columns = [self.ve0_kmh, self.vo0_kmh, self.dv_kmh, self.vy_mps, self.boundary_dx0_m]
        fmt = ["{:g}", "{:g}", "{:g}", "{:g}", "{:.3f}"]
        with atomic_path(path) as tmp, tmp.open("w", newline="") as fh:
            writer = csv.writer(fh)
            writer.writerow(
                ["ve0_kmh", "vo0_kmh", "dv_kmh", "vy_mps", "boundary_dx0_m", "colliding_dx0_m"]
            )
            cells = [
                [f.format(v) if np.isfinite(v) else str(v) for v in c.tolist()]
                for c, f in zip(columns, fmt, strict=True)
            ]
            for i, row in enumerate(zip(*cells, strict=True)):
                writer.writerow([*row, format_regions(self.regions, i)])
        return path


def cut_in_grid(
    ve0_kmh: Grid, dv_kmh: Grid, vy_mps: Grid, params: CCParams = _DEFAULT
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Feasible (Ve0, Vo0, Vy) of a grid, km/h and m/s: Vo0 = Ve0 - dv > 0 and Vy at most
    Vo0 x tan(max_heading_deg); other combinations are dropped."""
    check_speed_grid(ve0_kmh, "Ve0")
    check_speed_grid(dv_kmh, "Ve0 - Vo0")
    check_vy_grid(vy_mps, "Vy", params.lane_width_m)
    ve, dv, vy = np.meshgrid(ve0_kmh.values(), dv_kmh.values(), vy_mps.values(), indexing="ij")
    vo = np.round(ve - dv, 9)
    tan = math.tan(math.radians(params.max_heading_deg))
    keep = (vo > 0) & (vy <= vo / KMH_PER_MPS * tan + 1e-9)
    if not keep.any():
        raise HiyariError(
            f"cut-in grid Ve0 {ve0_kmh}, dv {dv_kmh}, Vy {vy_mps}: no feasible scenario "
            "(Vo0 must be > 0 and Vy <= Vo0 x tan(max_heading))"
        )
    return ve[keep], vo[keep], vy[keep]


def cut_in_datasheet(
    ve0_kmh: Grid = Grid(10, 130, 1),
    dv_kmh: Grid = Grid(0, 60, 1),
    vy_mps: Grid = Grid(0.1, 3.0, 0.1),
    params: CCParams = _DEFAULT,
    resolution_m: float | None = 0.1,
    search: SearchOptions = SearchOptions(),
) -> CutInDatasheet:
    """Cut-in regions and boundaries over a grid. ``resolution_m`` rounds each boundary up to
    that grid (the smallest Preventable gap on it); None keeps the exact value."""
    ve, vo, vy = cut_in_grid(ve0_kmh, dv_kmh, vy_mps, params)
    regions = cut_in_regions(ve / KMH_PER_MPS, vo / KMH_PER_MPS, vy, params, search.region_search())
    boundary = ceil_to_resolution(regions.upper, resolution_m)
    return CutInDatasheet(ve, vo, vy, boundary, resolution_m, params, regions)


@dataclass(frozen=True)
class CutOutDatasheet:
    """Cut-out boundaries on a (Ve0, Vy) grid, with the Annex G exclusion limit."""

    ve0_kmh: np.ndarray
    vy_mps: np.ndarray
    boundary_dx0_f_m: np.ndarray
    lead_clear_dx0_f_m: np.ndarray
    resolution_m: float | None
    params: CCParams

    def write_csv(self, path: str | Path) -> Path:
        """One row per (Ve0, Vy). ``lead_clear_dx0_f_m``: below it the lead itself hits the
        stopped vehicle (excluded by Annex G)."""
        return _write_csv(
            Path(path),
            ["ve0_kmh", "vo0_kmh", "vy_mps", "dx0_m", "boundary_dx0_f_m", "lead_clear_dx0_f_m"],
            [
                self.ve0_kmh,
                self.ve0_kmh,
                self.vy_mps,
                self.params.thw_s * self.ve0_kmh / KMH_PER_MPS,
                self.boundary_dx0_f_m,
                self.lead_clear_dx0_f_m,
            ],
            ["{:g}", "{:g}", "{:g}", "{:.3f}", "{:.3f}", "{:.3f}"],
        )


def cut_out_datasheet(
    ve0_kmh: Grid = Grid(10, 130, 1),
    vy_mps: Grid = Grid(0.1, 3.0, 0.1),
    params: CCParams = _DEFAULT,
    resolution_m: float | None = 0.1,
    search: SearchOptions = SearchOptions(),
) -> CutOutDatasheet:
    """Cut-out boundaries over a grid (infeasible Vy at low speed dropped)."""
    check_speed_grid(ve0_kmh, "Ve0")
    check_vy_grid(vy_mps, "Vy", params.lane_width_m)
    ve, vy = np.meshgrid(ve0_kmh.values(), vy_mps.values(), indexing="ij")
    tan = math.tan(math.radians(params.max_heading_deg))
    keep = (ve > 0) & (vy <= ve / KMH_PER_MPS * tan + 1e-9)
    if not keep.any():
        raise HiyariError(f"cut-out grid Ve0 {ve0_kmh}, Vy {vy_mps}: no feasible scenario")
    ve, vy = ve[keep], vy[keep]
    b = cut_out_boundary(ve / KMH_PER_MPS, vy, params, search)
    clear = cut_out_lead_clear_gap(ve / KMH_PER_MPS, vy, params)
    return CutOutDatasheet(ve, vy, ceil_to_resolution(b, resolution_m), clear, resolution_m, params)


@dataclass(frozen=True)
class DecelDatasheet:
    """Deceleration scenario on a (Ve0, Gx_max) grid at ``thw_s`` following."""

    ve0_kmh: np.ndarray
    gx_max_g: np.ndarray
    preventable: np.ndarray
    min_gap_m: np.ndarray
    boundary_dx0_m: np.ndarray
    params: CCParams

    def write_csv(self, path: str | Path) -> Path:
        """One row per (Ve0, Gx_max); ``boundary_dx0_m`` is the smallest Preventable gap."""
        dx0 = self.params.thw_s * self.ve0_kmh / KMH_PER_MPS
        return _write_csv(
            Path(path),
            [
                "ve0_kmh",
                "vo0_kmh",
                "gx_max_g",
                "dx0_m",
                "preventable",
                "min_gap_m",
                "boundary_dx0_m",
            ],
            [
                self.ve0_kmh,
                self.ve0_kmh,
                self.gx_max_g,
                dx0,
                self.preventable,
                self.min_gap_m,
                self.boundary_dx0_m,
            ],
            ["{:g}", "{:g}", "{:g}", "{:.3f}", "bool", "{:.3f}", "{:.3f}"],
        )


def decel_datasheet(
    ve0_kmh: Grid = Grid(10, 130, 1),
    gx_max_g: Grid = Grid(0.01, 1.0, 0.01),
    params: CCParams = _DEFAULT,
    search: SearchOptions = SearchOptions(),
) -> DecelDatasheet:
    """Deceleration verdicts over a grid of (Ve0, Gx_max)."""
    check_speed_grid(ve0_kmh, "Ve0")
    if gx_max_g.start <= 0 or gx_max_g.stop > params.road_mu:
        raise HiyariError(
            f"Gx_max {gx_max_g}: must lie in (0, {params.road_mu:g}] g (road friction μ)"
        )
    ve, gx = np.meshgrid(ve0_kmh.values(), gx_max_g.values(), indexing="ij")
    keep = ve > 0
    ve, gx = ve[keep], gx[keep]
    v = ve / KMH_PER_MPS
    result = run_chunked(lambda *a: decel_setup(*a, params), [v, gx, params.thw_s * v], params)
    boundary = decel_boundary_gap(v, gx, params, search)
    return DecelDatasheet(ve, gx, ~result.collision, result.min_gap_m, boundary, params)
