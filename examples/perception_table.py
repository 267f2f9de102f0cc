"""Perception-disturbance table: detection range of LiDAR, radar and camera per JAMA preset.

A crossing pedestrian and a car (rear view) stand in the ego's lane of a straight road at
5-150 m; each sensor's detection range is measured under clear weather, rain, fog, night
(with and without low beams), backlight, dark clothing, uniform and spot soiling and partial
occlusion. Writes perception_table.md / .csv / .png and prints the Markdown table.

Run: .venv/bin/python examples/perception_table.py [--out out/perception_table]
(about half a minute). From Python: hiyari.sensors.detection_range.perception_table().
"""

from __future__ import annotations

import argparse
import time

from hiyari.bridge.studies.report.perception.detection_range import write_table
from hiyari.sensors.detection_range import perception_table, table_markdown


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="out/perception_table", help="output folder")
    ap.add_argument("--presets", nargs="*", help="preset names (default: the ten of the table)")
    args = ap.parse_args()
    start = time.perf_counter()
    rows = perception_table(args.presets)
    paths = write_table(rows, args.out)
    print(table_markdown(rows))
    print(f"computed in {time.perf_counter() - start:.0f} s; written:")
    for p in paths.values():
        print(f"   {p}")


if __name__ == "__main__":
    main()
