"""``hiyari doctor``: versions of the parts hiyari needs, non-zero when one is missing."""

from __future__ import annotations

import argparse
import importlib
import platform
import sys
from importlib.metadata import PackageNotFoundError, version


def _pkg_version(dist: str) -> str | None:
    try:
        return version(dist)
    except PackageNotFoundError:
        return None


def _check_embree() -> str:
    import numpy as np
    from embreex import rtcore_scene
    from embreex.mesh_construction import TriangleMesh

    scene = rtcore_scene.EmbreeScene()
    tri = np.array([[[0, -1, -1], [0, 1, -1], [0, 0, 1]]], dtype=np.float32)
    TriangleMesh(scene, tri)
    hit = scene.run(np.array([[-1, 0, 0]], np.float32), np.array([[1, 0, 0]], np.float32))
    if int(hit[0]) != 0:
        raise RuntimeError("test ray missed")
    return "ray cast ok"


def _check_sumo() -> str:
    from hiyari.sumo_tools import sumo_binary, sumo_version

    for tool in ("sumo", "netconvert", "netgenerate"):
        sumo_binary(tool)
    return sumo_version()


def _check_libsumo() -> str:
    importlib.import_module("libsumo")
    return _pkg_version("libsumo") or "?"


def run(_: argparse.Namespace) -> int:
    """Print one line per part; return 1 when a required part fails."""
    checks = [
        ("python", lambda: platform.python_version(), True),
        ("SUMO (eclipse-sumo)", _check_sumo, True),
        ("libsumo", _check_libsumo, True),
        ("Embree (embreex)", _check_embree, True),
    ]
    for dist in (
        "sumolib",
        "numpy",
        "shapely",
        "lxml",
        "opencv-python-headless",
        "mcap",
        "osi-python",
        "viser",
        "matplotlib",
    ):
        checks.append((dist, lambda d=dist: _pkg_version(d) or _missing(d), True))
    checks.append(("ray (optional)", lambda: _pkg_version("ray") or "not installed", False))
    failed = 0
    for name, fn, required in checks:
        try:
            status, ok = fn(), True
        except Exception as exc:  # report every failing part, not just the first
            status, ok = f"MISSING: {exc}", False
        mark = "ok " if ok else ("ERR" if required else "-- ")
        print(f"[{mark}] {name:28s} {status}")
        failed += (not ok) and required
    if failed:
        print(f"{failed} required part(s) missing", file=sys.stderr)
        return 1
    print("all required parts present")
    return 0


def _missing(dist: str) -> str:
    raise RuntimeError(f"{dist} is not installed")


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("doctor", help="check Python, SUMO, libsumo, Embree and libraries")
    p.set_defaults(func=run)
