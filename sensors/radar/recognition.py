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
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

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
    d = np.linalg.norm(xyz[:, None] - xyz[None], axis=2)
    dv = np.abs(det.range_rate[:, None] - det.range_rate[None])
    i, j = np.nonzero((d < cfg.gate_m) & (dv < cfg.gate_m_s))
    graph = coo_matrix((np.ones(len(i)), (i, j)), shape=(n, n))
    count, lab = connected_components(graph, directed=False)
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
