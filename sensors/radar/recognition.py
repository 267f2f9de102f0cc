"""Radar recognition: detections that lie close in position and range rate form one object.

Detections are linked when they are within ``gate_m`` of each other and their range rates
differ by less than ``gate_m_s``; each connected group is an object at its power-weighted
position. Radar measures only the radial part of the relative velocity, so an object's
velocity is its range rate along the line of sight (tangential part unknown, taken as 0).
Radar does not classify (seed: its points are too sparse), so classes are -1.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hiyari.jit import njit
from hiyari.sensors.outputs import HIT_NONE, HIT_STATIC, ObjectList, RadarDetections


@dataclass(frozen=True)
class RadarRecognitionConfig:
    """Gates of the radar clustering (toolkit choices)."""

    gate_m: float = 2.5
    """Largest distance between linked detections, m."""
    gate_m_s: float = 1.5
    """Largest range-rate difference between linked detections, m/s."""
    min_detections: int = 1
    """Fewest detections for an object."""
    full_confidence_snr_db: float = 25.0
    """Cluster SNR at which confidence reaches 1 (confidence rises linearly from the threshold)."""


def recognise_radar(
    det: RadarDetections,
    config: RadarRecognitionConfig | None = None,
    snr_threshold_db: float = 12.0,
) -> ObjectList:
    """Objects from one radar cycle (sensor frame; velocity = range rate along the sight line)."""
    cfg = config or RadarRecognitionConfig()
    n = len(det)
    if n == 0:
        return ObjectList.empty(det.time, "radar", det.sensor_to_world)
    xyz = det.xyz()
    count, lab = linked_groups(
        np.ascontiguousarray(xyz, np.float64),
        np.ascontiguousarray(det.range_rate, np.float64),
        cfg.gate_m,
        cfg.gate_m_s,
    )
    w = 10 ** (det.snr_db / 10)
    wsum = np.bincount(lab, w, count)
    pos = np.stack([np.bincount(lab, w * xyz[:, k], count) / wsum for k in range(3)], 1)
    rr = np.bincount(lab, w * det.range_rate, count) / wsum
    size = np.bincount(lab, minlength=count)
    keep = np.flatnonzero(size >= cfg.min_detections)
    unit = pos / np.maximum(np.linalg.norm(pos, axis=1, keepdims=True), 1e-9)
    best_snr = np.zeros(count)
    np.maximum.at(best_snr, lab, det.snr_db)
    # ground truth by power: the hit code carrying the largest SNR sum in each object
    codes = len(det.actor_ids) + 2
    votes = np.bincount(lab * codes + (det.hit.astype(np.int64) + 2), w, count * codes)
    best = votes.reshape(count, codes).argmax(1) - 2
    truth = np.full(count, "", dtype=object)
    truth[best == HIT_STATIC] = "static"
    actor = best >= 0
    truth[actor] = det.actor_ids[best[actor]]
    truth[best == HIT_NONE] = ""
    conf = np.clip(
        (best_snr - snr_threshold_db) / (cfg.full_confidence_snr_db - snr_threshold_db), 0.05, 1.0
    )
    m = len(keep)
    return ObjectList(
        time=det.time,
        source="radar",
        frame_to_world=det.sensor_to_world,
        object_id=np.arange(m, dtype=np.int64),
        cls=np.full(m, -1, np.int8),
        position=pos[keep],
        velocity=unit[keep] * rr[keep, None],
        size=np.full((m, 3), np.nan),
        confidence=conf[keep],
        truth=truth[keep],
    )


@njit(cache=True, nogil=True)
def linked_groups(
    xyz: np.ndarray, range_rate: np.ndarray, gate_m: float, gate_m_s: float
) -> tuple[int, np.ndarray]:
    """Connected groups of detections (``xyz`` (n, 3) m, ``range_rate`` (n,) m/s) linked when
    closer than ``gate_m`` and with range rates differing by less than ``gate_m_s``: (number of
    groups, group of each detection), groups numbered in the order of their first detection
    (as scipy's connected_components numbers them). The distance is numpy's
    ``norm(a - b)`` of three components, summed in the same order."""
    n = len(range_rate)
    parent = np.arange(n)
    for i in range(n):
        for j in range(i + 1, n):
            dx, dy, dz = xyz[i, 0] - xyz[j, 0], xyz[i, 1] - xyz[j, 1], xyz[i, 2] - xyz[j, 2]
            d = np.sqrt(dx * dx + dy * dy + dz * dz)
            if d < gate_m and abs(range_rate[i] - range_rate[j]) < gate_m_s:
                a, b = i, j
                while parent[a] != a:
                    a = parent[a]
                while parent[b] != b:
                    b = parent[b]
                if a != b:
                    parent[max(a, b)] = min(a, b)
    label = np.full(n, -1, np.int64)
    group = np.empty(n, np.int32)
    count = 0
    for v in range(n):
        r = v
        while parent[r] != r:
            r = parent[r]
        if label[r] < 0:
            label[r] = count
            count += 1
        group[v] = label[r]
    return count, group
