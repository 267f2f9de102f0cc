"""The competent and careful (C&C) driver as a reference ego in the closed loop, for catalogue
cases outside the three Annex G types that hiyari.risk.cc evaluates in closed form.

The same rules as the C&C model (JAMA 2.3.3.1, docs/models.md §1), generalised from the ego's
view of the ground truth: an object is *judged* when it enters the ego's lane corridor (its
side reaches ``wander_m`` inside the corridor edge, moving inward), when a vehicle ahead in the
corridor starts braking, or when an object in the corridor comes within ``ttc_brake_s``; danger
judgement follows ``perception_time_s`` later. The reaction starts there (``above_ttc="end"``,
the default: the closed form counts a cut-in still ``ttc_brake_s`` away at danger judgement as
not critical, and a careful driver who sees a car cutting in ahead reacts to it), or, with
``above_ttc="wait"``, not before an object entering or in the corridor comes within
``ttc_brake_s`` (a braking lead needs no TTC). Braking force follows ``reaction_delay_s``
later, a linear ramp to ``max_decel_g`` over ``ramp_time_s``, held while the ego still closes
on an object in its corridor. Before that the driver holds its speed (Annex G's C&C does not
follow with an ACC). The generalisation to rear, adjacent and lane-changing cases is ours.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from hiyari.bridge.loop.stack.aeb import AEBStage, EgoCommand
from hiyari.bridge.loop.stack.fusion import KalmanFusion
from hiyari.bridge.loop.stack.interfaces import EgoStack
from hiyari.bridge.loop.stack.perception_truth import PerfectPerception
from hiyari.kinematics import Pose
from hiyari.risk.cc.model import CCParams
from hiyari.sensors.outputs import ObjectList

#: Deceleration of a vehicle ahead (m/s^2) that counts as its brake onset.
BRAKE_ONSET = 1.0


@dataclass
class CCReferencePlanner:
    """The C&C driver as a planner (see the module doc). Stateful per run."""

    params: CCParams = field(default_factory=CCParams)
    _judged: float = math.inf  # s: the first judgement
    _critical: float = math.inf  # s: first object within ttc_brake_s (or a braking lead)
    _last_speed: dict[str, tuple[float, float]] = field(default_factory=dict)

    def _corridor(self, tracks: ObjectList) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(N,) lateral intrusion into the ego's corridor (m), longitudinal clear gap (m),
        closing speed (m/s) for each track."""
        p = self.params
        x, y = tracks.position[:, 0], tracks.position[:, 1]
        half_l = 0.5 * np.nan_to_num(tracks.size[:, 0], nan=p.other_length_m)
        half_w = 0.5 * np.nan_to_num(tracks.size[:, 1], nan=p.other_width_m)
        edge = 0.5 * p.lane_width_m
        intrusion = edge - (np.abs(y) - half_w)
        gap = x - half_l - 0.5 * p.ego_length_m
        closing = -np.nan_to_num(tracks.velocity[:, 0])
        return intrusion, gap, closing

    def _judge(self, tracks: ObjectList, ego: Pose, time: float) -> tuple[bool, bool]:
        """(judged, critical) at ``time``: an object enters the corridor, a vehicle in it
        brakes, or one in it is within ``ttc_brake_s``; critical: an entering or in-path
        object within ``ttc_brake_s``, or a braking one in the path."""
        p = self.params
        intrusion, gap, closing = self._corridor(tracks)
        ahead = gap > -0.5 * p.ego_length_m
        vy_in = -np.sign(tracks.position[:, 1]) * np.nan_to_num(tracks.velocity[:, 1])
        entering = ahead & (intrusion >= p.wander_m) & (vy_in > 0.05) & (closing > -1.0)
        in_path = ahead & (intrusion > 0) & (gap > -1.0)
        ttc = np.where(closing > 0, gap / np.maximum(closing, 1e-9), np.inf)
        braking = np.zeros(len(tracks), bool)
        for i, truth in enumerate(tracks.truth):
            v_abs = float(np.nan_to_num(tracks.velocity[i, 0])) + ego.speed
            prev = self._last_speed.get(str(truth))
            if prev is not None and time > prev[0]:
                braking[i] = (prev[1] - v_abs) / (time - prev[0]) > BRAKE_ONSET
            self._last_speed[str(truth)] = (time, v_abs)
        near = ttc < p.ttc_brake_s
        urgent = in_path & near
        judged = bool(entering.any() or (in_path & braking).any() or urgent.any())
        critical = bool(((entering | in_path) & near).any() or (in_path & braking).any())
        return judged, critical

    def reaction_time(self) -> float:
        """When the reaction delay starts (s; inf before any judgement)."""
        p = self.params
        danger = self._judged + p.perception_time_s
        return max(danger, self._critical) if p.above_ttc == "wait" else danger

    def plan(self, tracks: ObjectList, ego: Pose, time: float) -> EgoCommand:
        """The C&C driver's acceleration at ``time`` (m/s^2, negative: braking)."""
        p = self.params
        if len(tracks) and (math.isinf(self._judged) or math.isinf(self._critical)):
            judged, critical = self._judge(tracks, ego, time)
            if judged and math.isinf(self._judged):
                self._judged = time
            if critical and math.isinf(self._critical):
                self._critical = time
        t_force = self.reaction_time() + p.reaction_delay_s
        accel = 0.0
        if time >= t_force:
            intrusion, gap, closing = self._corridor(tracks)
            closing_any = bool(((intrusion > 0) & (gap > -1.0) & (closing > 0.05)).any())
            if closing_any and ego.speed > 0.05:
                ramp = min(1.0, (time - t_force) / p.ramp_time_s)
                accel = -ramp * p.max_decel_g * p.g_mps2
        stage = AEBStage.OFF if accel == 0.0 else AEBStage.FULL
        return EgoCommand(time, accel, 0.0, stage, -accel, math.inf, "")


def cc_reference_stack(_ctx: object = None) -> EgoStack:
    """Perfect perception + tracks + the C&C reference planner (a StackFactory)."""
    return EgoStack(PerfectPerception(), KalmanFusion(), CCReferencePlanner())
