"""The closed loop: SUMO step -> WorldState -> ego stack -> ego speed back into SUMO.

One run of a scripted scenario or of free traffic. Ground-truth metrics (true TTC, gap to the
scenario's target, collisions) come from the WorldState through hiyari.risk.metrics.ground_truth,
never from the stack's own beliefs.
"""

from __future__ import annotations

import time as wallclock
from collections.abc import Callable

import numpy as np

from hiyari.bridge.loop.result import DetectionStats, RunResult
from hiyari.bridge.loop.stack.interfaces import EgoStack, EgoStep
from hiyari.kinematics import Pose
from hiyari.risk.metrics.clearance import near_miss_time
from hiyari.risk.metrics.ground_truth import TruthConfig, gap_to, path_headway, time_to_collision
from hiyari.risk.metrics.visibility import in_line_of_sight
from hiyari.sensors.outputs import ObjectList
from hiyari.traffic.collision import Collision
from hiyari.traffic.simulation import Simulation
from hiyari.traffic.world_state import WorldState

#: Called after every stack step with (world, ego step, this step's collisions).
OnStep = Callable[[WorldState, EgoStep, list[Collision]], None]
#: Called after every scored step with (result so far, world, ego row, seconds left): True when
#: nothing still to simulate can change the judged values (bridge.scenario.decided).
Decided = Callable[[RunResult, WorldState, int, float], bool]


class ScenarioHooks:
    """What a scenario script supplies to the loop (all optional)."""

    ego_id: str = "ego"
    target_id: str = ""
    conflict_point: tuple[float, float] | None = None  # network x, y of the conflict point
    #: whether the run has a disturbance whose start :meth:`disturbance_started` reports
    #: (read after the run; hiyari.risk.metrics.tested: without one, a run is tested from
    #: its start)
    has_disturbance: bool = False

    def disturbance_started(self) -> bool:
        """True once the scenario's disturbance has started (on the state just reached)."""
        return False

    def before_step(self, sim: Simulation, script_time: float) -> None:
        """Move scripted actors for the coming step."""

    def script_time(self, sim_time: float) -> float:
        return sim_time

    def done(self, world: WorldState, ego: Pose, script_time: float) -> bool:
        """True when the scenario has played out (besides duration and collisions)."""
        return False

    def after_step(self, sim: Simulation, world: WorldState) -> bool:
        """Advance the scenario on the state SUMO just reached (triggers, actors for the next
        step); True when it has ended (its stop trigger): the loop still scores this state."""
        return False

    def stack_drives_ego(self) -> bool:
        """Whether the ego stack's command moves the ego now (else the scenario does)."""
        return True

    def ego_lane_scripted(self) -> bool:
        """Whether the scenario itself moves the ego across lanes now (its storyboard drives
        the ego, or it commanded a lane change): a lane change then is not the system
        leaving its lane (hiyari.risk.metrics.tested)."""
        return not self.stack_drives_ego()

    def sensed(self, world: WorldState) -> WorldState:
        """The world as the ego's sensors may see it (a scenario may hide entities)."""
        return world

    def drive_ego(self, sim: Simulation, ego_id: str, speed: float) -> None:
        """Apply the stack's ``speed`` (m/s) to the ego for the next step: SUMO drives it on
        its route (a scenario may steer it along its own path instead)."""
        sim.set_speed(ego_id, speed)

    def gap_target(self, world: WorldState, row: int) -> int:
        """Row of the actor whose bumper gap is scored (-1: none): the scenario's target."""
        if self.target_id and self.target_id in world.ids:
            return world.index(self.target_id)
        return -1


def run_closed_loop(
    sim: Simulation,
    stack: EgoStack,
    hooks: ScenarioHooks,
    duration: float,
    label: str = "",
    on_step: OnStep | None = None,
    progress: bool = False,
    decided: Decided | None = None,
    open_ended: bool = False,
) -> RunResult:
    """Run until ``duration`` (s of simulation time from now), a collision, ``hooks.done`` or
    ``decided`` (when given).

    ``on_step(world, ego_step, collisions)`` is called after every stack step (recording,
    custom metrics). ``open_ended``: the run usually ends before ``duration`` (a stop
    trigger), so the progress bar counts steps without a total and ends full.
    """
    from tqdm import tqdm

    res = RunResult(label=label)
    lanes = _LaneWatch()
    truth = TruthConfig()
    dt = sim.config.step_length
    t_end = sim.time + duration
    n_steps = int(round(duration / dt))
    t0 = wallclock.perf_counter()
    total = None if open_ended else n_steps
    bar = tqdm(total=total, unit="step", disable=not progress, desc=label[:30] or "run")
    ego_id = hooks.ego_id
    try:
        while sim.time < t_end - 1e-9:
            hooks.before_step(sim, hooks.script_time(sim.time + dt))
            world = sim.step()
            bar.update(1)
            ended = hooks.after_step(sim, world)
            if not np.isfinite(res.disturbance_time) and hooks.disturbance_started():
                res.disturbance_time = world.time
            if ego_id not in world.ids:
                if ended:
                    break
                if res.sim_seconds > 0:
                    break  # the ego left the network
                continue
            row = world.index(ego_id)
            sensed = hooks.sensed(world)
            step = stack.step(sensed, sensed.index(ego_id) if sensed is not world else row)
            ego = world.pose(row)
            _metrics(res, world, row, ego, step, hooks, truth)
            lanes.update(res, world, row, scripted=hooks.ego_lane_scripted())
            if on_step is not None:
                on_step(world, step, sim.collisions)
            # contact is overlapping outlines: SUMO's own check is per lane without sublanes,
            # so an actor beside the ego but assigned its lane would count as hit (in the
            # steep R157 cut-ins it reports contact with the outlines 2.1 m apart)
            hit = [c for c in sim.collisions if ego_id in (c.a, c.b) and c.depth > 0.0]
            if hit:
                other = hit[0].b if hit[0].a == ego_id else hit[0].a
                res.collision, res.collided_with, res.collision_time = True, other, world.time
                res.impact_speed = ego.speed
                k = world.index(other)
                rel = world.velocity[row] - world.velocity[k]
                res.relative_impact_speed = float(np.linalg.norm(rel))
                break
            if ended:
                res.stop_trigger = True
                break
            if hooks.stack_drives_ego():
                hooks.drive_ego(sim, ego_id, max(0.0, ego.speed + step.command.accel * dt))
            res.sim_seconds = world.time
            if hooks.done(world, ego, hooks.script_time(world.time)):
                break
            if decided is not None and decided(res, world, row, t_end - world.time):
                break
    finally:
        if open_ended:
            bar.total = bar.n  # the run's own end
            bar.refresh()
        bar.close()
    res.wall_seconds = wallclock.perf_counter() - t0
    res.has_disturbance = hooks.has_disturbance  # known once the acts that ran are known
    if len(res.series):
        res.final_speed = res.series.ego_speed[-1]
        res.sim_seconds = res.series.t[-1] - res.series.t[0] + dt
    return res


