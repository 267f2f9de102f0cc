"""The kinematics kernel: poses, frame transforms, footprints, time to overlap and gaps.

One definition of each, over numpy arrays, for every package (traffic, sensors, risk, bridge).
The gaps and extents (footprint distance and extent, point-to-box distances) are loops over
the compiled scalar functions of :mod:`hiyari.kinematics_scalar`, which compiled kernels call
one row at a time (the OpenSCENARIO trigger kernel): one piece of code for each.

Frames and units. World: network coordinates in metres (x east, y north, z up). Vehicle frame:
origin at the centre of the actor's ground rectangle, x forward along its heading, y to its
left, z up. Headings in radians counter-clockwise from world +x. Speeds m/s, accelerations
m/s^2, times s. Vehicles are flat: a pose has no pitch or roll, so frame changes rotate x, y
about z and leave z as it is (plus the origin's z for points).

Shapes. A footprint is an oriented rectangle (centre, heading, length along the heading, width
across it). "First overlap" of two shapes translating at constant velocities is found by the
slab algorithm: along each separating axis the projections overlap during one time interval
(an interval of a 1-D slab), and the shapes overlap when every axis does, so the first overlap
is the latest entry over the axes if it precedes the earliest exit. A rectangle and a disc use
the same algorithm on the rectangle grown by the disc radius with rounded corners (the union of
two grown rectangles and four corner discs).

Array conventions: functions broadcast over leading axes; ``(..., 2)`` is x, y and
``(..., 3)`` is x, y, z. Rotations keep a float32 input float32 (the sensors cast rays in
float32); everything else is float64.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hiyari import kinematics_scalar as _scalar

#: Relative speed (m/s) along an axis below which the projections are taken as not moving.
STILL_SPEED = 1e-9


def _flat(*arrays: float | np.ndarray) -> tuple[tuple[int, ...], list[np.ndarray]]:
    """The broadcast shape of ``arrays`` and each of them broadcast to it, as a flat
    contiguous float64 array: the rows the compiled loops of kinematics_scalar take."""
    arrs = [np.asarray(a, float) for a in arrays]
    shape = np.broadcast_shapes(*(a.shape for a in arrs))
    # a broadcast view is copied, not passed on: numba warns on (and numpy will refuse)
    # writeable views from broadcast_arrays
    flat = [
        np.ascontiguousarray(a) if a.shape == shape else np.array(np.broadcast_to(a, shape))
        for a in arrs
    ]
    return shape, [a.reshape(-1) for a in flat]


# ---------------------------------------------------------------------------------- rotations
def _cos_sin(heading: float | np.ndarray, like: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """cos and sin of ``heading`` in the float type of ``like`` (float64 unless float32)."""
    c, s = np.cos(heading), np.sin(heading)
    if like.dtype == np.float32:
        return np.asarray(c, np.float32), np.asarray(s, np.float32)
    return c, s


def heading_vector(heading: float | np.ndarray) -> np.ndarray:
    """(..., 2) unit vectors along ``heading`` (rad), world frame."""
    return np.stack([np.cos(heading), np.sin(heading)], axis=-1)


def wrap_angle(angle: float | np.ndarray) -> np.ndarray:
    """Angles (rad) wrapped into (-pi, pi]."""
    return np.arctan2(np.sin(angle), np.cos(angle))


def point_ahead(
    xy: np.ndarray, heading: float | np.ndarray, distance: float | np.ndarray
) -> np.ndarray:
    """(..., 2) points ``distance`` m ahead of ``xy`` (..., 2) along ``heading`` (rad); behind
    for a negative distance (e.g. SUMO's front-bumper position <-> the rectangle centre)."""
    return np.asarray(xy, float) + np.asarray(distance, float)[..., None] * heading_vector(heading)


def rotate_xy(
    x: np.ndarray, y: np.ndarray, heading: float | np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Vehicle-frame vector components (``x`` forward, ``y`` left) -> world-frame components,
    for a vehicle at ``heading`` (rad). Component arrays broadcast with ``heading``."""
    x, y = np.asarray(x), np.asarray(y)
    c, s = _cos_sin(heading, x)
    return x * c - y * s, x * s + y * c


def unrotate_xy(
    x: np.ndarray, y: np.ndarray, heading: float | np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """World-frame vector components -> vehicle-frame components (forward, left) for a vehicle
    at ``heading`` (rad). The inverse of :func:`rotate_xy`."""
    x, y = np.asarray(x), np.asarray(y)
    c, s = _cos_sin(heading, x)
    return x * c + y * s, -x * s + y * c


def _with_xy(
    v: np.ndarray, x: np.ndarray, y: np.ndarray, z_offset: np.ndarray | None = None
) -> np.ndarray:
    """(..., 2 | 3) array with new x, y (and z of ``v`` plus ``z_offset`` when 3-D)."""
    if v.shape[-1] == 2:
        return np.stack([x, y], axis=-1)
    z = v[..., 2] if z_offset is None else v[..., 2] + z_offset
    return np.stack([x, y, np.broadcast_to(z, x.shape)], axis=-1)


def rotate(v: np.ndarray, heading: float | np.ndarray) -> np.ndarray:
    """(..., 2 | 3) vehicle-frame vectors -> world-frame vectors (z unchanged)."""
    v = np.asarray(v)
    x, y = rotate_xy(v[..., 0], v[..., 1], heading)
    return _with_xy(v, x, y)


def unrotate(v: np.ndarray, heading: float | np.ndarray) -> np.ndarray:
    """(..., 2 | 3) world-frame vectors -> vehicle-frame vectors (z unchanged)."""
    v = np.asarray(v)
    x, y = unrotate_xy(v[..., 0], v[..., 1], heading)
    return _with_xy(v, x, y)


def vehicle_to_world(
    points: np.ndarray, origin: np.ndarray, heading: float | np.ndarray
) -> np.ndarray:
    """(..., 2 | 3) points in the frame of a vehicle at ``origin`` (..., 2 | 3, world m) and
    ``heading`` (rad) -> world points. With 3-D points and a 2-D origin, z is kept."""
    p, o = np.asarray(points), np.asarray(origin)
    x, y = rotate_xy(p[..., 0], p[..., 1], heading)
    x, y = x + o[..., 0], y + o[..., 1]
    return _with_xy(p, x, y, o[..., 2] if p.shape[-1] == 3 and o.shape[-1] == 3 else None)


def world_to_vehicle(
    points: np.ndarray, origin: np.ndarray, heading: float | np.ndarray
) -> np.ndarray:
    """(..., 2 | 3) world points -> the frame of a vehicle at ``origin`` and ``heading``.
    The inverse of :func:`vehicle_to_world`."""
    p, o = np.asarray(points), np.asarray(origin)
    x, y = unrotate_xy(p[..., 0] - o[..., 0], p[..., 1] - o[..., 1], heading)
    return _with_xy(p, x, y, -o[..., 2] if p.shape[-1] == 3 and o.shape[-1] == 3 else None)


def rotation_2d(angle: float) -> np.ndarray:
    """(2, 2) matrix rotating vectors by ``angle`` (rad, counter-clockwise): a vehicle frame at
    that heading to the world (also turns covariances: R C R^T)."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s], [s, c]])


def pose_matrix(x: float, y: float, z: float, heading: float) -> np.ndarray:
    """(4, 4) homogeneous transform from a vehicle frame at (x, y, z, heading) to the world."""
    c, s = np.cos(heading), np.sin(heading)
    m = np.eye(4)
    m[:2, :2] = [[c, -s], [s, c]]
    m[:3, 3] = [x, y, z]
    return m


# ---------------------------------------------------------------------------------- the pose
@dataclass(frozen=True)
class Pose:
    """One actor's kinematic state: centre of its ground rectangle (x, y, z world m), heading
    (rad CCW from +x), speed (m/s, along the heading), acceleration (m/s^2 along the heading)
    and footprint length / width (m; 0 when unknown)."""

    x: float
    y: float
    z: float = 0.0
    heading: float = 0.0
    speed: float = 0.0
    accel: float = 0.0
    length: float = 0.0
    width: float = 0.0

    @property
    def position(self) -> np.ndarray:
        """(3,) world position, m."""
        return np.array([self.x, self.y, self.z])

    @property
    def velocity(self) -> np.ndarray:
        """(2,) velocity in the world frame, m/s."""
        return self.speed * np.array([np.cos(self.heading), np.sin(self.heading)])

    def to_world(self) -> np.ndarray:
        """(4, 4) transform from this vehicle's frame to the world."""
        return pose_matrix(self.x, self.y, self.z, self.heading)

    def world_to_vehicle(self, points: np.ndarray) -> np.ndarray:
        """(..., 2 | 3) world points -> this vehicle's frame."""
        p = np.asarray(points, dtype=float)
        origin = self.position if p.shape[-1] == 3 else self.position[:2]
        return world_to_vehicle(p, origin, self.heading)

    def vehicle_to_world(self, points: np.ndarray) -> np.ndarray:
        """(..., 2 | 3) points in this vehicle's frame -> world points."""
        p = np.asarray(points, dtype=float)
        origin = self.position if p.shape[-1] == 3 else self.position[:2]
        return vehicle_to_world(p, origin, self.heading)

    def world_to_vehicle_vec(self, v: np.ndarray) -> np.ndarray:
        """(..., 2 | 3) world-frame vectors -> this vehicle's axes (no translation)."""
        return unrotate(np.asarray(v, dtype=float), self.heading)

    def vehicle_to_world_vec(self, v: np.ndarray) -> np.ndarray:
        """(..., 2 | 3) vectors along this vehicle's axes -> world frame."""
        return rotate(np.asarray(v, dtype=float), self.heading)


# ---------------------------------------------------------------------------------- footprints
def footprint_corners(
    centre: np.ndarray,
    heading: float | np.ndarray,
    length: float | np.ndarray,
    width: float | np.ndarray,
) -> np.ndarray:
    """(..., 4, 2) corners of oriented rectangles, counter-clockwise from front-left, m.

    ``centre`` (..., 2) m, ``heading`` (...) rad, ``length`` / ``width`` (...) m.
    """
    centre = np.asarray(centre, dtype=float)
    fx, fy = rotate_xy(0.5 * np.asarray(length, float), 0.0, heading)
    lx, ly = rotate_xy(0.0, 0.5 * np.asarray(width, float), heading)
    fwd = np.stack(np.broadcast_arrays(fx, fy), axis=-1)
    left = np.stack(np.broadcast_arrays(lx, ly), axis=-1)
    return np.stack(
        [centre + fwd + left, centre - fwd + left, centre - fwd - left, centre + fwd - left],
        axis=-2,
    )


def box_corners(
    xyz: np.ndarray,
    heading: np.ndarray,
    length: np.ndarray,
    width: np.ndarray,
    height: np.ndarray,
) -> np.ndarray:
    """(N, 8, 3) corners of N upright boxes standing on their ground-rectangle centre ``xyz``
    (N, 3) m, world frame. Order: for x in (rear, front), y in (right, left), z in (0, top)."""
    unit = np.array([[a, b, h] for a in (-0.5, 0.5) for b in (-0.5, 0.5) for h in (0.0, 1.0)])
    size = np.stack([length, width, height], axis=1)
    local = unit[None] * size[:, None, :]
    return vehicle_to_world(local, np.asarray(xyz)[:, None, :], np.asarray(heading)[:, None])


def footprint_extent(
    length: np.ndarray, width: np.ndarray, heading: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Half extents (m) along a frame's x and y of rectangles at ``heading`` (rad, relative to
    that frame): the half sizes of their axis-aligned bounding boxes. Broadcasts."""
    shape, (length, width, heading) = _flat(length, width, heading)
    ex, ey = np.empty(len(length)), np.empty(len(length))
    _scalar.footprint_extent_rows(length, width, heading, ex, ey)
    return ex.reshape(shape), ey.reshape(shape)


def overlap_depth(corners_a: np.ndarray, corners_b: np.ndarray) -> np.ndarray:
    """(P,) penetration depth (m) of pairs of convex quadrilaterals by the separating-axis
    test; <= 0 means apart. ``corners_a``, ``corners_b``: (P, 4, 2), in order around each."""
    edges_a = corners_a[:, [1, 2]] - corners_a[:, [0, 1]]
    edges_b = corners_b[:, [1, 2]] - corners_b[:, [0, 1]]
    axes = np.concatenate([edges_a, edges_b], axis=1)  # (P, 4, 2)
    axes = axes / np.maximum(np.linalg.norm(axes, axis=2, keepdims=True), 1e-12)
    pa = np.einsum("pkc,pac->pak", corners_a, axes)  # (P, 4 axes, 4 corners)
    pb = np.einsum("pkc,pac->pak", corners_b, axes)
    overlap = np.minimum(pa.max(2), pb.max(2)) - np.maximum(pa.min(2), pb.min(2))
    return overlap.min(axis=1)


# ---------------------------------------------------------------------------------- time to overlap
def slab_interval(p: np.ndarray, v: np.ndarray, half: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Times (s) between which |p + v t| <= half: entry and exit of a 1-D slab.

    ``p`` relative position (m), ``v`` relative velocity (m/s), ``half`` the slab's half width
    (m), broadcasting. Not moving: (-inf, inf) when inside, (inf, -inf) when outside.
    """
    p, v, half = np.asarray(p, float), np.asarray(v, float), np.asarray(half, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        a = (-half - p) / v
        b = (half - p) / v
    still = np.abs(v) < STILL_SPEED
    inside = np.abs(p) <= half
    t_in = np.where(still, np.where(inside, -np.inf, np.inf), np.minimum(a, b))
    t_out = np.where(still, np.where(inside, np.inf, -np.inf), np.maximum(a, b))
    return t_in, t_out


def slab_entry_time(p: np.ndarray, v: np.ndarray, half: np.ndarray) -> np.ndarray:
    """First time t >= 0 (s) at which |p_k + v_k t| <= half_k along every axis k (the last
    axis of the (..., K) arrays); 0 when already inside, inf when never."""
    t_in, t_out = slab_interval(p, v, half)
    first, last = t_in.max(axis=-1), t_out.min(axis=-1)
    return np.where((first <= last) & (last >= 0), np.maximum(first, 0.0), np.inf)


def box_entry_time(
    p: np.ndarray, v: np.ndarray, half_x: np.ndarray, half_y: np.ndarray
) -> np.ndarray:
    """First time t >= 0 (s) at which the point ``p + v t`` (..., 2) lies in the box
    |x| <= ``half_x``, |y| <= ``half_y`` (box frame, m and m/s); 0 inside, inf never."""
    p, v = np.asarray(p, float), np.asarray(v, float)
    half = np.stack(np.broadcast_arrays(half_x, half_y), axis=-1)
    return slab_entry_time(p, v, half)


def disc_entry_time(q: np.ndarray, u: np.ndarray, radius: float) -> np.ndarray:
    """First time t >= 0 (s) at which |q + u t| <= ``radius`` (q (..., 2) m, u (..., 2) m/s);
    0 inside, inf never."""
    a = np.einsum("...k,...k->...", u, u)
    b = 2.0 * np.einsum("...k,...k->...", q, u)
    c = np.einsum("...k,...k->...", q, q) - radius * radius
    disc = b * b - 4.0 * a * c
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (-b - np.sqrt(np.maximum(disc, 0.0))) / (2.0 * a)
    hit = (disc >= 0) & (a > 0) & (t >= 0)
    return np.where(c <= 0, 0.0, np.where(hit, t, np.inf))


def rounded_box_entry_time(
    p: np.ndarray, v: np.ndarray, half_x: np.ndarray, half_y: np.ndarray, radius: float
) -> np.ndarray:
    """First time t >= 0 (s) at which the point ``p + v t`` comes within ``radius`` of the box
    |x| <= ``half_x``, |y| <= ``half_y``: a disc entering a rectangle (box frame).

    Exact: the rounded box is the union of two grown boxes and four corner discs, so its entry
    time is the earliest of theirs. 0 when already touching, inf when never.
    """
    p, v = np.asarray(p, float), np.asarray(v, float)
    hx, hy = np.asarray(half_x, float), np.asarray(half_y, float)
    t = np.minimum(box_entry_time(p, v, hx + radius, hy), box_entry_time(p, v, hx, hy + radius))
    for sx in (-1.0, 1.0):
        for sy in (-1.0, 1.0):
            corner = np.stack(np.broadcast_arrays(sx * hx, sy * hy), axis=-1)
            t = np.minimum(t, disc_entry_time(p - corner, v, radius))
    return t


def footprint_entry_time(
    rel_pos: np.ndarray,
    rel_vel: np.ndarray,
    rel_heading: np.ndarray,
    length_a: float | np.ndarray,
    width_a: float | np.ndarray,
    length_b: np.ndarray,
    width_b: np.ndarray,
    exact: bool = False,
) -> np.ndarray:
    """First time t >= 0 (s) at which rectangle B overlaps rectangle A, both translating.

    In A's frame: A centred at the origin along x; B's centre ``rel_pos`` (..., 2) m, velocity
    relative to A ``rel_vel`` (..., 2) m/s and heading ``rel_heading`` (...) rad. The slab test
    on A's two axes (B by its extent along them, :func:`footprint_extent`): exact for B aligned
    with A and conservative (never later) for a rotated B. ``exact`` adds B's own two axes,
    the full separating-axis test. 0 when overlapping now, inf when never.
    """
    p, v = np.asarray(rel_pos, float), np.asarray(rel_vel, float)
    la, wa = np.asarray(length_a, float), np.asarray(width_a, float)
    ext_x, ext_y = footprint_extent(length_b, width_b, rel_heading)
    hx, hy = ext_x + la / 2, ext_y + wa / 2
    if not exact:
        return box_entry_time(p, v, hx, hy)
    bu, bv = unrotate_xy(p[..., 0], p[..., 1], rel_heading)
    vu, vv = unrotate_xy(v[..., 0], v[..., 1], rel_heading)
    a_u, a_v = footprint_extent(la, wa, rel_heading)  # A seen from B's axes
    hu = np.asarray(length_b, float) / 2 + a_u
    hv = np.asarray(width_b, float) / 2 + a_v
    arrays = np.broadcast_arrays(p[..., 0], p[..., 1], bu, bv)
    pos = np.stack(arrays, axis=-1)
    vel = np.stack(np.broadcast_arrays(v[..., 0], v[..., 1], vu, vv), axis=-1)
    half = np.stack(np.broadcast_arrays(hx, hy, hu, hv), axis=-1)
    return slab_entry_time(pos, vel, half)


# ---------------------------------------------------------------------------------- gaps
def box_distance(p: np.ndarray, half_x: np.ndarray, half_y: np.ndarray) -> np.ndarray:
    """Distance (m) from points ``p`` (..., 2, box frame) to the box |x| <= ``half_x``,
    |y| <= ``half_y``; 0 inside."""
    p = np.asarray(p, float)
    shape, (x, y, hx, hy) = _flat(p[..., 0], p[..., 1], half_x, half_y)
    out = np.empty(len(x))
    _scalar.box_distance_rows(x, y, hx, hy, out)
    return out.reshape(shape)


def rectangle_point_distance(
    centre: np.ndarray,
    heading: np.ndarray,
    half_x: np.ndarray,
    half_y: np.ndarray,
    points: np.ndarray,
) -> np.ndarray:
    """Distance (m) from world ``points`` (..., 2) to oriented rectangles (centre (..., 2) m,
    ``heading`` rad, half length / width m) in the world; 0 inside. Broadcasts."""
    c, p = np.asarray(centre, float), np.asarray(points, float)
    shape, rows = _flat(c[..., 0], c[..., 1], heading, half_x, half_y, p[..., 0], p[..., 1])
    out = np.empty(len(rows[0]))
    _scalar.rectangle_point_distance_rows(*rows, out)
    return out.reshape(shape)


def bumper_gap(
    rel_pos: np.ndarray,
    length_a: float | np.ndarray,
    width_a: float | np.ndarray,
    length_b: np.ndarray,
    width_b: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Gaps (m) between rectangle A at the origin of its frame and rectangles B at
    ``rel_pos`` (..., 2) in that frame, both taken aligned with the frame.

    Returns (longitudinal, lateral): B's rear bumper minus A's front bumper along x (signed:
    negative when B is not ahead with clearance), and the side-to-side clearance along y
    (>= 0: B is beside A, out of its lane of travel).
    """
    p = np.asarray(rel_pos, float)
    along = p[..., 0] - (np.asarray(length_a, float) + length_b) / 2
    across = np.abs(p[..., 1]) - (np.asarray(width_a, float) + width_b) / 2
    return along, across


def footprint_distance(
    centre_a: np.ndarray,
    heading_a: float | np.ndarray,
    length_a: float | np.ndarray,
    width_a: float | np.ndarray,
    centre_b: np.ndarray,
    heading_b: float | np.ndarray,
    length_b: float | np.ndarray,
    width_b: float | np.ndarray,
) -> np.ndarray:
    """Shortest distance (m) between oriented rectangles A and B; 0 when they touch or overlap.

    Centres (..., 2) world m, headings (...) rad, lengths / widths (...) m; broadcasts. Two
    disjoint convex shapes are closest at a corner of one of them, so the distance is the least
    corner-to-rectangle distance both ways (:func:`hiyari.kinematics_scalar.footprint_distance`).
    """
    ca, cb = np.asarray(centre_a, float), np.asarray(centre_b, float)
    shape, rows = _flat(
        ca[..., 0], ca[..., 1], heading_a, length_a, width_a,
        cb[..., 0], cb[..., 1], heading_b, length_b, width_b,
    )  # fmt: skip
    out = np.empty(len(rows[0]))
    _scalar.footprint_distance_rows(*rows, out)
    return out.reshape(shape)
