"""Line of sight in the ground truth: could a sensor on the ego see an actor, or do other
actors' footprints hide it?

Plain arrays in (a WorldState's columns: world metres, radians CCW from +x). The check is 2-D:
every other actor's footprint is an obstacle as tall as the line of sight, which holds for cars
and trucks seen from a car's sensors and for anything behind them. An actor counts as in sight
when a straight line from the eye reaches its centre or one of its corners without crossing
another footprint: a partly hidden car still gives a sensor something to detect.
"""

from __future__ import annotations

import numpy as np

from hiyari.kinematics import footprint_corners, slab_interval, unrotate


def in_line_of_sight(
    xy: np.ndarray,
    heading: np.ndarray,
    length: np.ndarray,
    width: np.ndarray,
    viewer: int,
    target: int,
) -> bool:
    """Whether actor ``target`` is in line of sight from the centre of actor ``viewer`` (rows of
    the (N, 2) ``xy`` m, ``heading`` rad, ``length`` / ``width`` m arrays), past the footprints
    of every other actor."""
    others = np.flatnonzero((np.arange(len(xy)) != viewer) & (np.arange(len(xy)) != target))
    eye = xy[viewer]
    corners = footprint_corners(xy[target], heading[target], length[target], width[target])
    aims = np.vstack([xy[target][None, :], corners])  # (5, 2)
    if not len(others):
        return True
    # every aim against every other footprint, in that footprint's frame: the segment
    # eye + (aim - eye) t, t in [0, 1], against the slab |p| <= half on both axes
    p = unrotate((eye - xy[others])[:, None, :], heading[others][:, None])  # (M, 1, 2)
    v = unrotate((aims - eye)[None, :, :], heading[others][:, None])  # (M, 5, 2)
    half = np.stack([length[others], width[others]], axis=-1)[:, None, :] / 2
    t_in, t_out = slab_interval(np.broadcast_to(p, v.shape), v, half)
    first, last = t_in.max(axis=-1), t_out.min(axis=-1)
    blocked = (first <= last) & (last >= 0.0) & (first <= 1.0)  # (M, 5)
    return bool((~blocked.any(axis=0)).any())