def _metrics(
    res: RunResult,
    world: WorldState,
    row: int,
    ego: Pose,
    step: EgoStep,
    hooks: ScenarioHooks,
    truth: TruthConfig,
) -> None:
    xy = world.xyz[:, :2]
    ttc = time_to_collision(xy, world.heading, world.speed, world.length, world.width, row, truth)
    ttc_true = float(ttc.min())
    headway = path_headway(xy, world.heading, world.speed, world.length, world.width, row, truth)
    near_miss = near_miss_time(
        xy, world.heading, world.speed, world.length, world.width, world.cls, row,
        res.clearances.rule, truth,
    )  # fmt: skip
    res.min_ttc = min(res.min_ttc, ttc_true)
    gap = float("inf")
    k = hooks.gap_target(world, row)
    if k >= 0:
        gap, beside = gap_to(xy, world.heading, world.length, world.width, row, k)
        if beside < 0 and gap > -world.length[k]:
            res.min_gap = min(res.min_gap, gap)
        if not np.isfinite(res.target_sight_time) and in_line_of_sight(
            xy, world.heading, world.length, world.width, row, k
        ):
            res.target_sight_time = world.time
            res.target_sight_range = float(np.hypot(*(xy[k] - xy[row])))
    res.clearances.update(
        world.time, world.ids, world.cls, xy, world.heading, world.length, world.width, row,
        ego.speed,
    )  # fmt: skip
    cmd = step.command
    # any stage reached has its time: aeb_max_stage > 0 exactly when aeb_first_time is set
    if cmd.aeb_stage >= 1 and not np.isfinite(res.aeb_first_time):
        res.aeb_first_time = world.time
    if cmd.aeb_stage >= 2 and not np.isfinite(res.aeb_brake_time):
        res.aeb_brake_time = world.time
    res.aeb_max_stage = max(res.aeb_max_stage, int(cmd.aeb_stage))
    s = res.series
    s.t.append(world.time)
    s.ego_speed.append(ego.speed)
    s.ego_accel_cmd.append(cmd.accel)
    s.gap.append(gap)
    s.ttc_true.append(ttc_true)
    s.headway_true.append(headway)
    s.near_miss_true.append(near_miss)
    s.ttc_stack.append(cmd.ttc)
    s.aeb_stage.append(int(cmd.aeb_stage))
    s.aeb_decel.append(cmd.aeb_decel)
    if hooks.conflict_point is not None:
        rel = ego.world_to_vehicle(np.array(hooks.conflict_point, dtype=float))
        s.conflict_distance.append(float(rel[0] - ego.length / 2))
        if ego.speed < 0.05 and not np.isfinite(res.stop_distance) and len(s) > 1:
            res.stop_distance = s.conflict_distance[-1]
    for ol in step.object_lists:
        _count(res.detection[ol.source], ol, world, ego, hooks.target_id)
    _count(res.detection["fusion"], step.tracks, world, ego, hooks.target_id)


class _LaneWatch:
    """Sets ``RunResult.lane_left_time`` at the ego's first change of lane within an edge
    (moving on to the next edge along its route, or through a junction's internal lanes, is
    following the lane, not leaving it)."""

    def __init__(self) -> None:
        self.edge, self.lane = "", ""

    def update(self, res: RunResult, world: WorldState, row: int, scripted: bool = False) -> None:
        """``scripted``: the scenario moves the ego across lanes now (not counted)."""
        edge, lane = str(world.edge[row]), str(world.lane[row])
        if not lane or edge.startswith(":"):
            return
        changed = edge == self.edge and lane != self.lane
        if changed and not scripted and not np.isfinite(res.lane_left_time):
            res.lane_left_time = world.time
        self.edge, self.lane = edge, lane


def _count(
    st: DetectionStats,
    ol: ObjectList,
    world: WorldState,
    ego: Pose,
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
        rows = world.rows(ol.truth[tp])
        ok = rows >= 0
        err = np.linalg.norm(pos_world[ok, :2] - world.xyz[rows[ok], :2], axis=1)
        st.position_error_sum += float(err.sum())
    if target and target in set(ol.truth.tolist()):
        st.target_frames += 1
        if not np.isfinite(st.target_first_time):
            k = world.index(target)
            st.target_first_time = world.time
            st.target_first_range = float(np.hypot(*(world.xyz[k, :2] - [ego.x, ego.y])))
