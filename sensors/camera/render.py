"""A human-viewable camera image: ray-cast material, normal and depth per pixel, then light.

The image is rendered at a modest resolution (CameraConfig.render_width_px) by casting one ray
per pixel through the distorted lens model, shading each surface with the same LightingModel
as the recogniser (sun, sky, street lights, headlights), then adding fog / rain airlight,
veiling glare, window soiling, auto-exposure and sensor noise. It is for people and recordings;
the recogniser never looks at it.
"""

from __future__ import annotations

import math

import cv2
import numpy as np

from hiyari.kinematics import Pose, heading_vector, rotate
from hiyari.net.mesh.materials import DEFAULT_OPTICS, Material
from hiyari.sensors.camera.config import CameraConfig
from hiyari.sensors.environment.atmosphere import AtmosphereModel
from hiyari.sensors.environment.conditions import Environment
from hiyari.sensors.environment.lighting import LightingModel
from hiyari.sensors.environment.soiling import soiling_mask
from hiyari.sensors.frames import Mount, sensor_to_world
from hiyari.sensors.outputs import HIT_NONE, CameraFrame, ObjectList
from hiyari.sensors.scene.ray_scene import DirectionIndex, RayScene, SensorRays
from hiyari.traffic.world_state import WorldState

_TINT = {
    Material.ASPHALT: (1.0, 1.0, 1.05),
    Material.LANE_PAINT: (1.0, 1.0, 0.95),
    Material.CONCRETE: (1.05, 1.0, 0.95),
    Material.BARRIER_METAL: (0.95, 1.0, 1.05),
    Material.BUILDING: (1.15, 1.0, 0.85),
    Material.VEHICLE_PAINT: (1.0, 1.0, 1.0),
    Material.VEHICLE_GLASS: (0.8, 0.95, 1.25),
    Material.CLOTHING: (0.7, 0.9, 1.4),
    Material.DARK_CLOTHING: (1.0, 1.0, 1.0),
    Material.SKIN: (1.3, 1.0, 0.75),
    Material.RETROREFLECTOR: (1.1, 1.1, 0.8),
    Material.GRASS: (0.6, 1.6, 0.5),
}
"""Relative RGB colour of each material (mean 1); the visible albedo sets the brightness."""

_PAINT = np.array(
    [(1.5, 0.4, 0.4), (0.5, 0.7, 1.6), (1.0, 1.0, 1.0), (0.5, 0.5, 0.5), (1.3, 1.1, 0.4)]
)
"""Paint colours cycled over vehicles (mean ~1)."""

EXPOSURE_KEY = 0.18
"""Auto-exposure maps the scene's log-average luminance to this mid-grey (Reinhard)."""
DARKEST_EXPOSED_SHARE = 0.1
"""Auto-exposure runs out of exposure time and gain for scenes darker than this share of the
camera's noise luminance: darker scenes stay dark."""
RENDER_RANGE_M = 2000.0
"""Farthest surface drawn; beyond it the sky is."""
SUN_DISC_DEG = 0.6
"""Drawn radius of the sun's disc (with its aureole), degrees."""
SUN_DISC_GAIN = 10.0
"""Luminance of the sun's disc in cd/m^2 per lux of direct sunlight (saturates the image)."""
NOISE_AT_DARK = 0.04
"""Standard deviation of image noise, as a fraction of full scale, in a scene far darker than
the camera's noise luminance (falls as the scene brightens)."""


def _albedo_table() -> np.ndarray:
    table = np.zeros((256, 3), np.float32)
    for m, tint in _TINT.items():
        table[m] = np.array(tint) * DEFAULT_OPTICS[m].visible
    return table


