"""A closed-loop run with the full sensor stack recorded to MCAP and read back."""

from __future__ import annotations

import numpy as np
from runs import run_preset

from hiyari.bridge.loop.execute import RunOptions
from hiyari.bridge.openscenario.presets.toml_file import ConcreteScenario
from hiyari.bridge.record.reader import Recording


def test_sensor_run_records_and_reads_back(tmp_path):
    cs = ConcreteScenario(
        "dart-out",
        "dart-out",
        0,
        1,
        4.0,
        0.05,
        {"ve0_kmh": 40.0, "ped_speed_kmh": 5.0, "impact_fraction": 0.5},
        perception="sensors",
    )
    seen = {"steps": 0, "lidar": [], "ego_speed": []}

    def on_step(world, step, collisions):
        seen["steps"] += 1
        seen["ego_speed"].append(float(world.speed[world.index("ego")]))

    res = run_preset(cs, RunOptions(out_dir=tmp_path, record=True), on_step=on_step)
    path = tmp_path / "run.mcap"
    assert path.exists() and not (tmp_path / "run.mcap.part").exists()
    rec = Recording.open(path)
    assert len(rec) == seen["steps"] == len(res.series.t)
    times = [rec.world(k).time for k in range(len(rec))]
    assert np.allclose(times, res.series.t)
    world, ego = rec.world_and_ego(len(rec) - 1)
    assert ego == "ego" and {"child", "parked"} <= set(world.ids.tolist())
    assert world.speed[world.index("ego")] == seen["ego_speed"][-1]
    # 4 s at 10 Hz LiDAR / 20 Hz radar; the 30 Hz camera renders every 10th frame
    topics = " ".join(rec.topics)
    for name in ("lidar", "radar", "camera", "fusion"):
        assert name in topics, topics
    last = len(rec) - 1
    assert len(rec.point_cloud("lidar", last)) > 1000
    status = rec.ego_status(last)
    assert status is not None and abs(status["speed_mps"] - seen["ego_speed"][-1]) < 1e-9
    assert rec.mesh() is not None
