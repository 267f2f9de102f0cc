"""Shared fixtures: small generated networks and demand, built once per test session."""

from __future__ import annotations

import os
import re
import resource
import shutil
import tempfile
from pathlib import Path

import pytest
from durations import DurationLog

from hiyari.checkout import shared_dir
from hiyari.net.sumo.build import IntersectionParams, build_intersection
from hiyari.traffic.demand import DemandConfig, write_demand

SHARED = shared_dir(Path(__file__).resolve().parents[1])
#: Temporary folders hiyari makes; none may be left behind by the test suite.
HIYARI_TEMP = ("hiyari-run-*", "hiyari-net-*", "hiyari-sumo-*", "hiyari-sim-*", "hiyari-study-*")


def _xdist_worker(config: pytest.Config) -> str | None:
    """The pytest-xdist worker id ("gw0", ...) when this process is one, else None."""
    workerinput = getattr(config, "workerinput", None)
    return None if workerinput is None else workerinput["workerid"]


def pytest_configure(config: pytest.Config) -> None:
    """Every temporary folder of this session (and of the processes it starts) goes into one
    folder of its own, so leftovers are this suite's and not another program's.

    Under pytest-xdist the controller makes that folder before it starts the workers, which
    inherit it (TMPDIR), and checks it once they have all finished. The workers share the
    compiled kernels' cache with every other hiyari process (hiyari/jit.py makes it safe);
    ``make test`` fills it before they start (tests/support/warm_kernels.py), so a kernel
    compiles once, not once per worker and per run the tests start.

    No core files: several tests crash processes on purpose (the pool's SIGSEGV hook, an
    aborted xdist worker), and each core of a process with hiyari loaded is about 300 MB in the
    working folder. On a CI machine with little free disk one of them fills it, and every
    later run that writes fails."""
    resource.setrlimit(resource.RLIMIT_CORE, (0, resource.getrlimit(resource.RLIMIT_CORE)[1]))
    if _xdist_worker(config) is not None:
        return
    config.pluginmanager.register(DurationLog(durations_path(config)), "hiyari-durations")
    base = Path(tempfile.mkdtemp(prefix="hiyari-tests-"))
    config.stash[_TEMP_KEY] = (base, os.environ.get("TMPDIR"))
    os.environ["TMPDIR"] = str(base)
    tempfile.tempdir = None  # recomputed from TMPDIR


def durations_path(config: pytest.Config) -> Path:
    """Where this session writes its durations: out/test-durations.csv for the whole suite
    (CI keeps it; the scheduler reads it), out/test-durations-<marker>.csv for a marker
    selection (CI's baseline-dispatch run after the suite would otherwise overwrite the
    suite's file with its 45 tests) and out/test-durations-selection.csv for named tests or -k."""
    out = Path(__file__).resolve().parents[1] / "out"
    mark = config.getoption("markexpr", "")
    if mark:
        return out / f"test-durations-{re.sub(r'[^A-Za-z0-9]+', '-', mark).strip('-')}.csv"
    whole = [config.rootpath / t for t in config.getini("testpaths")]
    if config.getoption("keyword", "") or [Path(a).resolve() for a in config.args] != whole:
        return out / "test-durations-selection.csv"
    return out / "test-durations.csv"


def pytest_sessionfinish(session: pytest.Session, exitstatus: int) -> None:
    """Fail the session when a test left one of hiyari's temporary folders behind."""
    if _xdist_worker(session.config) is not None:
        return  # the controller checks the folder all workers shared
    base, previous = session.config.stash[_TEMP_KEY]
    left = sorted(p.name for pattern in HIYARI_TEMP for p in base.glob(pattern))
    if left:
        print(f"\nhiyari temporary folders left behind: {', '.join(left)}")
        session.exitstatus = 1
    else:
        shutil.rmtree(base, ignore_errors=True)
    if previous is None:
        os.environ.pop("TMPDIR", None)
    else:
        os.environ["TMPDIR"] = previous
    tempfile.tempdir = None


_TEMP_KEY = pytest.StashKey[tuple[Path, str | None]]()


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config: pytest.Config, log: object) -> object | None:
    """``-n 2`` (``make test``): the suite's scheduler (tests/support/xdist_schedule.py)."""
    from xdist_schedule import make_scheduler

    return make_scheduler(config, log)


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Tests under tests/e2e carry the ``e2e`` marker (``-m "not e2e"``: the unit tests)."""
    e2e = Path(__file__).parent / "e2e"
    for item in items:
        if e2e in item.path.parents:
            item.add_marker(pytest.mark.e2e)


@pytest.fixture(scope="session")
def intersection_net(tmp_path_factory) -> Path:
    """A signalised four-leg intersection with sidewalks and crossings."""
    out = tmp_path_factory.mktemp("net") / "intersection.net.xml"
    return build_intersection(out, IntersectionParams(traffic_light=True))


@pytest.fixture(scope="session")
def intersection_demand(intersection_net, tmp_path_factory) -> Path:
    """Ten minutes of mixed vehicles and pedestrians on the intersection."""
    out = tmp_path_factory.mktemp("demand") / "demand.rou.xml"
    cfg = DemandConfig(
        vehicles_per_hour=1200,
        persons_per_hour=1200,
        end=600,
        seed=7,
        vehicle_mix={"car": 0.7, "truck": 0.1, "bus": 0.1, "motorcycle": 0.1},
    )
    return write_demand(intersection_net, out, cfg)
