"""The closed loop: SUMO step -> WorldState -> ego stack -> ego speed back into SUMO.

One run of a scripted scenario or of free traffic. Ground-truth metrics (true TTC, gap to the
scenario's target, collisions) come from the WorldState, never from the stack's own beliefs.
"""

from __future__ import annotations

import time as wallclock
from collections import defaultdict
from dataclasses import dataclass, field

import numpy as np

from hiyari.bridge.stack.aeb import AEBConfig, time_to_collision
from hiyari.bridge.stack.ego_pose import EgoPose
from hiyari.bridge.stack.interfaces import EgoStack, EgoStep
from hiyari.bridge.stack.perception_truth import PerfectPerception
from hiyari.sensors.outputs import ObjectList
from hiyari.traffic.simulation import Simulation
from hiyari.traffic.world_state import WorldState


@dataclass
class DetectionStats:
    """Counts for one object-list source over a run."""

    frames: int = 0
    objects: int = 0
    true_positives: int = 0
    false_positives: int = 0
    target_frames: int = 0  # frames in which the scenario's target was detected
    target_first_time: float = float("nan")  # s
    target_first_range: float = float("nan")  # m, ego centre to target centre
    position_error_sum: float = 0.0  # m, over true positives

    def as_dict(self) -> dict:
        mean_err = self.position_error_sum / self.true_positives if self.true_positives else None
        return {
            "frames": self.frames,
            "objects": self.objects,
            "true_positives": self.true_positives,
            "false_positives": self.false_positives,
            "target_frames": self.target_frames,
            "target_first_time_s": _num(self.target_first_time),
            "target_first_range_m": _num(self.target_first_range),
            "mean_position_error_m": None if mean_err is None else round(mean_err, 3),
        }


@dataclass
class RunResult:
    """Outcome of one closed-loop run. Speeds m/s, distances m, times s."""

    label: str
    collision: bool = False
    collided_with: str = ""
    collision_time: float = float("nan")
    impact_speed: float = 0.0  # ego speed at first contact
    relative_impact_speed: float = 0.0  # closing speed at first contact
    min_ttc: float = float("inf")  # true TTC over all actors
    min_gap: float = float("inf")  # bumper-to-bumper to the target
    stop_distance: float = float("nan")  # ego front to the conflict point at the first stop
    aeb_first_time: float = float("nan")
    aeb_max_stage: int = 0
    final_speed: float = 0.0
    sim_seconds: float = 0.0
    wall_seconds: float = 0.0
    detection: dict[str, DetectionStats] = field(
        default_factory=lambda: defaultdict(DetectionStats)
    )
    series: dict[str, list[float]] = field(default_factory=lambda: defaultdict(list))

    def verdict(self) -> str:
        return "collision" if self.collision else "no collision"

    def as_dict(self) -> dict:
        """JSON-ready summary (no time series)."""
        return {
            "label": self.label,
            "collision": self.collision,
            "collided_with": self.collided_with,
            "collision_time_s": _num(self.collision_time),
            "impact_speed_kmh": round(self.impact_speed * 3.6, 2),
            "relative_impact_speed_kmh": round(self.relative_impact_speed * 3.6, 2),
            "min_ttc_s": _num(self.min_ttc),
            "min_gap_m": _num(self.min_gap),
            "stop_distance_m": _num(self.stop_distance),
            "aeb_first_time_s": _num(self.aeb_first_time),
            "aeb_max_stage": self.aeb_max_stage,
            "final_speed_kmh": round(self.final_speed * 3.6, 2),
            "sim_seconds": round(self.sim_seconds, 3),
            "wall_seconds": round(self.wall_seconds, 3),
            "detection": {k: v.as_dict() for k, v in sorted(self.detection.items())},
        }


def _num(x: float) -> float | None:
    return None if not np.isfinite(x) else round(float(x), 3)


class ScenarioHooks:
    """What a scenario script supplies to the loop (all optional)."""

    ego_id: str = "ego"
    target_id: str = ""
    conflict_point: tuple[float, float] | None = None  # network x, y of the conflict point

    def before_step(self, sim: Simulation, script_time: float) -> None:
        """Move scripted actors for the coming step."""

    def script_time(self, sim_time: float) -> float:
        return sim_time

    def done(self, world: WorldState, ego: EgoPose, script_time: float) -> bool:
        """True when the scenario has played out (besides duration and collisions)."""
        return False


