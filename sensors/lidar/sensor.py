"""LiDAR: ray-cast scan with intensity, threshold, extinction, noise, rain ghosts and skew.

Received intensity of a return (1 = white Lambertian target at 1 m, normal incidence):
    I = [rho_d cos(theta) + rho_s / (2 s^2) exp(-2 theta^2 / s^2)] x T_atm^2 x T_soil^2 / r^2
with rho_d the diffuse reflectance, rho_s = rho_d x share / (1 - share) the specular part
(``specular`` share of DEFAULT_OPTICS) in a Gaussian lobe of width s about the mirror direction
(backscatter at incidence theta is 2 theta off the mirror direction), T_atm = exp(-a r) the
one-way extinction by rain and fog and T_soil the window transmission. Returns below the
threshold (LidarConfig.range_10pct_m) are dropped. Each column fires at its own time in the
scan, so moving targets and the moving sensor smear the cloud (scan-time skew).
"""

from __future__ import annotations

import math

import numpy as np

from hiyari.kinematics import Pose
from hiyari.net.mesh.materials import DEFAULT_OPTICS, Material
from hiyari.sensors.environment.conditions import Environment, Soiling
from hiyari.sensors.environment.soiling import soiling_mask
from hiyari.sensors.frames import Mount, sensor_to_world
from hiyari.sensors.lidar.config import LidarConfig
from hiyari.sensors.lidar.recognition import LidarRecognitionConfig, recognise_lidar
from hiyari.sensors.lidar.returns import detected_returns
from hiyari.sensors.lidar.scan_kernel import add_range_noise, return_points, scan_rays
from hiyari.sensors.outputs import HIT_NONE, ObjectList, PointCloud
from hiyari.sensors.scene.ray_scene import DirectionIndex, RayScene, SensorRays
from hiyari.traffic.world_state import WorldState

PAD_M = 0.1
"""Margin (m) on the actors' bounding spheres when picking the rays cast into the actor scene:
the ray origins and directions are float32 while the spheres are tested in float64."""


def _material_tables(lobe_rad: float) -> tuple[np.ndarray, np.ndarray]:
    """Diffuse reflectance and specular peak gain per material id (256 entries)."""
    diffuse = np.zeros(256, np.float32)
    peak = np.zeros(256, np.float32)
    for m in Material:
        o = DEFAULT_OPTICS[m]
        diffuse[m] = o.lidar
        if o.specular > 0:
            peak[m] = o.lidar * o.specular / (1.0 - o.specular) / (2.0 * lobe_rad**2)
    return diffuse, peak


