"""Write the three C&C Preventable-boundary datasheets (cut-in, cut-out, deceleration).

Ve0 10-130 km/h at 1 km/h; cut-in relative speeds 0-60 km/h and Vy 0.1-3.0 m/s with the
boundary at 0.1 m; CSV and PNG per scenario, like JAMA Fig. 26, 28 and 30.

Run: .venv/bin/python examples/datasheets.py [OUT_DIR] [--aeb]   (default out/datasheets)
"""

from __future__ import annotations

import argparse
import time

from hiyari.bridge.studies.report.datasheets import write_datasheets
from hiyari.risk.cc.model import CCParams


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", nargs="?", default="out/datasheets", help="output folder")
    ap.add_argument("--aeb", action="store_true", help="AEB-equipped C&C driver")
    args = ap.parse_args()
    started = time.perf_counter()
    paths = write_datasheets(args.out, CCParams(aeb=args.aeb))
    print(f"datasheets written in {time.perf_counter() - started:.1f} s:")
    for path in paths:
        print(f"   {path}")


if __name__ == "__main__":
    main()
