"""The 15 ALKS reference scenarios in closed loop with hiyari's default ego stack on real SUMO:
each runs to its stop trigger with a verdict (perfect perception), and a cut-in with the full
sensor stack runs its first seconds, recorded and read back. The full table (both perception modes, recordings,
replays) comes from ``python -m hiyari.bridge.studies.alks``."""

from __future__ import annotations

from pathlib import Path

import pytest
from openscenario_files import ALKS

from hiyari.bridge.loop.execute import RunOptions, execute
from hiyari.bridge.loop.spec import EgoSetup
from hiyari.bridge.loop.xosc_runs import load_plan
from hiyari.bridge.record.reader import Recording

FILES = sorted(ALKS.glob("alks_scenario_*.xosc"))
#: The two 5-minute free drives: capped at 20 s here (the table runs them whole).
FREE_DRIVES = ("4_1_1", "4_1_3")
#: Scenarios with a target the ego must stop or stay behind (R157 5.2.5: no collision).
BLOCKING = ("4_2_1", "4_2_4", "4_3_2", "4_5_1", "4_5_2")


@pytest.mark.slow
@pytest.mark.parametrize("path", FILES, ids=lambda p: p.stem[14:19])
def test_alks_scenario_closed_loop_verdict(path: Path) -> None:
    free = any(k in path.stem for k in FREE_DRIVES)
    setup = EgoSetup(perception="perfect", max_duration=20.0 if free else 600.0)
    (run,) = load_plan(path, setup).expand()
    with run.spec() as spec:
        res = execute(spec)
    assert res.stop_trigger != free
    if free:
        assert res.sim_seconds == pytest.approx(20.0, abs=0.06)
    assert not res.collision, (res.collided_with, res.collision_time)
    assert len(res.series.t) == round(res.sim_seconds / setup.step_length)
    if any(k in path.stem for k in BLOCKING):
        # the stack braked for it (AEB or ACC): it ends standing or following, never inside
        assert 0.0 < res.min_gap < 30.0
        assert res.min_ttc < 10.0


@pytest.mark.slow
def test_alks_cut_in_with_sensors_records_perceived_objects(tmp_path: Path) -> None:
    """The first 4 s of the cut-in with camera, radar and LiDAR (the full runs are in the
    README's table): the sensors see the cut-in car, the recording holds every step."""
    path = next(p for p in FILES if "4_4_1" in p.stem)
    (run,) = load_plan(path, EgoSetup(perception="sensors", max_duration=4.0)).expand()
    with run.spec() as spec:
        res = execute(spec, RunOptions(out_dir=tmp_path, record=True))
    assert not res.stop_trigger and not res.collision
    assert res.detection["fusion"].target_frames == 0  # no fixed target in a .xosc run
    assert res.detection["fusion"].true_positives > 0
    rec = Recording.open(tmp_path / "run.mcap")
    assert len(rec) == len(res.series.t)
    assert "lidar" in " ".join(rec.topics)
