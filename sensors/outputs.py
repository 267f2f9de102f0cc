"""What sensors and recognition produce: small typed classes around numpy arrays.

Frames: a sensor frame has x forward, y left, z up (metres); ``sensor_to_world`` (4x4) maps
sensor-frame points into SUMO network coordinates. Angles in radians (azimuth positive to the
left, elevation positive up). Times in seconds of simulation time.

Ground truth: ``hit`` holds, per point or detection, the row of the actor in ``actor_ids``
(the frame's WorldState ids), ``HIT_STATIC`` for the static scene (road, kerb, barrier,
building) or ``HIT_NONE`` for returns with no real surface (noise, rain ghosts, multipath).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

HIT_STATIC = -1
HIT_NONE = -2


@dataclass(frozen=True, eq=False)
class PointCloud:
    """One LiDAR scan (N points)."""

    time: float
    sensor: str
    sensor_to_world: np.ndarray  # (4, 4) float64
    xyz: np.ndarray  # (N, 3) float32, sensor frame, m
    intensity: np.ndarray  # (N,) float32, 0..1 (1 = white Lambertian at 1 m, normal incidence)
    range: np.ndarray  # (N,) float32, m
    hit: np.ndarray  # (N,) int32: actor row, HIT_STATIC or HIT_NONE
    actor_ids: np.ndarray  # (A,) object: WorldState ids at scan time

    def __len__(self) -> int:
        return len(self.range)

    def truth_ids(self) -> np.ndarray:
        """(N,) object: SUMO id per point, 'static' or '' (no surface)."""
        out = np.full(len(self.hit), "", dtype=object)
        out[self.hit == HIT_STATIC] = "static"
        a = self.hit >= 0
        out[a] = self.actor_ids[self.hit[a]]
        return out


@dataclass(frozen=True, eq=False)
class RadarDetections:
    """One radar cycle (N detections)."""

    time: float
    sensor: str
    sensor_to_world: np.ndarray  # (4, 4)
    range: np.ndarray  # (N,) m
    range_rate: np.ndarray  # (N,) m/s, negative when closing
    azimuth: np.ndarray  # (N,) rad, + left
    elevation: np.ndarray  # (N,) rad, + up
    snr_db: np.ndarray  # (N,) dB
    power_dbm: np.ndarray  # (N,) received power, dBm
    hit: np.ndarray  # (N,) int32
    actor_ids: np.ndarray  # (A,) object

    def __len__(self) -> int:
        return len(self.range)

    def xyz(self) -> np.ndarray:
        """(N, 3) detection positions in the sensor frame, m."""
        ce = np.cos(self.elevation)
        return np.stack(
            [
                self.range * ce * np.cos(self.azimuth),
                self.range * ce * np.sin(self.azimuth),
                self.range * np.sin(self.elevation),
            ],
            1,
        )


@dataclass(frozen=True, eq=False)
class CameraFrame:
    """One rendered camera image with its calibration."""

    time: float
    sensor: str
    sensor_to_world: np.ndarray  # (4, 4)
    image: np.ndarray  # (H, W, 3) uint8, RGB
    intrinsics: np.ndarray  # (3, 3) pinhole K, pixels
    distortion: np.ndarray  # (k1, k2) radial coefficients


@dataclass(frozen=True, eq=False)
class ObjectList:
    """Recognised objects from one sensor (or the fusion), with ground truth attached.

    Positions and velocities are in the frame ``frame_to_world`` describes (for sensors, the
    sensor frame; for fusion, the ego vehicle frame); velocities are relative to that frame.
    """

    time: float
    source: str  # "lidar", "radar", "camera", "fusion", ...
    frame_to_world: np.ndarray  # (4, 4)
    object_id: np.ndarray  # (N,) int64: detection or track id
    cls: np.ndarray  # (N,) int8: ActorClass, -1 when unknown
    position: np.ndarray  # (N, 3) m
    velocity: np.ndarray  # (N, 3) m/s, nan when not measured
    size: np.ndarray  # (N, 3) length, width, height, m; nan when unknown
    confidence: np.ndarray  # (N,) 0..1
    truth: np.ndarray  # (N,) object: SUMO id, 'static' (static scene), or '' for a false positive
    box_2d: np.ndarray | None = None  # (N, 4) camera boxes u0, v0, u1, v1 in pixels; else None
    heading: np.ndarray | None = None  # (N,) box heading about the frame's z axis, rad; else None
    #: (N,) largest standard deviation of each velocity estimate, m/s (trackers); else None
    velocity_sigma: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self.object_id)

    @staticmethod
    def empty(time: float, source: str, frame_to_world: np.ndarray) -> ObjectList:
        """No objects."""
        return ObjectList(
            time,
            source,
            frame_to_world,
            np.zeros(0, np.int64),
            np.zeros(0, np.int8),
            np.zeros((0, 3)),
            np.zeros((0, 3)),
            np.zeros((0, 3)),
            np.zeros(0),
            np.zeros(0, dtype=object),
        )
