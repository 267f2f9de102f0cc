"""Transition shapes and durations (OpenSCENARIO TransitionDynamics).

A shape maps progress x in [0, 1] to the fraction of the change done: step 1, linear x,
cubic 3x^2 - 2x^3, sinusoidal (1 - cos(pi x)) / 2. With dimension "rate" the value is the
peak rate of change (for linear the constant rate), so the duration is the change times the
shape's peak slope (1, 1.5, pi / 2) over the rate.
"""

from __future__ import annotations

import math

from hiyari.bridge.openscenario.model.actions import Dimension, Shape
from hiyari.errors import HiyariError
from hiyari.jit import njit

PEAK_SLOPE = {Shape.STEP: 0.0, Shape.LINEAR: 1.0, Shape.CUBIC: 1.5, Shape.SINUSOIDAL: math.pi / 2}


#: Codes of the shapes in compiled code.
STEP, LINEAR, CUBIC, SINUSOIDAL = 0, 1, 2, 3
SHAPE_CODE = {
    Shape.STEP: STEP,
    Shape.LINEAR: LINEAR,
    Shape.CUBIC: CUBIC,
    Shape.SINUSOIDAL: SINUSOIDAL,
}


@njit(cache=True)
def shape_progress(code: int, x: float) -> float:
    """Fraction of the change done at progress ``x`` (clamped to [0, 1]) for shape ``code``."""
    x = min(1.0, max(0.0, x))
    if code == STEP:
        return 1.0
    if code == LINEAR:
        return x
    if code == CUBIC:
        return x * x * (3.0 - 2.0 * x)
    return 0.5 * (1.0 - math.cos(math.pi * x))


def progress(shape: Shape, x: float) -> float:
    """Fraction of the change done at progress ``x`` (clamped to [0, 1])."""
    return shape_progress(SHAPE_CODE[shape], x)


def span(shape: Shape, dimension: Dimension, value: float, change: float, where: str) -> float:
    """Length of a transition: seconds (time, rate) or metres travelled (distance).

    ``change`` is the size of the change (m/s for speed, m for lateral position)."""
    if shape == Shape.STEP or abs(change) < 1e-12:
        return 0.0
    if value < 0 or (dimension == Dimension.RATE and value == 0):
        raise HiyariError(f"{where}: transition {dimension} value must be positive, got {value:g}")
    if dimension == Dimension.RATE:
        return abs(change) * PEAK_SLOPE[shape] / value
    return value


def lateral_duration(shape: Shape, max_acc: float, change: float) -> float:
    """Duration (s) of a lateral shift of ``change`` m whose peak acceleration is ``max_acc``:
    sinusoidal pi sqrt(d / (2 a)), cubic sqrt(6 d / a); step 0."""
    d = abs(change)
    if shape == Shape.STEP or d < 1e-12:
        return 0.0
    if shape == Shape.CUBIC:
        return math.sqrt(6.0 * d / max_acc)
    return math.pi * math.sqrt(d / (2.0 * max_acc))
