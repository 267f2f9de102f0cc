"""Representative-factor sweep: each disturbance over its intensity range, for the standard
targets, with detection range, missed and ghost rates per sensor and for the fused tracks.

Built on sensors.detection_range (the same road, targets, sensors and far-limit rule). At each
target distance a few frames run through LiDAR, radar and camera and a fresh KalmanFusion;
'fused' is a confirmed fusion track on the target after the last frame.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from hiyari.bridge.loop.stack.fusion import FusionConfig, KalmanFusion
from hiyari.errors import HiyariError
from hiyari.net.mesh.materials import Material
from hiyari.sensors.coverage.disturbances import Disturbance
from hiyari.sensors.detection_range import SENSORS, RangeStudy, RangeSweep, far_limit
from hiyari.sensors.environment.conditions import Environment, Illumination, Soiling
from hiyari.sensors.environment.presets import PRESETS, DisturbancePreset
from hiyari.sensors.scene.actor_shapes import ActorAppearance

OUTPUTS = (*SENSORS, "fused")
FRAME_S = 0.1
"""Time between the frames at one distance, s."""


@dataclass(frozen=True)
class SweepConfig:
    """What the sweep covers."""

    levels: int = 3
    """Intensities per disturbance, evenly spaced over its range (first = clear end)."""
    targets: tuple[str, ...] = ("pedestrian", "car", "motorcycle", "obstacle")
    distances_m: tuple[float, ...] = tuple(np.arange(10.0, 150.01, 10.0))
    frames: int = FusionConfig().confirm_m
    """Frames per distance: as many as the fusion needs to confirm a track (M of N,
    FusionConfig.confirm_m); 'fused' is judged on the last one."""
    seed: int = 7


def levels(d: Disturbance, n: int) -> np.ndarray:
    """``n`` intensities (at most the disturbance's own number of levels: 2 for on / off ones)
    from the clear end to the severe end of ``d``'s range; visibility ranges are spaced
    geometrically (extinction goes as 1 / visibility)."""
    lo, hi = d.range
    n = min(n, d.levels or n)
    if n < 2:
        return np.array([hi])
    if "visibility" in d.unit:
        return np.geomspace(lo, hi, n)
    return np.linspace(lo, hi, n)


def conditions(
    d: Disturbance, level: float, study: RangeStudy
) -> tuple[DisturbancePreset, RangeStudy]:
    """The preset (environment, appearance, occluder) and sensor study for ``d`` at ``level``."""
    preset = replace(PRESETS["clear"], name=f"{d.name}={level:g}", jama_factor=d.name)
    env = Environment()
    on = level >= 0.5
    match d.kind:
        case "environment" if d.parameter == "night":
            env = Environment(illumination=Illumination.NIGHT, headlights=True) if on else env
        case "environment" if d.parameter == "spots":
            env = PRESETS["soiling_spot"].environment if on else env
        case "environment":
            env = Environment(**{d.parameter: float(level)}) if level > 0 else env
        case "sun":
            env = Environment(sun_elevation_deg=float(level))
            preset = replace(preset, sun_relative_azimuth_deg=0.0)
        case "window":
            soil = Soiling(uniform_transmission=float(level))
            env = Environment(sensor_soiling=((d.parameter, soil),))
        case "mount" | "pitch":
            key = "yaw_deg" if d.kind == "mount" else "pitch_deg"
            study = replace(
                study,
                **{
                    f"{s}_mount": replace(getattr(study, f"{s}_mount"), **{key: float(level)})
                    for s in SENSORS
                },
            )
        case "multipath":
            # guard rails at every level: only the ghosts they mirror change
            study = replace(study, guard_rail=True, radar=replace(study.radar, multipath=on))
        case "occluder":
            preset = replace(preset, occluder=on)
        case "clothing":
            clothing = Material.DARK_CLOTHING if on else ActorAppearance().clothing
            preset = replace(preset, appearance=ActorAppearance(clothing=clothing))
        case _:
            raise HiyariError(f"disturbance {d.name!r}: kind {d.kind!r} cannot be swept")
    return replace(preset, environment=env), study


@dataclass(frozen=True)
class SweepRow:
    """One disturbance level and target: per output (lidar, radar, camera, fused)."""

    disturbance: str
    level: float
    unit: str
    target: str
    range_m: dict[str, float]
    """Detection range (far end of the unbroken run of detections), m."""
    missed: dict[str, float]
    """Share of frames without the target within the clear-level range of that output."""
    ghosts: dict[str, float]
    """Share of frames with at least one false object (no real surface)."""


def _run_target(
    sweep: RangeSweep, target: str, preset: DisturbancePreset, cfg: SweepConfig
) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    """(distances, frames) hit and ghost arrays per output."""
    shape = (len(cfg.distances_m), cfg.frames)
    hit = {o: np.zeros(shape, bool) for o in OUTPUTS}
    ghost = {o: np.zeros(shape, bool) for o in OUTPUTS}
    for i, dist in enumerate(cfg.distances_m):
        fusion = KalmanFusion()
        for f in range(cfg.frames):
            ob = sweep.observe(target, preset, float(dist), [i, f])
            ego = ob.world.pose_of("ego")
            tracks = fusion.update(list(ob.objects.values()), ego, f * FRAME_S)
            for s in SENSORS:
                hit[s][i, f] = np.any(ob.objects[s].truth == "target")
                ghost[s][i, f] = ob.ghosts(s) > 0
            hit["fused"][i, f] = np.any(tracks.truth == "target")
            ghost["fused"][i, f] = np.any(tracks.truth == "")
    return hit, ghost


def sweep_disturbance(
    d: Disturbance, cfg: SweepConfig, study: RangeStudy | None = None, progress: object = None
) -> list[SweepRow]:
    """Rows for every level of ``d`` and every target (``progress``: a tqdm to advance)."""
    base = study or RangeStudy(seed=cfg.seed)
    dist = np.asarray(cfg.distances_m)
    rows: list[SweepRow] = []
    clear: dict[tuple[str, str], float] = {}
    for k, level in enumerate(levels(d, cfg.levels)):
        preset, st = conditions(d, float(level), base)
        sweep = RangeSweep(st)
        for target in cfg.targets:
            hit, ghost = _run_target(sweep, target, preset, cfg)
            rng, missed = {}, {}
            for o in OUTPUTS:
                # the fusion confirms a track on its second frame: judge it on the last one
                frames = hit[o][:, -1:] if o == "fused" else hit[o]
                rng[o] = far_limit(dist, frames.mean(axis=1) >= 0.5)
                if k == 0:
                    clear[(target, o)] = rng[o]
                inside = dist <= clear[(target, o)]
                missed[o] = float(1 - frames[inside].mean()) if inside.any() else math.nan
            rows.append(
                SweepRow(
                    d.name,
                    float(level),
                    d.unit,
                    target,
                    rng,
                    missed,
                    {o: float(ghost[o].mean()) for o in OUTPUTS},
                )
            )
            if progress is not None:
                progress.update(1)
    return rows
