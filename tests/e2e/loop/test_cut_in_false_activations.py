"""Issue 30 item 4: no false activation from the fusion's own errors in R157 points that had
them with sensors (real SUMO, full sensor stack, the judge's seed).

- A car cuts in at 1.3 m/s, alongside the ego at the same 20 km/h with its rear 0.1 m ahead of
  the ego's front: in ground truth their footprints never overlap (TTC infinite). A camera
  object 1 m too long, taken as the track's size, and a radar point on the car's rear face
  taken as a second car 2.5 m nearer, each put a box over the ego's front: full AEB at TTC 0.
- A lead 2 s ahead at 20 km/h brakes at 0.1 g: the radar's point on its rear face, taken as a
  centre, grew a second track 2.4 m nearer than the car, and AEB warnings with no conflict.

Both now pass without an AEB stage or braking beyond the ACC's 3 m/s^2 outside a ground-truth
conflict (FusionConfig.size_drift, FusionConfig.radar_face_depth), and without a collision.
"""

from __future__ import annotations

import pytest

from hiyari.bridge.loop.execute import RunOptions, execute
from hiyari.bridge.loop.toml_runs import TomlRun
from hiyari.bridge.openscenario.presets.toml_file import ConcreteScenario
from hiyari.units import G

POINTS = {
    "cut-in/ve20/vo20/vy1.3/boundary": (
        "cut-in",
        {"ve0_kmh": 20.0, "vo0_kmh": 20.0, "dx0_m": 0.1, "vy_ms": 1.3},
        3.5 / 1.3 + 8.0,
    ),
    "decel/ve20/gx0.1/thw2": (
        "decel",
        {"ve0_kmh": 20.0, "gx_max_g": 0.1},
        20 / 3.6 / (G * 0.1) + 8.0,
    ),
}


@pytest.mark.parametrize("name", list(POINTS))
def test_no_false_activation_with_sensors(name: str):
    kind, params, duration = POINTS[name]
    # seed 1 and the judge's step, AEB delay and early end (bridge.studies.r157_judge)
    cs = ConcreteScenario(kind, name, 0, 1, duration, 0.05, params, perception="sensors")
    with TomlRun(cs).spec() as spec:
        res = execute(spec, RunOptions(end_when_decided=True))
    assert res.false_activations() == 0
    assert not res.collision
    assert res.tested().tested
