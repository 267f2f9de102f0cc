"""Fusion: camera + radar and camera + LiDAR pairing, then one constant-velocity Kalman track
per object (DIVP C1: the camera gives class and bearing, radar / LiDAR give range, radar also
range rate; association by bearing and range gating). Tracks live in network coordinates so
ego motion does not smear them; the output ObjectList is in the ego frame.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import linear_sum_assignment

from hiyari.bridge.ego_pose import EgoPose, frame_points_to_ego
from hiyari.sensors.outputs import ObjectList
from hiyari.traffic.actor_class import ActorClass

#: Class-typical footprint (length, width, height, m) when a sensor does not measure size.
CLASS_SIZE = {
    -1: (4.5, 1.8, 1.5),
    ActorClass.CAR: (4.5, 1.8, 1.5),
    ActorClass.TRUCK: (8.0, 2.5, 3.2),
    ActorClass.BUS: (12.0, 2.5, 3.2),
    ActorClass.MOTORCYCLE: (2.2, 0.9, 1.5),
    ActorClass.BICYCLE: (1.8, 0.65, 1.7),
    ActorClass.PEDESTRIAN: (0.5, 0.5, 1.7),
}


@dataclass(frozen=True)
class FusionConfig:
    """Association gates, noise and track management (toolkit defaults, MODELS.md §4)."""

    gate_bearing_deg: float = 3.0  # camera-to-ranging bearing gate
    gate_range_frac: float = 0.35  # camera range error allowed, fraction of range
    gate_range_min_m: float = 3.0
    gate_chi2: float = 13.8  # track gate, chi-square 2 dof at 99.9 %
    accel_noise: float = 2.0  # m/s^2, white-acceleration process noise (manoeuvring targets)
    sigma_pos: dict[str, float] = field(
        default_factory=lambda: {"truth": 0.02, "lidar": 0.10, "radar": 0.30, "camera": 0.5}
    )
    camera_range_sigma_frac: float = 0.10  # camera-only range sigma, fraction of range
    confirm_hits: int = 2
    max_age_s: float = 0.5  # drop a track not updated for this long
    use_unpaired_camera: bool = True  # camera-only objects (camera range) become tracks


@dataclass
class _Track:
    tid: int
    x: np.ndarray  # (4,) x, y, vx, vy in the network frame
    p: np.ndarray  # (4, 4)
    t: float
    hits: int
    cls: int
    size: tuple[float, float, float]
    truth: str
    last_update: float


@dataclass
class _Meas:
    xy: np.ndarray  # (M, 2) network frame
    sigma: np.ndarray  # (M, 2) std along (range, cross-range) approximated as isotropic x/y
    vel: np.ndarray  # (M, 2) network-frame absolute velocity or nan
    cls: np.ndarray  # (M,)
    size: np.ndarray  # (M, 3) nan when unknown
    truth: np.ndarray  # (M,) object


class KalmanFusion:
    """Pairs camera with ranging sensors, then tracks with a constant-velocity Kalman filter."""

    def __init__(self, config: FusionConfig | None = None) -> None:
        self.config = config or FusionConfig()
        self._tracks: list[_Track] = []
        self._next_id = 1

    def update(self, lists: list[ObjectList], ego: EgoPose, time: float) -> ObjectList:
        """Fuse this step's object lists (any sensors); return confirmed tracks, ego frame."""
        for tr in self._tracks:
            self._predict(tr, time)
        meas = self._measurements(lists, ego)
        if meas is not None and len(meas.xy):
            self._associate(meas, time)
        cfg = self.config
        self._tracks = [t for t in self._tracks if time - t.last_update <= cfg.max_age_s]
        return self._output(ego, time)

    # ---------------------------------------------------------------- measurements
    def _measurements(self, lists: list[ObjectList], ego: EgoPose) -> _Meas | None:
        cfg = self.config
        cams = [ol for ol in lists if ol.source == "camera" and len(ol)]
        ranging = [ol for ol in lists if ol.source != "camera" and len(ol)]
        rows: list[tuple] = []  # (xy_ego, sigma, vel_rel_ego or nan, cls, size, truth)
        rng_pts = []
        for ol in ranging:
            xy = frame_points_to_ego(ol.frame_to_world, ol.position, ego)
            vel = _vel_to_ego(ol, ego)
            s = cfg.sigma_pos.get(ol.source, 0.3)
            for k in range(len(ol)):
                rng_pts.append([xy[k], s, vel[k], int(ol.cls[k]), ol.size[k], ol.truth[k], False])
        for ol in cams:
            xy = frame_points_to_ego(ol.frame_to_world, ol.position, ego)
            for k in range(len(ol)):
                r_cam = float(np.hypot(*xy[k]))
                b_cam = float(np.arctan2(xy[k, 1], xy[k, 0]))
                best, best_d = None, np.inf
                for j, rp in enumerate(rng_pts):
                    r = float(np.hypot(*rp[0]))
                    db = abs(_wrap(np.arctan2(rp[0][1], rp[0][0]) - b_cam))
                    dr = abs(r - r_cam)
                    gate_r = max(cfg.gate_range_min_m, cfg.gate_range_frac * r_cam)
                    if db <= np.radians(cfg.gate_bearing_deg) and dr <= gate_r and dr < best_d:
                        best, best_d = j, dr
                if best is not None:
                    rp = rng_pts[best]
                    r = float(np.hypot(*rp[0]))
                    # range from the ranging sensor along the camera's bearing
                    rp[0] = np.array([r * np.cos(b_cam), r * np.sin(b_cam)])
                    rp[3] = int(ol.cls[k])
                    rp[6] = True
                    if not rp[5]:
                        rp[5] = ol.truth[k]
                elif cfg.use_unpaired_camera:
                    sig = max(cfg.sigma_pos["camera"], cfg.camera_range_sigma_frac * r_cam)
                    rows.append(
                        (xy[k], sig, np.full(2, np.nan), int(ol.cls[k]), ol.size[k], ol.truth[k])
                    )
        rows += [(rp[0], rp[1], rp[2], rp[3], rp[4], rp[5]) for rp in rng_pts]
        if not rows:
            return None
        xy_ego = np.array([r[0] for r in rows], dtype=float)
        world = xy_ego @ np.array(
            [
                [np.cos(ego.heading), np.sin(ego.heading)],
                [-np.sin(ego.heading), np.cos(ego.heading)],
            ]
        ) + [ego.x, ego.y]
        vel_rel = np.array([r[2] for r in rows], dtype=float)
        c, s = np.cos(ego.heading), np.sin(ego.heading)
        vel_abs = (
            np.stack(
                [vel_rel[:, 0] * c - vel_rel[:, 1] * s, vel_rel[:, 0] * s + vel_rel[:, 1] * c], 1
            )
            + ego.velocity
        )
        return _Meas(
            xy=world,
            sigma=np.array([r[1] for r in rows], dtype=float),
            vel=vel_abs,
            cls=np.array([r[3] for r in rows]),
            size=np.array([r[4] for r in rows], dtype=float).reshape(-1, 3),
            truth=np.array([r[5] for r in rows], dtype=object),
        )

    # ---------------------------------------------------------------- tracking
    def _predict(self, tr: _Track, time: float) -> None:
        dt = time - tr.t
        if dt <= 0:
            return
        f = np.eye(4)
        f[0, 2] = f[1, 3] = dt
        q = self.config.accel_noise**2
        g = np.array([[dt**2 / 2, 0], [0, dt**2 / 2], [dt, 0], [0, dt]])
        tr.x = f @ tr.x
        tr.p = f @ tr.p @ f.T + q * g @ g.T
        tr.t = time

    def _associate(self, m: _Meas, time: float) -> None:
        cfg = self.config
        nt, nm = len(self._tracks), len(m.xy)
        cost = np.full((nt, nm), 1e6)
        for i, tr in enumerate(self._tracks):
            s = tr.p[:2, :2] + np.eye(2)[None] * (m.sigma**2)[:, None, None]
            d = m.xy - tr.x[:2]
            maha = np.einsum("mi,mij,mj->m", d, np.linalg.inv(s), d)
            cost[i] = np.where(maha <= cfg.gate_chi2, maha, 1e6)
        used_m: set[int] = set()
        if nt:
            ri, ci = linear_sum_assignment(cost)
            for i, j in zip(ri, ci, strict=True):
                if cost[i, j] < 1e6:
                    self._update(self._tracks[i], m, j, time)
                    used_m.add(int(j))
        for j in range(nm):
            if j not in used_m:
                self._spawn(m, j, time)

    def _update(self, tr: _Track, m: _Meas, j: int, time: float) -> None:
        has_vel = bool(np.all(np.isfinite(m.vel[j])))
        h = np.eye(4) if has_vel else np.eye(4)[:2]
        z = np.concatenate([m.xy[j], m.vel[j]]) if has_vel else m.xy[j]
        r = np.diag([m.sigma[j] ** 2] * 2 + ([0.3**2] * 2 if has_vel else []))
        s = h @ tr.p @ h.T + r
        k = tr.p @ h.T @ np.linalg.inv(s)
        tr.x = tr.x + k @ (z - h @ tr.x)
        tr.p = (np.eye(4) - k @ h) @ tr.p
        tr.hits += 1
        tr.last_update = time
        if m.cls[j] >= 0:
            tr.cls = int(m.cls[j])
        if np.all(np.isfinite(m.size[j])):
            tr.size = tuple(m.size[j])
        if m.truth[j]:
            tr.truth = m.truth[j]

    def _spawn(self, m: _Meas, j: int, time: float) -> None:
        has_vel = bool(np.all(np.isfinite(m.vel[j])))
        x = np.concatenate([m.xy[j], m.vel[j] if has_vel else np.zeros(2)])
        p = np.diag([m.sigma[j] ** 2] * 2 + ([0.5**2] * 2 if has_vel else [10.0**2] * 2))
        cls = int(m.cls[j])
        size = (
            tuple(m.size[j])
            if np.all(np.isfinite(m.size[j]))
            else CLASS_SIZE.get(cls, CLASS_SIZE[-1])
        )
        self._tracks.append(_Track(self._next_id, x, p, time, 1, cls, size, m.truth[j], time))
        self._next_id += 1

    def _output(self, ego: EgoPose, time: float) -> ObjectList:
        tracks = [t for t in self._tracks if t.hits >= self.config.confirm_hits]
        if not tracks:
            return ObjectList.empty(time, "fusion", ego.to_world())
        xs = np.array([t.x for t in tracks])
        pos = np.zeros((len(tracks), 3))
        pos[:, :2] = ego.world_to_ego_xy(xs[:, :2])
        vel = np.zeros((len(tracks), 3))
        vel[:, :2] = ego.world_to_ego_vec(xs[:, 2:] - ego.velocity)
        return ObjectList(
            time=time,
            source="fusion",
            frame_to_world=ego.to_world(),
            object_id=np.array([t.tid for t in tracks], np.int64),
            cls=np.array([t.cls for t in tracks], np.int8),
            position=pos,
            velocity=vel,
            size=np.array([t.size for t in tracks], dtype=float),
            confidence=np.array([min(1.0, t.hits / 5) for t in tracks]),
            truth=np.array([t.truth for t in tracks], dtype=object),
        )


def _wrap(a: float) -> float:
    return (a + np.pi) % (2 * np.pi) - np.pi


def _vel_to_ego(ol: ObjectList, ego: EgoPose) -> np.ndarray:
    """Relative velocities of an object list -> ego axes (nan rows stay nan)."""
    v = np.asarray(ol.velocity, dtype=float)[:, :3]
    rot = ol.frame_to_world[:3, :3]
    world = v @ rot.T
    return ego.world_to_ego_vec(world[:, :2])
