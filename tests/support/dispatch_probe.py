"""Run a few closed-loop scenarios and print what they computed, as JSON on stdout.

tests/e2e/core/test_cross_cpu_determinism.py runs this once with numpy's default SIMD dispatch and once
with it limited (NPY_DISABLE_CPU_FEATURES), standing in for two CPUs: numpy's vectorised
transcendental functions differ between dispatch targets in the last bits.
"""

from __future__ import annotations

import json
import sys

from paths import SHARED

from hiyari.bridge.loop.execute import execute
from hiyari.bridge.loop.spec import EgoSetup, model_spec
from hiyari.bridge.openscenario.xosc.reader import read_scenario

ALKS = SHARED / "data/openscenario/alks"
#: scenario file, perception, run length (s): a cut-in, an emergency brake, a pedestrian
SCENARIOS = [
    ("alks_scenario_4_4_1_cut_in_no_collision_template.xosc", "perfect", 8.0),
    ("alks_scenario_4_3_2_follow_lead_vehicle_emergency_brake_template.xosc", "perfect", 8.0),
    ("alks_scenario_4_2_3_crossing_pedestrian_template.xosc", "sensors", 6.0),
]


def probe(name: str, perception: str, duration: float) -> dict:
    """The run's verdict, its TTC and gap series and every actor's position at every step."""
    positions: list[list[float]] = []

    def on_step(state, _step, _collisions) -> None:
        positions.append(state.xyz[:, :2].ravel().tolist())

    setup = EgoSetup(perception=perception, max_duration=duration)
    res = execute(model_spec(read_scenario(ALKS / name), setup), on_step=on_step)
    return {
        "verdict": res.verdict(),
        "min_ttc": res.min_ttc,
        "ttc": res.series.ttc_true,
        "gap": res.series.gap,
        "positions": positions,
    }


if __name__ == "__main__":
    json.dump({n: probe(n, p, d) for n, p, d in SCENARIOS}, sys.stdout)
