"""Compile hiyari's kernels into their on-disk cache before the test workers start.

numba compiles a kernel on its first call and caches it beside its source, so on a fresh clone
every test process (both pytest-xdist workers, and the sweeps, judges and CLI runs the tests
start) would compile the same kernels at the same moment, several times over, before any of
them could load another's build. ``make test`` runs this first: two processes, one per core,
each driving one part of the code through short real runs, so every kernel the suite uses is
compiled once. With a warm cache it takes a few seconds.

Usage: python tests/support/warm_kernels.py [part]  (no part: every part, in parallel)
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from pathlib import Path

from paths import SHARED

ALKS = SHARED / "data/openscenario/alks"


def warm_loop() -> None:
    """The OpenSCENARIO engine, the OpenDRIVE road, the traffic state, the sensors (LiDAR,
    radar, camera) and recognition, and the closed-loop metrics: the first seconds of a cut-in
    with the sensor stack (the LiDAR sees the car and fits its box) and of a crossing
    pedestrian with perfect perception."""
    from hiyari.bridge.loop.execute import execute
    from hiyari.bridge.loop.spec import EgoSetup, model_spec
    from hiyari.bridge.openscenario.xosc.reader import read_scenario

    for name, perception, duration in (
        ("alks_scenario_4_4_1_cut_in_no_collision_template.xosc", "sensors", 4.0),
        ("alks_scenario_4_2_3_crossing_pedestrian_template.xosc", "perfect", 6.0),
    ):
        setup = EgoSetup(perception=perception, max_duration=duration)
        execute(model_spec(read_scenario(ALKS / name), setup))


def warm_sct() -> None:
    """The SCT model, controller and encounter metrics, and the study's step scan: a short
    arm of the incident study with SCT-driven vehicles on the generated intersection."""
    from hiyari.bridge.studies.sct.study import StudyConfig, build_inputs, run_arm

    with tempfile.TemporaryDirectory(prefix="hiyari-warm-") as tmp:
        config = StudyConfig(days=180 / 86400, runs=1, seed=3)
        for task in build_inputs(config, Path(tmp)):
            run_arm(task)


PARTS = {"loop": warm_loop, "sct": warm_sct}


def main(argv: list[str]) -> int:
    if argv:
        PARTS[argv[0]]()
        return 0
    t0 = time.monotonic()
    procs = [subprocess.Popen([sys.executable, __file__, part]) for part in PARTS]
    failed = [part for part, p in zip(PARTS, procs, strict=True) if p.wait() != 0]
    # a part that fails leaves its kernels to the tests, which compile them on first use and
    # report the failure where it belongs: the suite runs either way
    note = f"; {', '.join(failed)} failed (the tests compile those)" if failed else ""
    print(f"kernels warm in {time.monotonic() - t0:.0f} s{note}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