class Lidar:
    """A LiDAR mounted on the ego. ``scan`` returns one PointCloud with ground truth."""

    def __init__(
        self,
        config: LidarConfig,
        mount: Mount | None = None,
        name: str = "lidar",
        recognition: LidarRecognitionConfig | None = None,
    ) -> None:
        self.config = config.validate()
        self.mount = mount or Mount(x=0.0, z=1.9)
        self.name = name
        self.recognition = recognition or LidarRecognitionConfig()
        c = config
        el = np.radians(np.asarray(c.elevations_deg, dtype=np.float64))
        fov = math.radians(c.horizontal_fov_deg)
        step = fov / c.columns
        first = math.pi if c.horizontal_fov_deg >= 360 else fov / 2 - step / 2
        az = first - step * np.arange(c.columns)  # clockwise sweep seen from above
        ce = np.cos(el)[:, None]
        dirs = np.stack(
            [
                ce * np.cos(az)[None],
                ce * np.sin(az)[None],
                np.broadcast_to(np.sin(el)[:, None], (len(el), c.columns)),
            ],
            -1,
        ).reshape(-1, 3)
        self.index = DirectionIndex.build(dirs)
        self.directions = self.index.directions
        # the ego only yaws, so rays are turned into the ego frame once and yawed per scan
        in_ego = dirs @ self.mount.sensor_to_ego()[:3, :3].T
        self._ego_x, self._ego_y, self._ego_z = (
            np.ascontiguousarray(in_ego[:, k], dtype=np.float32) for k in range(3)
        )
        self.fire_time = np.tile(np.arange(c.columns) / (c.columns * c.rate_hz), len(el)).astype(
            np.float32
        )
        self._diffuse, self._peak = _material_tables(math.radians(c.specular_lobe_deg))
        self._soil_key: Soiling | None = None
        self._soil_t2 = np.ones(len(dirs), np.float32)
        self._spot_rays = np.zeros(0, np.int64)

    @property
    def rate_hz(self) -> float:
        """Scans per second."""
        return self.config.rate_hz

    def sensor_to_world(self, ego: Pose) -> np.ndarray:
        """(4, 4) sensor-to-network transform for the ego pose."""
        return sensor_to_world(self.mount, ego)

    def sense(
        self,
        scene: RayScene,
        ego: Pose,
        world: WorldState,
        env: Environment,
        rng: np.random.Generator,
    ) -> tuple[PointCloud, ObjectList]:
        """Scan and recognise: the point cloud and its object list."""
        cloud = self.scan(scene, ego, world, env, rng)
        return cloud, recognise_lidar(cloud, self.recognition)

    def _soiling(self, soiling: Soiling) -> None:
        if soiling != self._soil_key:
            t, spot = soiling_mask(self.directions, soiling)
            self._soil_t2 = (t * t).astype(np.float32)
            self._spot_rays = np.flatnonzero(spot)
            self._soil_key = soiling

    def scan(
        self,
        scene: RayScene,
        ego: Pose,
        world: WorldState,
        env: Environment,
        rng: np.random.Generator,
    ) -> PointCloud:
        """One scan starting at ``world.time`` from the sensor on ``ego`` (points in the sensor frame)."""
        c = self.config
        scene.ensure(world)
        self._soiling(env.soiling)
        s2w = self.sensor_to_world(ego)
        rot, origin = s2w[:3, :3], s2w[:3, 3]
        rot32 = rot.astype(np.float32)
        v_ego = np.append(ego.velocity, 0.0)
        dirs_w, origins = scan_rays(
            (self._ego_x, self._ego_y, self._ego_z),
            (np.float32(np.cos(ego.heading)), np.float32(np.sin(ego.heading))),
            origin.astype(np.float32),
            v_ego.astype(np.float32),
            self.fire_time,
            bool(np.any(v_ego)),
        )
        cast_dirs = dirs_w
        if len(self._spot_rays) and env.soiling.spot_deflection_deg > 0:
            cast_dirs = dirs_w.copy()
            j = self._spot_rays
            bend = rng.normal(0.0, math.radians(env.soiling.spot_deflection_deg), (len(j), 3))
            d = dirs_w[j] + bend.astype(np.float32)
            cast_dirs[j] = d / np.linalg.norm(d, axis=1, keepdims=True)
        # the actors stand still in the scene for the whole scan (their motion is the points'
        # skew below); only the rays' origins move, by at most the ego's travel in a scan, so
        # that travel (plus PAD_M for float32 rounding) is what the actor spheres need
        pad = float(np.linalg.norm(v_ego)) / c.rate_hz + PAD_M
        hits = scene.cast(
            origins, cast_dirs, c.max_range_m, SensorRays(self.index, origin, rot, pad)
        )

        ray, r, inten = detected_returns(
            hits.hit, hits.distance, hits.material, hits.cos_incidence,
            (self._diffuse, self._peak, self._soil_t2),
            np.float32(math.radians(c.specular_lobe_deg) ** 2),
            np.float32(2.0 * c.atmosphere.lidar_extinction(env)),
            (np.float32(c.min_intensity), np.float32(c.min_range_m)),
        )  # fmt: skip
        hit = hits.hit[ray]

        if env.rain_mm_h > 0:
            ray, r, inten, hit = self._rain_ghosts(env, rng, ray, r, inten, hit)

        xyz = return_points(self.directions, ray, r)
        moving = np.flatnonzero(hit >= 0)
        if len(moving):
            v = scene.actor_velocity(hit[moving]).astype(np.float32)
            if np.any(v):
                xyz[moving] += (v @ rot32) * self.fire_time[ray[moving], None]
                r = r.copy()
                r[moving] = np.linalg.norm(xyz[moving], axis=1)
        if c.range_noise_m > 0 and len(r):
            draws = rng.standard_normal(len(r), dtype=np.float32)
            sigma, least = np.float32(c.range_noise_m), np.float32(c.min_range_m)
            r = add_range_noise(xyz, r, sigma, draws, least)
        return PointCloud(
            time=world.time,
            sensor=self.name,
            sensor_to_world=s2w,
            xyz=xyz.astype(np.float32, copy=False),
            intensity=inten,
            range=r.astype(np.float32, copy=False),
            hit=hit.astype(np.int32, copy=False),
            actor_ids=world.ids,
        )

    def _rain_ghosts(
        self,
        env: Environment,
        rng: np.random.Generator,
        ray: np.ndarray,
        r: np.ndarray,
        inten: np.ndarray,
        hit: np.ndarray,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Drop returns at 7-15 m replace (first return) or add to the real ones."""
        c = self.config
        p = min(c.rain_ghost_max_probability, c.rain_ghost_per_mm_h * env.rain_mm_h)
        n = c.rays
        ghosts = np.flatnonzero(rng.random(n, dtype=np.float32) < p)
        if not len(ghosts):
            return ray, r, inten, hit
        g_r = rng.uniform(c.rain_ghost_min_m, c.rain_ghost_max_m, len(ghosts)).astype(np.float32)
        g_i = c.min_intensity * c.rain_ghost_intensity_span ** rng.random(
            len(ghosts), dtype=np.float32
        )
        full_r = np.full(n, np.inf, np.float32)
        full_r[ray] = r
        wins = g_r < full_r[ghosts]
        ghosts, g_r, g_i = ghosts[wins], g_r[wins], g_i[wins].astype(np.float32)
        lost = np.zeros(n, bool)
        lost[ghosts] = True
        real = ~lost[ray]
        ray = np.concatenate([ray[real], ghosts])
        order = np.argsort(ray, kind="stable")
        r = np.concatenate([r[real], g_r])[order]
        inten = np.concatenate([inten[real], g_i])[order]
        hit = np.concatenate([hit[real], np.full(len(ghosts), HIT_NONE, np.int32)])[order]
        return ray[order], r, inten, hit
