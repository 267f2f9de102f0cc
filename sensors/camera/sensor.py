"""Camera: analytic recognition from projected boxes, pixel size, contrast and visibility.

For every actor in view the recogniser projects its 3D box (with distortion), estimates its
luminance against the background behind it (sun, sky, street lights, headlights; fog and rain
airlight; veiling glare from the sun or oncoming headlamps; soiling), checks how much of it is
visible with a few rays, and detects it with probability
    P = logistic((h_px - h50) / s_h) x logistic(ln(C / C_th) / s_c) x visibility x in-image share
where C_th rises as 1/sqrt(L) in low light. Range comes from the box size and a size prior, so
its error grows with distance (seed: cameras range poorly). The image itself is optional
(camera_render) and never used by the recogniser.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hiyari.kinematics import Pose, box_corners, heading_vector
from hiyari.net.mesh.materials import DEFAULT_OPTICS, Material
from hiyari.sensors.camera.config import CameraConfig
from hiyari.sensors.camera.render import CameraRenderer, oncoming_lamps
from hiyari.sensors.environment.atmosphere import AtmosphereModel
from hiyari.sensors.environment.conditions import Environment, Illumination
from hiyari.sensors.environment.lighting import LightingModel
from hiyari.sensors.environment.soiling import soiling_mask
from hiyari.sensors.frames import Mount, sensor_to_world
from hiyari.sensors.outputs import CameraFrame, ObjectList
from hiyari.sensors.scene.ray_scene import RayScene
from hiyari.traffic.actor_class import ActorClass
from hiyari.traffic.world_state import WorldState

_BODY = {
    ActorClass.CAR: Material.VEHICLE_PAINT,
    ActorClass.TRUCK: Material.VEHICLE_PAINT,
    ActorClass.BUS: Material.VEHICLE_PAINT,
}
"""Material that sets a vehicle's apparent albedo; people and riders use their clothing."""


VISIBILITY_ACROSS = (-0.3, 0.0, 0.3)
"""Sample points across an actor's seen width (fractions of it) for the visibility rays."""
VISIBILITY_UP = (0.25, 0.5, 0.8)
"""Sample heights on an actor (fractions of its height) for the visibility rays."""
BACKGROUND_RANGE_M = 1000.0
"""Farthest static surface taken as an actor's background; beyond it the sky is."""
_GRID = np.array([(a, b) for a in VISIBILITY_ACROSS for b in VISIBILITY_UP])
"""(9, 2) visibility sample points: fraction across, fraction up."""
_NO_LAMPS = np.zeros((0, 3))


def _visible_table() -> np.ndarray:
    """(256,) visible reflectance per material id (0 for ids without optics)."""
    table = np.zeros(256)
    for material, optics in DEFAULT_OPTICS.items():
        table[material] = optics.visible
    return table


_VISIBLE = _visible_table()
_PAINTED = np.isin(np.arange(256), list(_BODY))
"""(256,) whether an ActorClass id is painted (a vehicle body), else dressed."""


def _logistic(x: np.ndarray) -> np.ndarray:
    return 1.0 / (1.0 + np.exp(-x))


@dataclass(frozen=True, eq=False)
class CameraView:
    """Per-actor quantities behind a detection decision (one row per actor in view)."""

    rows: np.ndarray  # (n,) WorldState rows
    box: np.ndarray  # (n, 4) u0, v0, u1, v1 full-resolution pixels (clipped to the image)
    height_px: np.ndarray  # (n,) unclipped box height, px
    in_image: np.ndarray  # (n,) share of the box inside the image
    visible: np.ndarray  # (n,) share of sample rays reaching the actor
    contrast: np.ndarray  # (n,) apparent Weber contrast against the background
    contrast_threshold: np.ndarray  # (n,) threshold at the local light level
    probability: np.ndarray  # (n,) detection probability
    range_m: np.ndarray  # (n,) true distance from the camera to the box centre, m
    centre: np.ndarray  # (n, 3) box centre in the sensor frame, m


