"""RandomRouteAction on the Euro NCAP X intersection: the actor drives on through the junction
to a destination drawn along the roads ahead, the same one in every run."""

from __future__ import annotations

from pathlib import Path

from openscenario_files import (
    SHARED,
    run_scenario,
    scenario_xml,
    story,
    teleport_speed,
    time_condition,
    write,
)

XODR = SHARED / "ncap" / "OpenDRIVE" / "NCAP" / "X-Intersection_NCAP.xodr"


def _end(tmp_path: Path, k: int) -> tuple[str, float, float]:
    init = teleport_speed("Ego", -1, 20, 5) + teleport_speed("Car", -1, 200, 10)
    stories = story(
        "Car",
        "<RoutingAction><RandomRouteAction/></RoutingAction>",
        time_condition(0.0, "go", "none"),
    )
    text = scenario_xml({"Ego": "", "Car": ""}, init, stories, road=XODR)
    engine, _ = run_scenario(write(tmp_path / f"r{k}.xosc", text), tmp_path, until=12.0)
    car = engine.actors["Car"]
    p = engine.road_pose("Car")
    return p.road, round(car.x, 9), round(car.y, 9)


def test_random_route_leaves_the_junction_the_same_way_each_run(tmp_path: Path) -> None:
    first, again = _end(tmp_path, 0), _end(tmp_path, 1)
    assert first == again
    # 120 m on from s = 200 on the west arm: through the junction onto another arm
    assert first[0] in ("1", "2", "3")
