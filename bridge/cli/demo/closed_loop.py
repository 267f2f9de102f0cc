"""Demo stages for the main job: C&C datasheets, a UN R157 judge sample, and the closed loop
with the full sensor stack (expressway cut-in, city dart-out), recorded and exported."""

from __future__ import annotations

import tempfile
from pathlib import Path

from hiyari.bridge.loop.execute import RunOptions, execute
from hiyari.bridge.loop.toml_runs import preset_spec
from hiyari.bridge.openscenario.presets.toml_file import ConcreteScenario
from hiyari.bridge.record.reader import Recording
from hiyari.bridge.replay.export import export_html
from hiyari.bridge.studies.r157_judge import JudgeOptions, judge
from hiyari.bridge.studies.report.datasheets import write_datasheets
from hiyari.bridge.studies.report.r157 import write_report
from hiyari.bridge.studies.report.timeseries import plot_timeseries
from hiyari.risk.cc.boundary import Grid
from hiyari.risk.cc.r157_points import R157Config, generate_points, write_points_csv

CUT_IN = {"ve0_kmh": 60.0, "vo0_kmh": 30.0, "dx0_m": 25.0, "vy_ms": 1.0}
DART_OUT = {"ve0_kmh": 40.0, "ped_speed_kmh": 5.0, "impact_fraction": 0.5}


def run_datasheets(out_dir: Path) -> list[Path]:
    """The cut-in, cut-out and deceleration datasheets over Ve0 10-130 km/h."""
    return write_datasheets(out_dir)


def run_r157_sample(out_dir: Path, sample: int, workers: int) -> dict:
    """Test points over a 20-60 km/h ODD; a seeded sample judged with perfect perception."""
    cfg = R157Config(ve0_kmh=Grid(20, 60, 10), dv_kmh=Grid(0, 60, 10))
    points = generate_points(cfg).points
    write_points_csv(points, out_dir / "r157_points.csv")
    report = judge(points, JudgeOptions(perception="perfect", workers=workers, sample=sample))
    write_report(report, out_dir)
    return report.summary()["perfect"]


def run_sensor_scenario(
    stype: str, params: dict, out_dir: Path, environment: str = "clear"
) -> dict:
    """One closed-loop run with camera, radar and LiDAR; recorded, plotted, summarised."""
    cs = ConcreteScenario(
        stype,
        f"demo {stype}",
        0,
        1,
        15.0,
        0.05,
        params,
        perception="sensors",
        environment=environment,
    )
    options = RunOptions(out_dir=out_dir, progress=True, record=True, plot=plot_timeseries)
    with tempfile.TemporaryDirectory(prefix="hiyari-road-") as tmp:
        res = execute(preset_spec(cs, Path(tmp)), options)
    return res.as_dict()


def export_replay(recording: Path, out: Path) -> Path:
    """A static HTML replay of a recording (opens in a browser without Python)."""
    return export_html(Recording.open(recording), out, progress=False)