def run_closed_loop(
    sim: Simulation,
    stack: EgoStack,
    hooks: ScenarioHooks,
    duration: float,
    label: str = "",
    on_step=None,
    progress: bool = False,
) -> RunResult:
    """Run until ``duration`` (s of simulation time from now), a collision or ``hooks.done``.

    ``on_step(world, ego_step, collisions)`` is called after every stack step (recording,
    custom metrics).
    """
    from tqdm import tqdm

    res = RunResult(label=label)
    truth_eye = PerfectPerception(max_range=300.0, fov_deg=360.0)
    ttc_cfg = AEBConfig(lateral_margin=0.0)
    dt = sim.config.step_length
    t_end = sim.time + duration
    n_steps = int(round(duration / dt))
    t0 = wallclock.perf_counter()
    bar = tqdm(total=n_steps, unit="step", disable=not progress, desc=label[:30] or "run")
    ego_id = hooks.ego_id
    try:
        while sim.time < t_end - 1e-9:
            hooks.before_step(sim, hooks.script_time(sim.time + dt))
            world = sim.step()
            bar.update(1)
            if ego_id not in world.ids:
                if res.sim_seconds > 0:
                    break  # the ego left the network
                continue
            row = world.index(ego_id)
            step = stack.step(world, row)
            ego = EgoPose.from_world(world, row)
            _metrics(res, world, row, ego, step, hooks, truth_eye, ttc_cfg)
            if on_step is not None:
                on_step(world, step, sim.collisions)
            hit = [c for c in sim.collisions if ego_id in (c.a, c.b)]
            if hit:
                other = hit[0].b if hit[0].a == ego_id else hit[0].a
                res.collision, res.collided_with, res.collision_time = True, other, world.time
                res.impact_speed = ego.speed
                k = world.index(other)
                rel = world.velocity[row] - world.velocity[k]
                res.relative_impact_speed = float(np.linalg.norm(rel))
                break
            v_next = max(0.0, ego.speed + step.command.accel * dt)
            sim.set_speed(ego_id, v_next)
            res.sim_seconds = world.time
            if hooks.done(world, ego, hooks.script_time(world.time)):
                break
    finally:
        bar.close()
    res.wall_seconds = wallclock.perf_counter() - t0
    if res.series["t"]:
        res.final_speed = res.series["ego_speed"][-1]
        res.sim_seconds = res.series["t"][-1] - res.series["t"][0] + dt
    return res


def _metrics(
    res: RunResult,
    world: WorldState,
    row: int,
    ego: EgoPose,
    step: EgoStep,
    hooks: ScenarioHooks,
    truth_eye: PerfectPerception,
    ttc_cfg: AEBConfig,
) -> None:
    truth = truth_eye.perceive(world, row, ego)[0]
    ttc = time_to_collision(truth, ego, ttc_cfg)
    ttc_true = float(ttc.min()) if len(ttc) else float("inf")
    res.min_ttc = min(res.min_ttc, ttc_true)
    gap = float("inf")
    if hooks.target_id and hooks.target_id in world.ids:
        k = world.index(hooks.target_id)
        rel = ego.world_to_ego_xy(world.xyz[k : k + 1, :2])[0]
        gap = float(rel[0] - (world.length[k] + ego.length) / 2)
        beside = abs(rel[1]) >= (world.width[k] + ego.width) / 2
        if not beside and gap > -world.length[k]:
            res.min_gap = min(res.min_gap, gap)
    cmd = step.command
    if cmd.aeb_stage >= 2 and not np.isfinite(res.aeb_first_time):
        res.aeb_first_time = world.time
    res.aeb_max_stage = max(res.aeb_max_stage, int(cmd.aeb_stage))
    s = res.series
    s["t"].append(world.time)
    s["ego_speed"].append(ego.speed)
    s["ego_accel_cmd"].append(cmd.accel)
    s["gap"].append(gap)
    s["ttc_true"].append(ttc_true)
    s["ttc_stack"].append(cmd.ttc)
    s["aeb_stage"].append(int(cmd.aeb_stage))
    if hooks.conflict_point is not None:
        rel = ego.world_to_ego_xy(np.array([hooks.conflict_point]))[0]
        s["conflict_distance"].append(float(rel[0] - ego.length / 2))
        if ego.speed < 0.05 and not np.isfinite(res.stop_distance) and len(s["t"]) > 1:
            res.stop_distance = s["conflict_distance"][-1]
    for ol in step.object_lists:
        _count(res.detection[ol.source], ol, world, ego, hooks.target_id)
    _count(res.detection["fusion"], step.tracks, world, ego, hooks.target_id)


def _count(
    st: DetectionStats,
    ol: ObjectList,
    world: WorldState,
    ego: EgoPose,
    target: str,
) -> None:
    st.frames += 1
    st.objects += len(ol)
    if not len(ol):
        return
    tp = ol.truth != ""
    st.true_positives += int(tp.sum())
    st.false_positives += int((~tp).sum())
    if tp.any():
        pos_world = ol.position[tp] @ ol.frame_to_world[:3, :3].T + ol.frame_to_world[:3, 3]
        rows = np.array([_row(world, t) for t in ol.truth[tp]])
        ok = rows >= 0
        err = np.linalg.norm(pos_world[ok, :2] - world.xyz[rows[ok], :2], axis=1)
        st.position_error_sum += float(err.sum())
    if target and target in set(ol.truth.tolist()):
        st.target_frames += 1
        if not np.isfinite(st.target_first_time):
            k = world.index(target)
            st.target_first_time = world.time
            st.target_first_range = float(np.hypot(*(world.xyz[k, :2] - [ego.x, ego.y])))


def _row(world: WorldState, actor_id: str) -> int:
    hits = np.flatnonzero(world.ids == actor_id)
    return int(hits[0]) if hits.size else -1
