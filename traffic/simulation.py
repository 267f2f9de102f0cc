"""A libsumo simulation session that yields one WorldState per step."""

from __future__ import annotations

import os
import sys
import tempfile
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from hiyari.errors import HiyariError
from hiyari.net.sumo.files import check_net, check_routes, check_xml
from hiyari.sumo_tools import (
    StderrTrap,
    check_net_loads,
    check_sumo_loads,
    first_error,
    sumo_binary,
    sumo_home,
)
from hiyari.traffic.collision import Collision, CollisionDetector
from hiyari.traffic.commands import Commands
from hiyari.traffic.read_scope import ReadScope
from hiyari.traffic.sumo_reader import ReadMode, WorldStateReader
from hiyari.traffic.world_state import WorldState


@dataclass(frozen=True)
class SimConfig:
    """What SUMO runs: a net with route / demand files, or a .sumocfg.

    Times in seconds of simulation time. ``end_time`` None runs until stopped by the caller.
    ``read_mode`` chooses how the full state is read (same values either way);
    ``read_scope`` None puts every actor into every step's WorldState, a
    :class:`~hiyari.traffic.read_scope.ReadScope` only the actors around the ego (the cheap
    read a closed loop needs; ``Simulation.full_state`` still reads everyone on demand).
    """

    net: Path | None = None
    routes: Sequence[Path] = ()
    additional: Sequence[Path] = ()
    config: Path | None = None
    step_length: float = 0.1
    seed: int = 42
    begin: float = 0.0
    end_time: float | None = None
    read_mode: ReadMode = "getters"
    read_scope: ReadScope | None = None
    ignore_route_errors: bool = False
    extra_args: Sequence[str] = field(default_factory=tuple)
    #: Inputs hiyari wrote itself (generated demand, a scenario's road): load errors never
    #: name them as the culprit, the user's own files are named instead.
    generated: Sequence[Path] = ()
    #: Load the net (or config) in a SUMO subprocess first: SUMO's loader crashes on some
    #: broken nets, and a crash in libsumo takes this process down. For files from users
    #: (the CLI turns it on); costs one extra load of the net.
    preflight: bool = False

    def validate(self) -> None:
        """Raise HiyariError for impossible parameters or unreadable input files."""
        if self.step_length <= 0:
            raise HiyariError(f"step length must be positive, got {self.step_length} s")
        if self.end_time is not None and self.end_time <= self.begin:
            raise HiyariError(f"end time {self.end_time} s must be after begin {self.begin} s")
        if self.read_scope is not None:
            self.read_scope.validate()
        if (self.net is None) == (self.config is None):
            raise HiyariError("give either a network (net) or a SUMO config (config), not both")
        if self.config is not None:
            check_xml(self.config, ("configuration", "sumoConfiguration"), "config")
        if self.net is not None:
            check_net(self.net)
        for r in self.routes:
            check_routes(r)
        for a in self.additional:
            check_xml(a, ("additional", "routes"), "additional file")

    def sumo_args(self, error_log: Path) -> list[str]:
        """Command line for libsumo.start (without the binary)."""
        args: list[str] = []
        if self.config is not None:
            args += ["-c", str(self.config)]
        if self.net is not None:
            args += ["-n", str(self.net)]
        if self.routes:
            args += ["-r", ",".join(str(r) for r in self.routes)]
        if self.additional:
            args += ["-a", ",".join(str(a) for a in self.additional)]
        args += [
            "--step-length",
            repr(self.step_length),
            "--seed",
            str(self.seed),
            "--begin",
            repr(self.begin),
            "--no-step-log",
            "true",
            "--no-warnings",
            "true",
            "--error-log",
            str(error_log),
            "--collision.action",
            "warn",
            "--collision.check-junctions",
            "true",
            # SUMO's default counts a gap below minGap (2.5 m) as a collision: contact only
            "--collision.mingap-factor",
            "0",
            "--time-to-teleport",
            "-1",
        ]
        if self.end_time is not None:
            args += ["--end", repr(self.end_time)]
        if self.ignore_route_errors:
            args += ["--ignore-route-errors", "true"]
        return args + list(self.extra_args)