class CameraRenderer:
    """Renders CameraFrames for one camera; pixel rays are built once."""

    def __init__(
        self,
        config: CameraConfig,
        mount: Mount,
        lighting: LightingModel | None = None,
        atmosphere: AtmosphereModel | None = None,
    ) -> None:
        self.config = config
        self.mount = mount
        self.lighting = lighting or LightingModel()
        self.atmosphere = atmosphere or AtmosphereModel()
        self.scale = config.render_width_px / config.width_px
        self.width = config.render_width_px
        self.height = max(1, round(config.height_px * self.scale))
        u = (np.arange(self.width) + 0.5) / self.scale
        v = (np.arange(self.height) + 0.5) / self.scale
        uu, vv = np.meshgrid(u, v)
        dirs = config.pixel_rays(uu.ravel(), vv.ravel())
        self.index = DirectionIndex.build(dirs)
        self._ego_dirs = (dirs @ mount.sensor_to_ego()[:3, :3].T).astype(np.float32)
        self._albedo = _albedo_table()

    def render(
        self,
        name: str,
        scene: RayScene,
        ego: Pose,
        world: WorldState,
        env: Environment,
        rng: np.random.Generator,
    ) -> CameraFrame:
        """One frame (RGB uint8, render resolution)."""
        c, light = self.config, self.lighting
        scene.ensure(world)
        s2w = sensor_to_world(self.mount, ego)
        rot, cam = s2w[:3, :3], s2w[:3, 3]
        dirs = rotate(self._ego_dirs, ego.heading)
        origins = np.empty_like(dirs)
        origins[:] = cam.astype(np.float32)
        hits = scene.cast(
            origins, dirs, RENDER_RANGE_M, SensorRays(self.index, cam, rot), normals=True
        )
        hit = hits.hit != HIT_NONE
        fog = self.atmosphere.fog_extinction(env.fog_visibility_m)
        beta = self.atmosphere.visible_extinction(env)
        sky = light.sky_luminance(env)

        lum = np.zeros((len(dirs), 3), np.float32)
        j = np.flatnonzero(hit)
        pts = origins[j] + dirs[j] * hits.distance[j, None]
        lamp = np.array([ego.x, ego.y, ego.z]) if env.headlights else None
        e_lux = light.illuminance(env, pts, hits.normal[j], lamp, ego.heading, fog).astype(
            np.float32
        )
        alb = self._albedo[hits.material[j]]
        paint = hits.material[j] == Material.VEHICLE_PAINT
        if paint.any():
            alb[paint] = (
                _PAINT[hits.hit[j][paint] % len(_PAINT)]
                * DEFAULT_OPTICS[Material.VEHICLE_PAINT].visible
            )
        lum[j] = alb * (e_lux / math.pi)[:, None]
        miss = np.flatnonzero(~hit)
        up = np.clip(dirs[miss, 2], 0.0, 1.0)
        lum[miss] = (sky * (1.0 - 0.5 * up))[:, None] * np.array([0.8, 0.9, 1.15], np.float32)
        if beta > 0:
            dist = np.where(hit, hits.distance, np.float32(np.inf))
            t = np.exp(-beta * dist)[:, None]
            lum = lum * t + np.float32(sky) * (1 - t)
        glare = light.glare_sources(env, cam, rot[:, 0], oncoming_lamps(scene, world, cam), fog)
        if glare:
            lum += light.veiling_luminance(env, dirs.astype(np.float64), glare).astype(np.float32)[
                :, None
            ]
        if env.sun_up and fog < 1e-3:
            sun = np.array(env.sun_direction(), np.float32)
            disc = (dirs @ sun > math.cos(math.radians(SUN_DISC_DEG))) & ~hit
            lum[disc] = light.sun_lux(env) * SUN_DISC_GAIN
        img = lum.reshape(self.height, self.width, 3)
        img = self._soil(img, env, self.index.directions)
        return CameraFrame(
            time=world.time,
            sensor=name,
            sensor_to_world=s2w,
            image=self._expose(img, env, rng),
            intrinsics=c.intrinsics(self.scale),
            distortion=np.array([c.k1, c.k2]),
        )

    def _soil(self, img: np.ndarray, env: Environment, dirs: np.ndarray) -> np.ndarray:
        s = env.soiling
        if s.uniform_transmission < 1.0:
            haze = 1.0 - s.uniform_transmission
            blurred = cv2.GaussianBlur(img, (0, 0), 1.0 + 6.0 * haze)
            img = s.uniform_transmission * blurred + haze * blurred.mean((0, 1))
        if s.spots:
            t, spot = soiling_mask(dirs, s)
            mask = spot.reshape(self.height, self.width).astype(np.float32)
            mask = cv2.GaussianBlur(mask, (0, 0), 2.0)[..., None]
            dirt = np.array([0.35, 0.28, 0.2], np.float32) * img.mean((0, 1)) * 0.4
            img = img * (1 - mask * (1 - s.spot_transmission)) + mask * dirt
        return img

    def _expose(self, img: np.ndarray, env: Environment, rng: np.random.Generator) -> np.ndarray:
        lum = img.mean(2)
        log_avg = float(np.exp(np.mean(np.log(lum + 1e-4))))
        adapt = max(log_avg, DARKEST_EXPOSED_SHARE * self.config.noise_luminance_cd_m2)
        x = img * (EXPOSURE_KEY / adapt)
        x = x / (1.0 + x)
        noise = NOISE_AT_DARK * math.sqrt(
            self.config.noise_luminance_cd_m2 / (adapt + self.config.noise_luminance_cd_m2)
        )
        x = x + rng.standard_normal(x.shape[:2], dtype=np.float32)[..., None] * noise
        out = np.clip(x, 0.0, 1.0) ** (1 / 2.2)
        return (out * 255 + 0.5).astype(np.uint8)


def oncoming_lamps(scene: RayScene, world: WorldState, cam: np.ndarray) -> np.ndarray:
    """Front-lamp positions of vehicles facing the camera."""
    rows = np.flatnonzero(world.is_vehicle & (world.ids != scene.ego_id))
    if not len(rows):
        return np.zeros((0, 3))
    fwd = heading_vector(world.heading[rows])
    front = world.xyz[rows, :2] + fwd * (world.length[rows] / 2)[:, None]
    to_cam = cam[:2] - front
    dist = np.linalg.norm(to_cam, axis=1)
    facing = (fwd * to_cam).sum(1) > 0.5 * dist
    return np.c_[front, world.xyz[rows, 2] + 0.65][facing & (dist < 300)]


def draw_objects(frame: CameraFrame, objects: ObjectList, config: CameraConfig) -> np.ndarray:
    """A copy of the frame's image with the recogniser's 2D boxes drawn (green true, red false)."""
    img = np.ascontiguousarray(frame.image.copy())
    if objects.box_2d is None:
        return img
    scale = frame.intrinsics[0, 0] / config.fx
    for box, truth, conf in zip(objects.box_2d, objects.truth, objects.confidence, strict=True):
        u0, v0, u1, v1 = (int(round(b * scale)) for b in box)
        colour = (40, 220, 40) if truth not in ("", "static") else (230, 40, 40)
        cv2.rectangle(img, (u0, v0), (u1, v1), colour, 1)
        cv2.putText(
            img,
            f"{truth or 'FP'} {conf:.2f}",
            (u0, max(v0 - 3, 8)),
            cv2.FONT_HERSHEY_SIMPLEX,
            0.3,
            colour,
            1,
        )
    return img
