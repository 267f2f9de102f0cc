"""C&C driver evaluator and Preventable-boundary datasheets: speed against a stepping loop.

Measured in this run, on one core, as CPU time of this process (time.process_time), so that
other load on a shared machine does not skew the ratio; wall times are printed beside:
  loop        - the straightforward evaluation: one cut-in scenario at a time, 0.01 s steps,
                judgements taken online (hiyari.risk.cc.reference_sim);
  vectorised  - the closed-form evaluator (hiyari.risk.cc.evaluator) on arrays of scenarios;
both on cut-in scenarios drawn from the Annex G ranges extended to 130 km/h. Prints scenario
evaluations per second of both and their ratio (target >= 1000 x), the verdict agreement on
the loop's sample, then the time of the full cut-in datasheet: every (Ve0, Vo0, Vy) on a
1 km/h x 1 km/h x 0.1 m/s grid (Ve0 10-130 km/h, Ve0 - Vo0 0-60 km/h, Vy 0.1-3.0 m/s) with its
boundary dx0 at 0.1 m (target < 10 s), next to what bisecting each boundary with the loop
would take at the measured loop rate. Also times the cut-out and deceleration datasheets and
the AEB variant. Run: .venv/bin/python benchmarks/boundary.py
"""

from __future__ import annotations

import argparse
import math
import time
from collections.abc import Callable

import numpy as np

from hiyari.risk.cc.boundary import Grid, cut_in_datasheet, cut_out_datasheet, decel_datasheet
from hiyari.risk.cc.evaluator import evaluate_cut_in
from hiyari.risk.cc.model import CCParams
from hiyari.risk.cc.reference_sim import simulate_cut_in

KMH = 1 / 3.6


def scenarios(n: int, seed: int) -> tuple[np.ndarray, ...]:
    """Cut-in scenarios: Ve0 20-130 km/h, Ve0 - Vo0 0-50 km/h, feasible Vy 0.1-3 m/s,
    dx0 0-60 m (Annex G)."""
    rng = np.random.default_rng(seed)
    ve = rng.uniform(20, 130, n) * KMH
    vo = np.maximum(ve - rng.uniform(0, 50, n) * KMH, 5 * KMH)
    vy = np.minimum(rng.uniform(0.1, 3.0, n), vo)
    dx0 = rng.uniform(0, 60, n)
    return ve, vo, dx0, vy


def best_of(fn: Callable[[], object], repeats: int) -> tuple[float, float]:
    """Shortest CPU time and shortest wall time of ``fn()`` over ``repeats`` calls, s."""
    cpu = wall = math.inf
    for _ in range(repeats):
        t, w = time.process_time(), time.perf_counter()
        fn()
        cpu = min(cpu, time.process_time() - t)
        wall = min(wall, time.perf_counter() - w)
    return cpu, wall


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--loop-scenarios", type=int, default=400)
    ap.add_argument("--vector-scenarios", type=int, default=1_000_000)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    p = CCParams()

    ve, vo, dx0, vy = scenarios(args.loop_scenarios, args.seed)
    loop: list = []
    loop_s, loop_wall = best_of(
        lambda: loop.extend(
            simulate_cut_in(ve[i], vo[i], dx0[i], vy[i], p) for i in range(ve.size)
        ),
        1,
    )
    loop_rate = ve.size / loop_s
    closed = evaluate_cut_in(ve, vo, dx0, vy, p)
    clear = np.abs(closed.min_gap_m) > 0.3  # verdicts a 0.01 s step cannot flip
    agree = np.mean([s.collision == c for s, c in zip(loop, closed.collision, strict=True)])
    agree_clear = np.mean(
        [s.collision == c for s, c, k in zip(loop, closed.collision, clear, strict=True) if k]
    )

    big = scenarios(args.vector_scenarios, args.seed + 1)
    vec_s, vec_wall = best_of(lambda: evaluate_cut_in(*big, p), 3)
    vec_rate = big[0].size / vec_s
    print("cut-in scenario evaluations, one core (CPU time)")
    print(
        f"  loop (0.01 s steps)  {loop_rate:12,.0f} /s   ({ve.size} scenarios, "
        f"{loop_s:.2f} s CPU, {loop_wall:.2f} s wall)"
    )
    print(
        f"  vectorised (exact)   {vec_rate:12,.0f} /s   ({big[0].size:,} scenarios, "
        f"{vec_s:.2f} s CPU, {vec_wall:.2f} s wall)"
    )
    print(f"  ratio                {vec_rate / loop_rate:12,.0f} x   (target >= 1000 x)")
    print(
        f"  same verdict as the loop: {100 * agree:.1f} % of its {ve.size} scenarios, "
        f"{100 * agree_clear:.1f} % where |min gap| > 0.3 m"
    )

    grid = (Grid(10, 130, 1), Grid(0, 60, 1), Grid(0.1, 3.0, 0.1))
    sheet = cut_in_datasheet(*grid, params=p, resolution_m=0.1)  # warm-up
    full_s, full_wall = best_of(lambda: cut_in_datasheet(*grid, params=p, resolution_m=0.1), 3)
    rows = sheet.ve0_kmh.size
    # a boundary to 0.1 m within 0-200 m by bisection takes ceil(log2(2000)) = 11 evaluations
    loop_estimate = rows * 11 / loop_rate
    print(
        "\nfull cut-in datasheet: Ve0 10-130 km/h x Vo0 (1 km/h, Ve0 - Vo0 0-60) x Vy 0.1-3.0 m/s"
    )
    print(f"  {rows:,} feasible (Ve0, Vo0, Vy), boundary dx0 at 0.1 m")
    print(f"  closed form          {full_s:8.3f} s CPU, {full_wall:.3f} s wall   (target < 10 s)")
    print(f"  loop + bisection     {loop_estimate:8.0f} s   (estimate: 11 loop runs per boundary)")
    print(
        f"  no Preventable gap at {np.isinf(sheet.boundary_dx0_m).sum():,} of them (Ve0 - Vo0 >= 53 km/h)"
    )

    print("\nother datasheets (Ve0 10-130 km/h at 1 km/h)")
    vy_grid, gx_grid = Grid(0.1, 3.0, 0.1), Grid(0.01, 1.0, 0.01)
    for name, fn in (
        ("cut-out, Vy 0.1-3.0 m/s at 0.1", lambda q: cut_out_datasheet(grid[0], vy_grid, q)),
        ("deceleration, Gx 0.01-1.0 g at 0.01", lambda q: decel_datasheet(grid[0], gx_grid, q)),
        ("cut-in with AEB (search)", lambda q: cut_in_datasheet(*grid, params=q)),
    ):
        for q in (p, CCParams(aeb=True)):
            if "AEB" in name and not q.aeb:
                continue
            cpu, wall = best_of(lambda fn=fn, q=q: fn(q), 1)
            kind = "AEB" if q.aeb else "driver"
            print(f"  {name:38s} {kind:6s} {cpu:7.2f} s CPU, {wall:6.2f} s wall")


if __name__ == "__main__":
    main()