class Simulation(Commands):
    """One libsumo simulation; a context manager that always closes SUMO.

    Typed commands (add / move / remove actors, set speeds, change lanes) and reads (routes,
    signals) come from :class:`~hiyari.traffic.commands.Commands`.

    libsumo runs one simulation per process: starting a second while one is open raises
    HiyariError. Use separate processes for parallel runs.
    """

    def __init__(self, config: SimConfig, detect_collisions: bool = True) -> None:
        config.validate()
        self.config = config
        self._detector = CollisionDetector() if detect_collisions else None
        self._open = False
        self._state: WorldState | None = None
        self._collisions: list[Collision] = []
        self._tmpdir: tempfile.TemporaryDirectory[str] | None = None
        self._trap: StderrTrap | None = None
        self._moves_pending = False  # a moveToXY waits for the next step

    # ------------------------------------------------------------------ lifecycle
    def __enter__(self) -> Simulation:
        self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def start(self) -> None:
        """Load the network and demand into libsumo."""
        import libsumo

        if libsumo.simulation.isLoaded():
            raise HiyariError(
                "a libsumo simulation is already running in this process; libsumo allows one "
                "per process (close it first, or run the second in another process)"
            )
        os.environ.setdefault("SUMO_HOME", str(sumo_home()))
        self._preflight()
        self._tmpdir = tempfile.TemporaryDirectory(prefix="hiyari-sumo-")
        self._trap = StderrTrap()
        err_log = Path(self._tmpdir.name) / "errors.log"
        try:
            with self._trap:
                libsumo.start([str(sumo_binary("sumo")), *self.config.sumo_args(err_log)])
        except Exception as exc:  # TraCIException / FatalError: "Process Error"
            if libsumo.simulation.isLoaded():  # a half-loaded run would block the next
                libsumo.close()
            detail = first_error(self._trap.take()) or _first_error(err_log) or str(exc)
            self._cleanup_tmp()
            raise HiyariError(
                self._sumo_error("SUMO could not load it", detail or type(exc).__name__)
            ) from None
        except BaseException:
            self._cleanup_tmp()
            raise
        self._sumo = libsumo
        self._open = True
        self._reader = WorldStateReader(libsumo, self.config.read_mode, self.config.read_scope)
        self._state = self._reader.read()
        self._full: WorldState | None = None

    def close(self) -> None:
        """Close SUMO (safe to call twice)."""
        if self._open:
            try:
                if self._moves_pending:
                    # libsumo keeps a vehicle moved by moveToXY for the next step in a
                    # process-wide table: closing with one pending left a dangling entry that
                    # crashed the next simulation of the process at its first step
                    self._sumo.simulationStep()
            finally:
                self._sumo.close()
                self._open = False
        self._cleanup_tmp()

    def _cleanup_tmp(self) -> None:
        if self._tmpdir is not None:
            self._tmpdir.cleanup()
            self._tmpdir = None
        if self._trap is not None:
            self._trap.close()
            self._trap = None

    def _preflight(self) -> None:
        """SUMO's own check of the user's net / config in a subprocess (see SimConfig)."""
        cfg = self.config
        generated = {Path(g) for g in cfg.generated}
        if not cfg.preflight:
            return
        if cfg.config is not None and Path(cfg.config) not in generated:
            check_sumo_loads(["-c", str(cfg.config)], str(cfg.config), "SUMO could not load it")
        elif cfg.net is not None and Path(cfg.net) not in generated:
            check_net_loads(cfg.net)

    def _advance(self, *until: float) -> None:
        """One ``simulationStep`` (to ``until`` when given) with SUMO's stderr trapped: a
        failure becomes one HiyariError naming the user's file; messages of a step that
        went on are passed to stderr as they came."""
        now = self._sumo.simulation.getTime()
        self._moves_pending = False
        try:
            with self._trap:
                self._sumo.simulationStep(*until)
        except Exception as exc:
            detail = first_error(self._trap.take())
            if not detail and self._tmpdir:
                detail = _first_error(Path(self._tmpdir.name) / "errors.log")
            what = f"SUMO stopped at t={now:.2f} s"
            raise HiyariError(self._sumo_error(what, detail or str(exc))) from None
        text = self._trap.take()
        if text:
            sys.stderr.write(text)

    def _sumo_error(self, what: str, detail: str) -> str:
        """One line for a SUMO failure, naming the user's file SUMO rejected.

        SUMO names the element, rarely the file: a file named in the message is the culprit;
        with a net and demand files, the net is checked alone to tell which one it was.
        Generated inputs are named by file name only and never blamed when a user's file can
        be (a caller such as ``hiyari run`` puts the scenario file in front).
        """
        cfg = self.config
        generated = {Path(g) for g in cfg.generated}
        for g in generated:
            detail = detail.replace(str(g), g.name)
        inputs = [Path(p) for p in (cfg.config, cfg.net) if p is not None]
        inputs += [Path(p) for p in (*cfg.routes, *cfg.additional)]
        user = [p for p in inputs if p not in generated]
        named = [p for p in user if p.name in detail]
        if named:
            culprits = named[:1]
        elif len(user) <= 1 or cfg.config is not None:
            culprits = user[:1]
        else:
            culprits = self._culprits(user)
        if not culprits:
            names = ", ".join(p.name for p in inputs)
            return f"{what} (generated {names}): {detail}"
        return f"{', '.join(map(str, culprits))}: {what}: {detail}"

    def _culprits(self, user: list[Path]) -> list[Path]:
        """The net when SUMO rejects it alone, else the user's demand / additional files."""
        net = self.config.net
        if net is not None and Path(net) in user:
            try:
                check_net_loads(net)
            except HiyariError:
                return [Path(net)]
            return [p for p in user if p != Path(net)] or [Path(net)]
        return user

    # ------------------------------------------------------------------ stepping
    def _api(self):
        self._require_open()
        return self._sumo

    def _commanded(self, actor_ids: Sequence[str], persons: bool = False) -> None:
        self._require_open()
        self._reader.pin(actor_ids, persons)

    @property
    def state(self) -> WorldState:
        """The WorldState after the latest step (or at load time)."""
        self._require_open()
        if self._state is None:  # after skip_ahead
            self._state = self._reader.read()
        return self._state

    @property
    def full_state(self) -> WorldState:
        """Every vehicle and person at the current step, whatever the read scope (read on the
        first access per step; without a scope this is ``state``)."""
        state = self.state
        if self.config.read_scope is None:
            return state
        if self._full is None or self._full.time != state.time:
            self._full = self._reader.read_full()
        return self._full

    @property
    def time(self) -> float:
        """Current simulation time, s."""
        return self.state.time

    @property
    def collisions(self) -> list[Collision]:
        """Contacts found at the latest step (oriented rectangles plus SUMO's own reports)."""
        return self._collisions

    def step(self) -> WorldState:
        """Advance one step and return the new WorldState."""
        self._require_open()
        self._advance()
        self._state = self._reader.read()
        if self._detector is not None:
            self._collisions = self._detector.detect(self._state, self._scope_contacts())
        return self._state

    def fast_forward(self, until: float) -> WorldState:
        """Step SUMO to ``until`` without reading states or checking contacts (warm-ups)."""
        self._require_open()
        self._reader.pause()
        while self._sumo.simulation.getTime() < until - 1e-9:
            self._advance()
        self._state = self._reader.read()
        self._collisions = []
        return self._state

    def skip_ahead(self, until: float) -> None:
        """Advance SUMO to ``until`` (s) in one call, reading nothing: for stretches where no
        consumer needs the state (the next ``state`` access reads it)."""
        self._require_open()
        self._reader.pause()
        self._advance(until)
        self._state = None
        self._collisions = []

    def run_bare(self, until: float) -> None:
        """Step SUMO one step at a time to ``until`` with nothing read: the bare-SUMO baseline
        the benchmarks compare against."""
        self._require_open()
        self._reader.pause()
        step, now = self._sumo.simulationStep, self._sumo.simulation.getTime
        end = until - 1e-9
        while now() < end:
            step()
        self._state = None
        self._collisions = []

    @staticmethod
    def loaded_in_process() -> bool:
        """Whether a libsumo simulation is open in this process."""
        import libsumo

        return bool(libsumo.simulation.isLoaded())

    def sumo_contacts(self) -> list[tuple[str, str]]:
        """(collider, victim) pairs SUMO itself reported at the latest step."""
        self._require_open()
        return self._sumo_collisions()

    def run(self, until: float | None = None) -> Iterator[WorldState]:
        """Step until ``until`` (or the configured end, or until SUMO has no more demand)."""
        end = until if until is not None else self.config.end_time
        eps = 1e-9
        while True:
            if end is not None and self.time >= end - eps:
                return
            if end is None and self._sumo.simulation.getMinExpectedNumber() <= 0:
                return
            yield self.step()

    def _sumo_collisions(self) -> list[tuple[str, str]]:
        return [(c.collider, c.victim) for c in self._sumo.simulation.getCollisions()]

    def _scope_contacts(self) -> list[tuple[str, str]]:
        """SUMO's contacts between actors of the current state (all of them without a scope)."""
        pairs = self._sumo_collisions()
        if pairs and self.config.read_scope is not None:
            ids = set(self._state.ids.tolist())
            pairs = [(a, b) for a, b in pairs if a in ids and b in ids]
        return pairs

    def _require_open(self) -> None:
        if not self._open:
            raise HiyariError(
                "the simulation is not running (use it inside 'with Simulation(...)')"
            )


def _first_error(log: Path) -> str:
    return first_error(log.read_text(errors="replace")) if log.exists() else ""
