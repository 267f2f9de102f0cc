"""Radar: ray-cast returns, radar equation, resolution cells, CFAR threshold, ghosts.

Each ray that hits something carries a share of a cross-section: an actor's class-and-aspect
RCS split evenly over the rays that hit it, or for static surfaces the material's RCS per m^2
times the ray's footprint r^2 dOmega cos(theta). Received power of a ray is
    P = P_t G_t G_r lambda^2 sigma g(az, el) / ((4 pi)^3 L r^4) x 10^(-2 a r / 10) x T_soil^2
(g the two-way antenna pattern, a the one-way rain/fog attenuation in dB/m). Rays falling in
the same range x range-rate x azimuth cell add up; a cell whose SNR passes the threshold is a
detection at its power-weighted position, with noise shrinking as 1/sqrt(SNR).
"""

from __future__ import annotations

import math

import numpy as np

from hiyari.kinematics import Pose, footprint_extent
from hiyari.net.mesh.materials import DEFAULT_OPTICS, Material
from hiyari.sensors.environment.conditions import Environment, Soiling
from hiyari.sensors.environment.soiling import soiling_mask
from hiyari.sensors.frames import Mount, sensor_to_world
from hiyari.sensors.outputs import HIT_NONE, HIT_STATIC, ObjectList, RadarDetections
from hiyari.sensors.radar.config import RadarConfig
from hiyari.sensors.radar.recognition import RadarRecognitionConfig, recognise_radar
from hiyari.sensors.scene.ray_scene import DirectionIndex, Hits, RayScene, SensorRays
from hiyari.traffic.actor_class import ActorClass
from hiyari.traffic.world_state import WorldState

MIN_RANGE_M = 0.1
"""Returns closer than this are the sensor's own housing, not targets."""


