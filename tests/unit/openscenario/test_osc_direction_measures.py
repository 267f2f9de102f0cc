"""The directional speed and acceleration measures of the trigger kernel, by hand: a car
crossing another at right angles, a yaw rate across the +-pi wrap."""

from __future__ import annotations

import math

import pytest

from hiyari.bridge.openscenario.engine.kernels import measures as M


def _entity(h: float, v: float, acc: float = 0.0) -> tuple:
    """An entity's scalars (measures.E_X ...) at the origin with heading ``h``, speed ``v``."""
    fields = [0.0] * M.N_FIELDS
    fields[M.E_H], fields[M.E_COS], fields[M.E_SIN] = h, math.cos(h), math.sin(h)
    fields[M.E_V], fields[M.E_ACC] = v, acc
    return tuple(fields)


def test_relative_velocity_in_the_triggering_entitys_axes() -> None:
    east, north = _entity(0.0, 10.0, -2.0), _entity(math.pi / 2, 5.0)
    # (10, 0) - (0, 5) = (10, -5) in the east-heading car's axes; speeds differ by 5
    assert M.single_measure(M.REL_SPEED, M.DIR_LON, east, north) == pytest.approx(10.0)
    assert M.single_measure(M.REL_SPEED, M.DIR_LAT, east, north) == pytest.approx(-5.0)
    assert M.single_measure(M.REL_SPEED, M.DIR_VERT, east, north) == 0.0
    assert M.single_measure(M.REL_SPEED, M.DIR_NONE, east, north) == 5.0
    # the north-heading one's: (0, 5) - (10, 0) = (-10, 5), 5 ahead (north), 10 left (west)
    assert M.single_measure(M.REL_SPEED, M.DIR_LON, north, east) == pytest.approx(5.0)
    assert M.single_measure(M.REL_SPEED, M.DIR_LAT, north, east) == pytest.approx(10.0)
    # own velocity is along the heading: lateral and vertical 0
    assert M.single_measure(M.SPEED, M.DIR_LAT, east, north) == 0.0
    assert M.single_measure(M.SPEED, M.DIR_LON, east, north) == 10.0
    assert M.single_measure(M.ACCEL, M.DIR_LON, east, north) == -2.0
    assert M.single_measure(M.ACCEL, M.DIR_VERT, east, north) == 0.0


def test_lateral_acceleration_is_speed_times_yaw_rate() -> None:
    first = M.lateral_accel_measure(0.0, True, 0.1, 10.0, math.nan, math.nan)
    assert math.isnan(first[0]) and first[1:] == (0.1, 0.0)
    m, h, t = M.lateral_accel_measure(0.05, True, 0.2, 10.0, 0.1, 0.0)
    assert (m, h, t) == (pytest.approx(10.0 * 0.1 / 0.05), 0.2, 0.05)
    # turning left across +-pi: 3.1 -> -3.1 is +0.0832 rad, not -6.2
    m, _, _ = M.lateral_accel_measure(1.0, True, -3.1, 10.0, 3.1, 0.9)
    assert m == pytest.approx(10.0 * (2 * math.pi - 6.2) / 0.1)
    assert all(math.isnan(x) for x in M.lateral_accel_measure(1.0, False, 0.0, 1.0, 0.0, 0.9))


def test_total_speed_and_acceleration_are_magnitudes() -> None:
    reversing, other = _entity(0.0, -3.0, -2.0), _entity(0.0, 1.0)
    assert M.single_measure(M.SPEED, M.DIR_NONE, reversing, other) == 3.0
    assert M.single_measure(M.SPEED, M.DIR_LON, reversing, other) == -3.0
    # braking at 3 m/s^2 while turning left with 4 m/s^2: |a| = 5
    assert M.total_accel_measure(-3.0, 4.0) == 5.0
    assert math.isnan(M.total_accel_measure(-3.0, math.nan))