class Camera:
    """A camera mounted on the ego: ``detect`` gives an ObjectList, ``render`` an image."""

    def __init__(
        self,
        config: CameraConfig,
        mount: Mount | None = None,
        name: str = "camera",
        lighting: LightingModel | None = None,
        atmosphere: AtmosphereModel | None = None,
    ) -> None:
        self.config = config.validate()
        self.mount = mount or Mount(x=0.8, z=1.3)
        self.name = name
        self.lighting = lighting or LightingModel()
        self.atmosphere = atmosphere or AtmosphereModel()
        self._renderer = None

    @property
    def rate_hz(self) -> float:
        """Frames per second."""
        return self.config.rate_hz

    def sensor_to_world(self, ego: Pose) -> np.ndarray:
        """(4, 4) sensor-to-network transform for the ego pose."""
        return sensor_to_world(self.mount, ego)

    def _albedo(self, scene: RayScene, world: WorldState, rows: np.ndarray) -> np.ndarray:
        app = scene.appearance
        cls = world.cls[rows]
        out = np.full(len(rows), DEFAULT_OPTICS[Material.VEHICLE_PAINT].visible)
        # people and riders: their own clothing (vehicle classes are painted)
        dressed = np.flatnonzero(~_PAINTED[cls])
        if not app.clothing_by_id:
            out[dressed] = DEFAULT_OPTICS[app.clothing].visible
            return out
        for i in dressed:
            mat = app.clothing_by_id.get(world.ids[rows[i]], app.clothing)
            out[i] = DEFAULT_OPTICS[mat].visible
        return out

    def view(self, scene: RayScene, ego: Pose, world: WorldState, env: Environment) -> CameraView:
        """Geometry, photometry and detection probability of every actor in view."""
        c = self.config
        scene.ensure(world)
        s2w = self.sensor_to_world(ego)
        rot, cam = s2w[:3, :3], s2w[:3, 3]
        rows = np.flatnonzero(world.ids != scene.ego_id)
        rel = (world.xyz[rows] - cam) @ rot
        dist = np.linalg.norm(rel, axis=1)
        near = (rel[:, 0] > 0.5) & (dist < c.max_range_m + 10)
        rows = rows[near]
        n = len(rows)
        if n == 0:
            z = np.zeros(0)
            return CameraView(rows, np.zeros((0, 4)), z, z, z, z, z, z, z, np.zeros((0, 3)))
        # 3D box corners in the sensor frame
        corners = box_corners(
            world.xyz[rows],
            world.heading[rows],
            world.length[rows],
            world.width[rows],
            world.height[rows],
        )
        pts = (corners.reshape(-1, 3) - cam) @ rot
        uv, front = c.project(pts)
        uv = uv.reshape(n, 8, 2)
        front = front.reshape(n, 8).all(1)
        lo, hi = uv.min(1), uv.max(1)
        height_px = hi[:, 1] - lo[:, 1]
        area = np.maximum((hi[:, 0] - lo[:, 0]) * height_px, 1e-9)
        clo = np.clip(lo, 0, [c.width_px, c.height_px])
        chi = np.clip(hi, 0, [c.width_px, c.height_px])
        in_image = np.clip((chi[:, 0] - clo[:, 0]) * (chi[:, 1] - clo[:, 1]) / area, 0, 1) * front

        centre_w = world.xyz[rows].copy()
        centre_w[:, 2] += world.height[rows] / 2
        centre = (centre_w - cam) @ rot
        rng_m = np.linalg.norm(centre, axis=1)
        visible = self._visibility(scene, world, rows, cam)
        contrast, c_th = self._contrast(scene, ego, world, env, rows, cam, centre_w, rot)
        p = (
            _logistic((height_px - c.height_50_px) / c.height_scale_px)
            * _logistic(np.log(np.maximum(contrast, 1e-9) / c_th) / c.contrast_scale)
            * np.clip((visible - c.min_visible_fraction) / (1 - c.min_visible_fraction), 0, 1)
            * in_image
        )
        if env.soiling.spots:
            t, spot = soiling_mask(centre / rng_m[:, None], env.soiling)
            p = np.where(spot, p * t / env.soiling.uniform_transmission, p)
        p = np.where(rng_m <= c.max_range_m, p, 0.0)
        return CameraView(
            rows, np.hstack([clo, chi]), height_px, in_image, visible, contrast, c_th, p, rng_m,
            centre,
        )  # fmt: skip

    def _visibility(
        self, scene: RayScene, world: WorldState, rows: np.ndarray, cam: np.ndarray
    ) -> np.ndarray:
        """Share of 3 x 3 sample points across each actor that a ray from the lens reaches."""
        grid = _GRID
        n = len(rows)
        fwd = heading_vector(world.heading[rows])
        side = np.stack([-fwd[:, 1], fwd[:, 0]], 1)
        to = world.xyz[rows, :2] - cam[:2]
        # offsets across the actor as the camera sees it: its width and length projected
        across = np.stack([-to[:, 1], to[:, 0]], 1) / np.maximum(
            np.linalg.norm(to, axis=1, keepdims=True), 1e-9
        )
        span = (
            np.abs((side * across).sum(1)) * world.width[rows]
            + np.abs((fwd * across).sum(1)) * world.length[rows]
        )
        p = np.repeat(world.xyz[rows], len(grid), 0).astype(np.float64)
        p[:, :2] += (
            np.repeat(across * span[:, None], len(grid), 0) * np.tile(grid[:, 0], n)[:, None]
        )
        p[:, 2] += np.repeat(world.height[rows], len(grid)) * np.tile(grid[:, 1], n)
        d = p - cam
        length = np.linalg.norm(d, axis=1)
        dirs = (d / length[:, None]).astype(np.float32)
        origins = np.empty_like(dirs)
        origins[:] = cam.astype(np.float32)
        hits = scene.cast(origins, dirs, float(length.max() + 5.0))
        seen = hits.hit == np.repeat(rows, len(grid))
        return seen.reshape(n, len(grid)).mean(1)

    def _contrast(
        self,
        scene: RayScene,
        ego: Pose,
        world: WorldState,
        env: Environment,
        rows: np.ndarray,
        cam: np.ndarray,
        centre_w: np.ndarray,
        rot: np.ndarray,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Apparent Weber contrast of each actor against what lies behind it, and threshold."""
        c, light = self.config, self.lighting
        to_cam = cam - centre_w
        to_cam[:, 2] = 0.0
        facing = to_cam / np.maximum(np.linalg.norm(to_cam, axis=1, keepdims=True), 1e-9)
        lamp = np.array([ego.x, ego.y, ego.z])
        beta = self.atmosphere.visible_extinction(env)
        fog = self.atmosphere.fog_extinction(env.fog_visibility_m)
        e_t = light.illuminance(env, centre_w, facing, fog_extinction=fog)
        if env.headlights:
            d = centre_w[:, :2] - lamp[:2]
            bearing = np.arctan2(d[:, 1], d[:, 0]) - ego.heading
            e_t = e_t + light.headlight_lux_on_target(
                np.linalg.norm(d, axis=1),
                (bearing + np.pi) % (2 * np.pi) - np.pi,
                world.height[rows],
            )
        l_t = self._albedo(scene, world, rows) * e_t / math.pi
        if env.illumination != Illumination.DAY:
            # vehicles carry their own lamps: spread over the end face the camera sees
            veh = world.cls[rows] != ActorClass.PEDESTRIAN
            face = world.width[rows] * world.height[rows]
            l_t = l_t + np.where(veh, light.vehicle_lamp_cd / face, 0.0)
        # background: the static scene straight behind the actor's centre
        view = centre_w - cam
        dist_t = np.linalg.norm(view, axis=1)
        dirs = (view / dist_t[:, None]).astype(np.float32)
        origins = np.empty_like(dirs)
        origins[:] = cam.astype(np.float32)
        bg = scene.cast(origins, dirs, BACKGROUND_RANGE_M, normals=True, actors=False)
        hit_bg = bg.hit != -2
        p_bg = cam + dirs * np.where(hit_bg, bg.distance, 0)[:, None]
        albedo_bg = np.where(hit_bg, _VISIBLE[bg.material], 0.0)
        e_b = light.illuminance(
            env, p_bg, bg.normal, lamp if env.headlights else None, ego.heading, fog
        )
        sky = light.sky_luminance(env)
        l_b = np.where(hit_bg, albedo_bg * e_b / math.pi, sky)
        if beta > 0:
            tt = np.exp(-beta * dist_t)
            tb = np.where(hit_bg, np.exp(-beta * np.minimum(bg.distance, 1e4)), 0.0)
            l_t = l_t * tt + sky * (1 - tt)
            l_b = l_b * tb + sky * (1 - tb)
        # oncoming headlamps dazzle only out of daylight (LightingModel.glare_sources)
        dazzle = env.oncoming_headlights and env.illumination != Illumination.DAY
        lamps = oncoming_lamps(scene, world, cam) if dazzle else _NO_LAMPS
        glare = light.glare_sources(env, cam, rot[:, 0], lamps, fog)
        l_v = light.veiling_luminance(env, dirs.astype(np.float64), glare)
        trans = env.soiling.uniform_transmission
        mean_l = 0.5 * (l_t + l_b)
        # a uniform film scatters part of the light into a veil over the whole image
        l_v = l_v + (1 - trans) / max(trans, 1e-6) * mean_l
        contrast = np.abs(l_t - l_b) / np.maximum(l_b + l_v, 1e-12)
        threshold = c.contrast_threshold * np.sqrt(
            1 + c.noise_luminance_cd_m2 / np.maximum(mean_l * trans, 1e-12)
        )
        return contrast, threshold

    def detect(
        self,
        scene: RayScene,
        ego: Pose,
        world: WorldState,
        env: Environment,
        rng: np.random.Generator,
    ) -> ObjectList:
        """Recognised objects (sensor frame; 2D boxes in full-resolution pixels)."""
        c = self.config
        v = self.view(scene, ego, world, env)
        s2w = self.sensor_to_world(ego)
        draw = rng.random(len(v.rows))
        det = np.flatnonzero(draw < v.probability)
        rows = v.rows[det]
        h = np.maximum(v.height_px[det], 1.0)
        rel_err = np.sqrt(c.size_prior_error**2 + (c.pixel_error_px / h) ** 2)
        scale = 1.0 + rng.standard_normal(len(det)) * rel_err
        # bearing from the box centre with pixel noise
        centre_uv, _ = c.project(v.centre[det])
        centre_uv = centre_uv + rng.standard_normal((len(det), 2)) * c.pixel_error_px
        rays = c.pixel_rays(centre_uv[:, 0], centre_uv[:, 1]).reshape(-1, 3)
        r_est = v.range_m[det] * np.maximum(scale, 0.05)
        pos = rays * r_est[:, None]
        size = (
            np.stack([world.length[rows], world.width[rows], world.height[rows]], 1)
            * np.maximum(scale, 0.05)[:, None]
        )
        boxes = v.box[det] + rng.standard_normal((len(det), 4)) * c.pixel_error_px
        objs = dict(
            cls=world.cls[rows].astype(np.int8),
            position=pos,
            size=size,
            confidence=v.probability[det],
            truth=world.ids[rows].astype(object),
            box=boxes,
        )
        fp = self._false_positives(env, rng)
        n = len(det) + len(fp["truth"])
        return ObjectList(
            time=world.time,
            source="camera",
            frame_to_world=s2w,
            object_id=np.arange(n, dtype=np.int64),
            cls=np.concatenate([objs["cls"], fp["cls"]]),
            position=np.concatenate([objs["position"], fp["position"]]).reshape(-1, 3),
            velocity=np.full((n, 3), np.nan),
            size=np.concatenate([objs["size"], fp["size"]]).reshape(-1, 3),
            confidence=np.concatenate([objs["confidence"], fp["confidence"]]),
            truth=np.concatenate([objs["truth"], fp["truth"]]),
            box_2d=np.concatenate([objs["box"], fp["box"]]).reshape(-1, 4),
        )

    def _false_positives(self, env: Environment, rng: np.random.Generator) -> dict:
        """Random ghosts plus objects seen in soiling spots (truth '')."""
        c = self.config
        dirs = []
        for _ in range(rng.poisson(c.false_positives_per_frame)):
            u, v = rng.uniform(0, c.width_px), rng.uniform(c.height_px * 0.4, c.height_px * 0.7)
            dirs.append(c.pixel_rays(np.array([u]), np.array([v]))[0])
        for s in env.soiling.spots:
            if rng.random() < c.spot_false_positive_probability:
                az, el = math.radians(s.azimuth_deg), math.radians(s.elevation_deg)
                dirs.append(
                    np.array(
                        [math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)]
                    )
                )
        k = len(dirs)
        if k == 0:
            return dict(
                cls=np.zeros(0, np.int8),
                position=np.zeros((0, 3)),
                size=np.zeros((0, 3)),
                confidence=np.zeros(0),
                truth=np.zeros(0, dtype=object),
                box=np.zeros((0, 4)),
            )
        d = np.array(dirs)
        r = rng.uniform(*c.false_positive_range_m, k)
        uv, _ = c.project(d)
        ped = ActorClass.PEDESTRIAN.size
        half = 0.5 * c.fx * ped.height / r
        return dict(
            cls=np.full(k, ActorClass.PEDESTRIAN, np.int8),
            position=d * r[:, None],
            size=np.tile(ped.as_tuple(), (k, 1)),
            confidence=np.full(k, 0.5),
            truth=np.full(k, "", dtype=object),
            box=np.c_[uv[:, 0] - half / 3, uv[:, 1] - half, uv[:, 0] + half / 3, uv[:, 1] + half],
        )

    def render(
        self,
        scene: RayScene,
        ego: Pose,
        world: WorldState,
        env: Environment,
        rng: np.random.Generator,
    ) -> CameraFrame:
        """The rendered image at ``config.render_width_px`` (intrinsics scaled to match)."""
        if self._renderer is None:
            self._renderer = CameraRenderer(self.config, self.mount, self.lighting, self.atmosphere)
        return self._renderer.render(self.name, scene, ego, world, env, rng)

    def sense(
        self,
        scene: RayScene,
        ego: Pose,
        world: WorldState,
        env: Environment,
        rng: np.random.Generator,
        render_image: bool = False,
    ) -> tuple[CameraFrame | None, ObjectList]:
        """The image when ``render_image`` (skip it on frames nobody records) and the objects.

        The image's noise comes from a stream jumped off ``rng`` without advancing it, so
        rendering (recording) never changes the detections of this or any later frame."""
        objects = self.detect(scene, ego, world, env, rng)
        if not render_image:
            return None, objects
        image_rng = np.random.Generator(rng.bit_generator.jumped())
        return self.render(scene, ego, world, env, image_rng), objects