class Radar:
    """A radar mounted on the ego. ``scan`` returns one cycle of RadarDetections."""

    def __init__(
        self,
        config: RadarConfig,
        mount: Mount | None = None,
        name: str = "radar",
        recognition: RadarRecognitionConfig | None = None,
    ) -> None:
        self.config = config.validate()
        self.mount = mount or Mount(x=2.3, z=0.5)
        self.name = name
        self.recognition = recognition or RadarRecognitionConfig()
        c = config
        nh = int(round(c.h_fov_deg / c.h_step_deg)) + 1
        nv = int(round(c.v_fov_deg / c.v_step_deg)) + 1
        az = np.radians(np.linspace(-c.h_fov_deg / 2, c.h_fov_deg / 2, nh))
        el = np.radians(np.linspace(-c.v_fov_deg / 2, c.v_fov_deg / 2, nv))
        a, e = np.meshgrid(az, el)
        a, e = a.ravel(), e.ravel()
        dirs = np.stack([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)], 1)
        self.index = DirectionIndex.build(dirs)
        self.directions = self.index.directions
        self.azimuth = a
        self.elevation = e
        self.solid_angle = math.radians(c.h_step_deg) * math.radians(c.v_step_deg) * np.cos(e)
        pattern_db = -10.0 * (
            (np.degrees(a) / c.azimuth_10db_deg) ** 2 + (np.degrees(e) / c.elevation_10db_deg) ** 2
        )
        self.pattern = 10 ** (2 * pattern_db / 10)  # transmit and receive
        self._rcs_m2 = np.array(
            [DEFAULT_OPTICS[m].radar_rcs_m2 for m in Material] + [0.0] * (256 - len(Material))
        )
        self._soil_key: Soiling | None = None
        self._soil_t2 = np.ones(len(dirs))
        self._spot = np.zeros(len(dirs), bool)

    @property
    def rate_hz(self) -> float:
        """Cycles per second."""
        return self.config.rate_hz

    def sensor_to_world(self, ego: Pose) -> np.ndarray:
        """(4, 4) sensor-to-network transform for the ego pose."""
        return sensor_to_world(self.mount, ego)

    def actor_rcs_m2(
        self, world: WorldState, rows: np.ndarray, sensor_xyz: np.ndarray
    ) -> np.ndarray:
        """(n,) RCS of actors at ``rows`` seen from ``sensor_xyz``, m^2 (class and aspect)."""
        rcs = self.config.rcs
        to_radar = sensor_xyz[:2] - world.xyz[rows, :2]
        phi = np.arctan2(to_radar[:, 1], to_radar[:, 0]) - world.heading[rows]
        c2, s2 = np.cos(phi) ** 2, np.sin(phi) ** 2
        cls = [ActorClass(k) for k in world.cls[rows]]
        front = np.array([rcs.front_dbsm[k] for k in cls])
        side = np.array([rcs.side_dbsm[k] for k in cls])
        rear = np.array([rcs.rear_dbsm[k] for k in cls])
        db = np.where(np.cos(phi) >= 0, front, rear) * c2 + side * s2
        return 10 ** (db / 10)

    def sense(
        self,
        scene: RayScene,
        ego: Pose,
        world: WorldState,
        env: Environment,
        rng: np.random.Generator,
    ) -> tuple[RadarDetections, ObjectList]:
        """Scan and recognise: the detections and their object list."""
        det = self.scan(scene, ego, world, env, rng)
        return det, recognise_radar(det, self.recognition, self.config.snr_threshold_db)

    def _rays_on_silhouette(
        self, world: WorldState, rows: np.ndarray, sensor_xyz: np.ndarray
    ) -> np.ndarray:
        """(n,) number of grid rays an unoccluded actor would intercept (its silhouette area
        over the ray footprint r^2 d_az d_el)."""
        c = self.config
        to = world.xyz[rows, :2] - sensor_xyz[:2]
        dist = np.maximum(np.linalg.norm(to, axis=1), 0.5)
        phi = np.arctan2(to[:, 1], to[:, 0]) - world.heading[rows]
        _, half_across = footprint_extent(world.length[rows], world.width[rows], phi)
        across = 2.0 * half_across  # the footprint's width across the line of sight
        footprint = dist**2 * math.radians(c.h_step_deg) * math.radians(c.v_step_deg)
        return across * world.height[rows] / footprint

    def _soiling(self, soiling: Soiling) -> None:
        if soiling != self._soil_key:
            t, self._spot = soiling_mask(self.directions, soiling)
            self._soil_t2 = t * t
            self._soil_key = soiling

    def scan(
        self,
        scene: RayScene,
        ego: Pose,
        world: WorldState,
        env: Environment,
        rng: np.random.Generator,
    ) -> RadarDetections:
        """One radar cycle at ``world.time`` from the sensor on ``ego``."""
        c = self.config
        scene.ensure(world)
        self._soiling(env.soiling)
        s2w = self.sensor_to_world(ego)
        rot, origin = s2w[:3, :3], s2w[:3, 3]
        dirs_w = (self.directions.astype(np.float64) @ rot.T).astype(np.float32)
        origins = np.empty_like(dirs_w)
        origins[:] = origin.astype(np.float32)
        rays = SensorRays(self.index, origin, rot)
        hits = scene.cast(origins, dirs_w, c.max_range_m, rays, normals=c.multipath)
        v_sensor = np.append(ego.velocity, 0.0)

        ray = np.flatnonzero((hits.hit != HIT_NONE) & (hits.distance > MIN_RANGE_M))
        r = hits.distance[ray].astype(np.float64)
        hit = hits.hit[ray]
        sigma = (
            self._rcs_m2[hits.material[ray]]
            * r**2
            * self.solid_angle[ray]
            * hits.cos_incidence[ray]
        )
        vel = np.zeros((len(ray), 3))
        on_actor = np.flatnonzero(hit >= 0)
        if len(on_actor):
            rows, per_row = np.unique(hit[on_actor], return_counts=True)
            # an actor's RCS is shared by the rays its whole silhouette would catch, so that
            # occluded or out-of-view parts take their share of the echo with them
            expected = self._rays_on_silhouette(world, rows, origin)
            share = self.actor_rcs_m2(world, rows, origin) / np.maximum(per_row, expected)
            where = np.searchsorted(rows, hit[on_actor])
            sigma[on_actor] = share[where]
            vel[on_actor] = scene.actor_velocity(hit[on_actor])
        u = dirs_w[ray].astype(np.float64)
        rr = ((vel - v_sensor) * u).sum(1)
        az, el = self.azimuth[ray].copy(), self.elevation[ray]
        weight = self.pattern[ray] * self._soil_t2[ray]
        if self._spot[ray].any():
            spot = np.flatnonzero(self._spot[ray])
            az[spot] += rng.normal(0.0, math.radians(env.soiling.spot_deflection_deg), len(spot))
        if c.multipath:
            extra = self._multipath(scene, world, hits, ray, origins, dirs_w, origin, v_sensor)
            if extra is not None:
                r_g, sig_g, rr_g, idx_g = extra
                r = np.concatenate([r, r_g])
                sigma = np.concatenate([sigma, sig_g])
                rr = np.concatenate([rr, rr_g])
                az = np.concatenate([az, self.azimuth[idx_g]])
                el = np.concatenate([el, self.elevation[idx_g]])
                weight = np.concatenate([weight, self.pattern[idx_g] * self._soil_t2[idx_g]])
                hit = np.concatenate([hit, np.full(len(r_g), HIT_NONE, np.int32)])
        atten_db = c.atmosphere.radar_attenuation_db_per_m(env)
        power = c.radar_constant * sigma * weight / r**4 * 10 ** (-2 * atten_db * r / 10)
        return self._detect(world, s2w, r, rr, az, el, power, hit, rng)

    def _multipath(
        self,
        scene: RayScene,
        world: WorldState,
        hits: Hits,
        ray: np.ndarray,
        origins: np.ndarray,
        dirs_w: np.ndarray,
        origin: np.ndarray,
        v_sensor: np.ndarray,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None:
        """Ghosts: sensor -> wall -> actor -> wall -> sensor, seen behind the wall point."""
        c = self.config
        mats = np.array([int(m) for m in c.multipath_materials], np.uint8)
        wall = ray[np.isin(hits.material[ray], mats) & (hits.hit[ray] == HIT_STATIC)]
        if not len(wall):
            return None
        d = dirs_w[wall]
        n = hits.normal[wall]
        p = origins[wall] + d * hits.distance[wall, None]
        refl = d - 2 * (d * n).sum(1, keepdims=True) * n
        start = (p + n * 0.05).astype(np.float32)
        sec = scene.cast(start, refl.astype(np.float32), c.max_range_m)
        on = np.flatnonzero(sec.hit >= 0)
        if not len(on):
            return None
        rows, per_row = np.unique(sec.hit[on], return_counts=True)
        where = np.searchsorted(rows, sec.hit[on])
        r1 = hits.distance[wall[on]].astype(np.float64)
        r2 = sec.distance[on].astype(np.float64)
        loss = 10 ** (-2 * c.multipath_loss_db / 10)
        sigma = (self.actor_rcs_m2(world, rows, p[on][0]) / per_row)[where] * loss
        v = scene.actor_velocity(sec.hit[on])
        rr = ((-v_sensor) * d[on]).sum(1) + (v * refl[on]).sum(1)
        return r1 + r2, sigma, rr, wall[on]

    def _detect(
        self,
        world: WorldState,
        s2w: np.ndarray,
        r: np.ndarray,
        rr: np.ndarray,
        az: np.ndarray,
        el: np.ndarray,
        power: np.ndarray,
        hit: np.ndarray,
        rng: np.random.Generator,
    ) -> RadarDetections:
        c = self.config
        keep = (r < c.max_range_m) & (np.abs(rr) < c.max_velocity_m_s) & (power > 0)
        r, rr, az, el, power, hit = r[keep], rr[keep], az[keep], el[keep], power[keep], hit[keep]
        rb = np.floor(r / c.range_resolution_m).astype(np.int64)
        vb = np.floor(rr / c.velocity_resolution_m_s).astype(np.int64) + 10_000
        # range-Doppler cells; inside one, returns closer in azimuth than the array's
        # resolution merge into one peak (no fixed azimuth grid, so no split at boresight)
        rv = rb * 20_000 + vb
        order = np.lexsort((az, rv))
        new = np.ones(len(order), bool)
        new[1:] = (rv[order][1:] != rv[order][:-1]) | (
            np.diff(az[order]) > c.azimuth_resolution_rad
        )
        inv = np.empty(len(order), np.int64)
        inv[order] = np.cumsum(new) - 1
        m = int(new.sum())
        p_cell = np.bincount(inv, power, m)
        mean = {
            k: np.bincount(inv, power * v, m) / p_cell
            for k, v in (("r", r), ("rr", rr), ("az", az), ("el", el))
        }
        # the ground truth of a cell is whatever put the most power into it
        codes = len(world) + 2
        key = inv * codes + (hit.astype(np.int64) + 2)
        uk, uinv = np.unique(key, return_inverse=True)
        kp = np.bincount(uinv, power)
        order = np.lexsort((-kp, uk // codes))
        first = np.ones(len(order), bool)
        first[1:] = (uk // codes)[order][1:] != (uk // codes)[order][:-1]
        truth = np.full(m, HIT_NONE, np.int32)
        truth[(uk // codes)[order][first]] = (uk % codes)[order][first] - 2
        snr = p_cell / c.noise_power_w
        det = snr >= 10 ** (c.snr_threshold_db / 10)
        snr, p_cell, truth = snr[det], p_cell[det], truth[det]
        mr, mrr, maz, mel = (mean[k][det] for k in ("r", "rr", "az", "el"))
        k = len(snr)
        scale = 1.0 / np.sqrt(2.0 * snr)
        mr = mr + rng.standard_normal(k) * c.range_resolution_m * scale
        mrr = mrr + rng.standard_normal(k) * c.velocity_resolution_m_s * scale
        az_sigma = np.hypot(c.azimuth_resolution_rad * scale, math.radians(c.azimuth_error_deg))
        maz = maz + rng.standard_normal(k) * az_sigma
        mel = mel + rng.standard_normal(k) * math.radians(c.v_step_deg) * scale
        nfa = rng.poisson(c.false_alarms_per_cycle)
        if nfa:
            thr = 10 ** (c.snr_threshold_db / 10)
            fa_snr = thr * (1.0 + rng.exponential(c.false_alarm_snr_spread, nfa))
            mr = np.concatenate([mr, rng.uniform(0.5, c.max_range_m, nfa)])
            mrr = np.concatenate([mrr, rng.uniform(-c.max_velocity_m_s, c.max_velocity_m_s, nfa)])
            maz = np.concatenate([maz, rng.uniform(-0.5, 0.5, nfa) * math.radians(c.h_fov_deg)])
            mel = np.concatenate([mel, rng.uniform(-0.5, 0.5, nfa) * math.radians(c.v_fov_deg)])
            snr = np.concatenate([snr, fa_snr])
            p_cell = np.concatenate([p_cell, fa_snr * c.noise_power_w])
            truth = np.concatenate([truth, np.full(nfa, HIT_NONE, np.int32)])
        return RadarDetections(
            time=world.time,
            sensor=self.name,
            sensor_to_world=s2w,
            range=mr,
            range_rate=mrr,
            azimuth=maz,
            elevation=mel,
            snr_db=10 * np.log10(snr),
            power_dbm=10 * np.log10(p_cell) + 30,
            hit=truth,
            actor_ids=world.ids,
        )
