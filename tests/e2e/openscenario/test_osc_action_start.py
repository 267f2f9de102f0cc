"""One start rule for every action (OpenSCENARIO 1.3, 7.6.1 and 8.4: a trigger is evaluated at
the discrete times t_d of the simulation; when an Event's start trigger is true the Event, and
with it each of its Actions, enters runningState): an action starts at the step time t_d its
trigger is true on, its dynamics timed from t_d, and the state of the next step (t_d + dt) is
the first that shows its motion. A SpeedAction, a LaneOffsetAction and a LaneChangeAction on
the same SimulationTimeCondition start in the same step; the links of chains on endTransition
start on the first step at or after the previous link's end, whatever the action kind (ALKS
4_1_2's swerves chain LaneOffsetActions this way)."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from openscenario_files import (
    run_scenario,
    scenario_xml,
    story,
    teleport_speed,
    time_condition,
    write,
)

#: the lane offset's duration pi sqrt(d / (2 a)) for d = 0.5 m, a = 2 m/s^2; the speed and lane
#: changes take as long, so that the three chains end together
D = math.pi * math.sqrt(0.5 / 4.0)


def _offset(v: float) -> str:
    return f"""<LateralAction><LaneOffsetAction continuous="false"><LaneOffsetActionDynamics maxLateralAcc="2.0" dynamicsShape="sinusoidal"/>
<LaneOffsetTarget><AbsoluteTargetLaneOffset value="{v}"/></LaneOffsetTarget></LaneOffsetAction></LateralAction>"""


def _speed(v: float) -> str:
    return f"""<LongitudinalAction><SpeedAction><SpeedActionDynamics dynamicsShape="linear" dynamicsDimension="time" value="{D!r}"/>
<SpeedActionTarget><AbsoluteTargetSpeed value="{v}"/></SpeedActionTarget></SpeedAction></LongitudinalAction>"""


def _change(lane: int) -> str:
    return f"""<LateralAction><LaneChangeAction><LaneChangeActionDynamics dynamicsShape="linear" dynamicsDimension="time" value="{D!r}"/>
<LaneChangeTarget><AbsoluteTargetLane value="{lane}"/></LaneChangeTarget></LaneChangeAction></LateralAction>"""


def _ended(ref: str) -> str:
    return f"""<Condition name="after{ref}" delay="0" conditionEdge="rising"><ByValueCondition>
<StoryboardElementStateCondition storyboardElementType="action" storyboardElementRef="{ref}" state="endTransition"/>
</ByValueCondition></Condition>"""


def test_speed_lane_offset_and_lane_change_start_in_the_same_step(tmp_path: Path) -> None:
    init = "".join(
        teleport_speed(n, lane, s, 10.0)
        for n, lane, s in (("Ego", -4, 20), ("A", -3, 60), ("B", -2, 60), ("C", -3, 100))
    )
    stories = "".join(
        story(n, first, time_condition(1.0, f"go{n}"), f"S{n}")
        + story(n, second, _ended(f"S{n}Action"), f"T{n}")
        for n, first, second in (
            ("A", _speed(15.0), _speed(10.0)),
            ("B", _offset(0.5), _offset(0.0)),
            ("C", _change(-2), _change(-3)),
        )
    )
    xml = scenario_xml({n: "" for n in ("Ego", "A", "B", "C")}, init, stories)
    starts: dict[str, list[float]] = {n: [] for n in "ABC"}
    state: dict[float, tuple[float, float, float]] = {}

    def on_step(sim, world, report, engine) -> None:  # noqa: ANN001
        a, b, c = (engine.actors[n] for n in "ABC")
        for n, tr in (("A", a.long), ("B", b.lat), ("C", c.lat)):
            t0 = None if tr is None else (tr.t0 if n == "A" else tr.t_start)
            if t0 is not None and round(t0, 9) not in starts[n]:
                starts[n].append(round(t0, 9))
        state[round(report.time + 0.05, 2)] = (a.v, b.t, c.t)  # the engine is a step ahead

    run_scenario(write(tmp_path / "start.xosc", xml), tmp_path, until=4.0, on_step=on_step)
    # started on the state at 1.0 s; the links end at 1 + D = 2.11 s, inside the step to
    # 2.15 s: the second links start on the state at 2.15 s
    assert starts == {"A": [1.0, 2.15], "B": [1.0, 2.15], "C": [1.0, 2.15]}
    (v0, tb0, tc0), (v1, tb1, tc1) = state[1.0], state[1.05]
    x = 0.05 / D  # the first step's share of the transitions
    assert v1 == pytest.approx(v0 + 5.0 * x, abs=1e-12)
    assert tb1 - tb0 == pytest.approx(0.5 * 0.5 * (1 - math.cos(math.pi * x)), abs=1e-12)
    change = state[2.15][2] - tc0  # the whole lateral shift: the change ended by 2.15 s
    assert tc1 - tc0 == pytest.approx(change * x, abs=1e-12)
