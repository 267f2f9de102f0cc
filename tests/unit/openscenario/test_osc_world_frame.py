"""coordinateSystem="world" on distance conditions (OpenSCENARIO 1.3): read (it used to raise
ValueError), and measured along the world's x (longitudinal) and y (lateral) axes, euclidean
in the x-y plane; hand-computed against the entity frame of the same pair."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from openscenario_files import scenario_xml, teleport_speed, write

from hiyari.bridge.openscenario.engine.kernels import measures as M
from hiyari.bridge.openscenario.model.conditions import CoordinateSystem
from hiyari.bridge.openscenario.xosc.reader import read_scenario


def _entity(cx: float, cy: float, h: float, v: float) -> tuple:
    """measures.entity_scalars of a 5 x 2 m box centred at (cx, cy) heading ``h``, its
    reference point 1.4 m behind the centre."""
    c, s = math.cos(h), math.sin(h)
    return (cx, cy, cx - 1.4 * c, cy - 1.4 * s, h, c, s, 5.0, 2.0, v, 0.0, 0.0, 0.0, 1.0)


# A heads north (+y) at 10 m/s centred at the origin (reference point (0, -1.4)); B stands
# heading east (+x) centred at (30, 40) (reference point (28.6, 40)).
A = _entity(0.0, 0.0, math.pi / 2, 10.0)
B = _entity(30.0, 40.0, 0.0, 0.0)
W, E = M.WORLD_FRAME, M.ENTITY_FRAME


@pytest.mark.parametrize(
    ("fs", "dtype", "world", "entity"),
    [
        (False, 1, 28.6, 41.4),  # reference points: |dx| = 28.6, |dy| = 41.4 (A's axis is y)
        (False, 2, 41.4, 28.6),
        (False, 0, math.hypot(28.6, 41.4), math.hypot(28.6, 41.4)),
        # boxes along the world axes: A spans x +-1, y +-2.5; B x +-2.5, y +-1
        (True, 1, 30.0 - 1.0 - 2.5, 40.0 - 2.5 - 1.0),
        (True, 2, 40.0 - 2.5 - 1.0, 30.0 - 1.0 - 2.5),
    ],
)
def test_relative_distance_in_the_world_frame(
    fs: bool, dtype: int, world: float, entity: float
) -> None:
    assert M.pair_measure(M.REL_DIST, fs, dtype, W, A, B) == pytest.approx(world, abs=1e-9)
    assert M.pair_measure(M.REL_DIST, fs, dtype, E, A, B) == pytest.approx(entity, abs=1e-9)


def test_ttc_closes_along_the_world_axis() -> None:
    """A closes on B at 10 m/s along y only: along x never (inf); along y 41.4 m in 4.14 s."""
    assert M.pair_measure(M.TTC, False, 1, W, A, B) == math.inf
    assert M.pair_measure(M.TTC, False, 2, W, A, B) == pytest.approx(4.14, abs=1e-9)


@pytest.mark.parametrize(
    ("fs", "dtype", "expected"),
    [(False, 1, 10.0), (False, 2, 21.4), (True, 1, 10.0 - 1.0), (True, 2, 20.0 - 2.5)],
)
def test_distance_to_a_point_in_the_world_frame(fs: bool, dtype: int, expected: float) -> None:
    """Point (10, 20): from A's reference point (0, -1.4), or from its box (x +-1, y +-2.5)."""
    point = (10.0, 20.0, math.nan, math.nan)
    got = M.point_measure(M.DISTANCE, fs, dtype, W, A, point)
    assert got == pytest.approx(expected, abs=1e-9)


def test_reader_accepts_world(tmp_path: Path) -> None:
    cond = """<ConditionGroup><Condition name="near" delay="0" conditionEdge="none"><ByEntityCondition>
<TriggeringEntities triggeringEntitiesRule="any"><EntityRef entityRef="Ego"/></TriggeringEntities>
<EntityCondition><RelativeDistanceCondition entityRef="Car" relativeDistanceType="longitudinal"
 value="5" freespace="false" rule="lessThan" coordinateSystem="world"/></EntityCondition>
</ByEntityCondition></Condition></ConditionGroup>"""
    init = teleport_speed("Ego", -4, 5.0, 10.0) + teleport_speed("Car", -4, 50.0, 10.0)
    xml = scenario_xml({"Ego": "", "Car": ""}, init, stop=cond)
    sc = read_scenario(write(tmp_path / "world.xosc", xml))
    body = sc.storyboard.stop_trigger[0][0].body.body
    assert body.coordinate_system == CoordinateSystem.WORLD
