"""The fuzz suite's element seeds (openscenario_files.element_seeds) run to their stop triggers
unmutated, on SUMO, with the motion and values the standard gives: the fuzz suite's mutants
start from files that work."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from openscenario_files import element_seeds, run_scenario

DT = 0.05


@pytest.fixture(scope="module")
def seeds(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("element_seeds")
    return {p.stem: p for p in element_seeds(folder)}


def _track(seed: Path, folder: Path, until: float) -> tuple:
    """Run ``seed``; (engine, report, the SUMO times and the car's reference point x, y after
    each step: the state the conditions of the next update see)."""
    t, xy = [], []

    def on_step(sim, world, report, engine) -> None:  # noqa: ANN001
        car = engine.actors["Car"]
        t.append(sim.time)
        xy.append((car.x, car.y))

    engine, report = run_scenario(seed, folder, until=until, dt=DT, on_step=on_step)
    return engine, report, np.array(t), np.array(xy)


@pytest.mark.parametrize(
    "name",
    [
        "speed_profile",
        "lateral_distance",
        "random_route",
        "clothoid_trajectory",
        "synchronize",
        "global_actions",
    ],
)
def test_seeds_stopped_by_time_run_to_it(seeds: dict[str, Path], name: str, tmp_path: Path):
    _, report = run_scenario(seeds[name], tmp_path, until=6.0, dt=DT)
    assert report.finished and report.time == pytest.approx(4.0)


def test_nurbs_seed_follows_its_timed_curve_to_the_end(seeds: dict[str, Path], tmp_path: Path):
    """Started at 0.5 s, timing relative: the NURBS ends at its last control point's time
    (6 s later) on that point, where the action completes and the stop trigger fires. At
    u = 1 the quadratic basis on knots 0 0 0 1 2 2 2 is (0, 1/2, 1/2, 0); with weights
    (1, 1, 2, 1) the curve is at ((75 + 2 * 95) / 3, (-8 - 2 * 4.5) / 3) at time
    (2 + 2 * 4) / 3 s after the start."""
    _, report, t, xy = _track(seeds["nurbs_trajectory"], tmp_path, until=10.0)
    assert report.finished and report.time == pytest.approx(6.5)
    assert xy[-1] == pytest.approx([115.0, -4.5], abs=1e-6)
    when = 0.5 + 10.0 / 3.0
    at = [np.interp(when, t, xy[:, k]) for k in (0, 1)]
    assert at == pytest.approx([265.0 / 3.0, -17.0 / 3.0], abs=0.05)


def test_geo_seed_places_and_stops_by_latitude_and_longitude(
    seeds: dict[str, Path], tmp_path: Path
):
    """The car starts at map (60, -8) (its latitude and longitude through the road's
    geoReference and header offset) at 10 m/s; the stop trigger (within 97.75 m of map
    (200, -8) along the road) first holds at the step after x passes 102.25 m: 4.25 s."""
    _, report, t, xy = _track(seeds["geo_position"], tmp_path, until=8.0)
    assert report.finished and report.time == pytest.approx(4.25)
    assert xy[0] == pytest.approx([60.0 + 10.0 * t[0], -8.0], abs=1e-3)
    assert xy[-1] == pytest.approx([102.5, -8.0], abs=1e-3)


def test_variables_seed_sets_modifies_and_stops_on_its_values(
    seeds: dict[str, Path], tmp_path: Path
):
    """Arm at 0.5 s; a condition sees a value from the step after the action that set it, so
    Tick runs at 0.55, 0.60 and 0.65 s (its three executions, Count 3), Double at 0.70 s
    (Count 6, Gain 2 * 1.5 = 3, the car decelerating at 4 m/s^2) and the stop trigger holds
    at 0.75 s."""
    engine, report, _, _ = _track(seeds["variables"], tmp_path, until=3.0)
    assert report.finished and report.time == pytest.approx(0.75)
    text = {n: engine.values.get(k, n, "").text for k, n in
            [("variable", "Count"), ("variable", "Armed"), ("variable", "Label"),
             ("parameter", "Gain")]}  # fmt: skip
    assert float(text["Count"]) == 6.0 and float(text["Gain"]) == 3.0
    assert (text["Armed"], text["Label"]) == ("true", "armed")
    started = [
        (round(t, 2), n)
        for t, kind, n, tr in engine.tree.log
        if kind == "event" and tr == "startTransition" and n != "Init"
    ]
    assert started == [(0.5, "Arm"), (0.55, "Tick"), (0.6, "Tick"), (0.65, "Tick"),
                       (0.7, "Double")]  # fmt: skip
    assert engine.actors["Car"].v == pytest.approx(10.0 - 4.0 * DT)
