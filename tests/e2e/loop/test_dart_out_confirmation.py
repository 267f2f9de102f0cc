"""Issue 30 item 2: confirming tracks (M of N) before the planner acts must not cost the CPNC-50
dart-out. A child steps out at 5 km/h from behind a parked car in front of the ego at 40 km/h,
seen by the full sensor stack (camera, radar, LiDAR) on real SUMO: the ego still stops short,
and its AEB starts at most two sensor cycles (0.1 s) later than with every track reported from
its first detection."""

from __future__ import annotations

from dataclasses import replace

from hiyari.bridge.loop.execute import execute
from hiyari.bridge.loop.stack import fusion
from hiyari.bridge.loop.toml_runs import TomlRun
from hiyari.bridge.openscenario.presets.toml_file import ConcreteScenario

DART = {"ve0_kmh": 40.0, "ped_speed_kmh": 5.0, "impact_fraction": 0.5}


def _run():
    cs = ConcreteScenario(
        "dart-out", "dart-out", 0, 1, 15.0, 0.05, DART, perception="sensors", environment="clear"
    )
    with TomlRun(cs).spec() as spec:
        return execute(spec)


def test_confirmation_does_not_cost_the_cpnc50_dart_out(monkeypatch):
    confirmed = _run()
    assert not confirmed.collision
    assert confirmed.aeb_max_stage == 3
    init = fusion.KalmanFusion.__init__

    def unconfirmed(self, config=None):
        init(self, replace(config or fusion.FusionConfig(), confirm_m=1))

    monkeypatch.setattr(fusion.KalmanFusion, "__init__", unconfirmed)
    at_once = _run()
    assert not at_once.collision
    assert confirmed.aeb_first_time <= at_once.aeb_first_time + 0.1 + 1e-9
