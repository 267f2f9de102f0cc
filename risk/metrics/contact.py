"""Vehicle–pedestrian risk metrics: time to contact, Safety Cushion Time, post-encroachment time.

Frames and units: SUMO network coordinates in metres, headings in radians counter-clockwise
from +x, speeds in m/s, times in seconds (docs/models.md §2). Contact geometry: the vehicle is its
ground rectangle grown by a margin on every side, the pedestrian a disc; they touch when the
disc centre comes within the disc radius of the grown rectangle.

- Time to contact (TTC): both keep their current velocity (the vehicle translates along its
  heading without turning); solved in closed form per pair.
- Safety Cushion Time (SCT): the vehicle moves along its route (a centre-line polyline) at its
  current speed or any speed profile; the pedestrian keeps its velocity or, when it stands or
  walks on the kerb within reach of the carriageway or a crossing and faces it, steps in at
  walking speed (dart-out hypothesis). Sampled over the horizon, refined by interpolation.
- Post-encroachment time (PET): for a vehicle and a pedestrian on a crossing, the time from
  one leaving their conflict zone (where the vehicle's swept path meets the pedestrian's line
  along the crossing) to the other entering it; 0 if both are in it at once.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import shapely

from hiyari.jit import njit
from hiyari.kinematics import (
    heading_vector,
    rectangle_point_distance,
    rounded_box_entry_time,
    unrotate,
)
from hiyari.risk.metrics.pedestrian_geometry import KerbSegments


@dataclass(frozen=True)
class ContactGeometry:
    """Shapes that touch: vehicle rectangle grown by ``vehicle_margin`` (m) on every side, and
    a pedestrian disc of ``pedestrian_radius`` (m)."""

    vehicle_margin: float = 0.0
    pedestrian_radius: float = 0.3


@dataclass(frozen=True)
class SCTConfig:
    """Safety Cushion Time model (docs/models.md §2; values are the toolkit's choices).

    vehicle_margin: m added around the vehicle rectangle.
    pedestrian_radius: m, the pedestrian disc.
    horizon: s, SCT is infinite when no contact is predicted within it.
    time_step: s between prediction samples (contact times are interpolated between them).
    dart_out_distance: m, a pedestrian on the kerb this close to the carriageway edge or a
        crossing end, facing it, is assumed to step in (dart-out hypothesis).
    dart_out_speed: m/s, walking speed of the step-in (or the pedestrian's own, if faster).
    dart_out_max_angle_deg: a pedestrian "faces" the kerb when its heading is within this
        angle of the direction into the carriageway / along the crossing.
    speed_factors: the careful driver does not bet on a pedestrian's exact speed: each
        prediction (constant velocity or dart-out) is also evaluated at these multiples of its
        speed (0: stops where it is), and SCT is the earliest contact among them. (1.0,) gives
        the plain single-prediction SCT of docs/models.md §2.
    """

    vehicle_margin: float = 0.2
    pedestrian_radius: float = 0.3
    horizon: float = 10.0
    time_step: float = 0.2
    dart_out_distance: float = 1.5
    dart_out_speed: float = 1.3
    dart_out_max_angle_deg: float = 60.0
    speed_factors: tuple[float, ...] = (0.0, 0.25, 0.5, 1.0, 1.5)

    @property
    def contact(self) -> ContactGeometry:
        return ContactGeometry(self.vehicle_margin, self.pedestrian_radius)

    @property
    def times(self) -> np.ndarray:
        """(K,) prediction sample times 0 .. horizon, s."""
        n = int(round(self.horizon / self.time_step))
        return np.arange(n + 1) * self.time_step


# ---------------------------------------------------------------------------- time to contact
def time_to_contact(
    veh_xy: np.ndarray,
    veh_heading: np.ndarray,
    veh_velocity: np.ndarray,
    veh_length: np.ndarray,
    veh_width: np.ndarray,
    ped_xy: np.ndarray,
    ped_velocity: np.ndarray,
    contact: ContactGeometry = ContactGeometry(),
    horizon: float = math.inf,
) -> np.ndarray:
    """(P,) time to contact, s, of P vehicle–pedestrian pairs at constant velocity.

    Vehicle: rectangle centre ``veh_xy`` (P, 2) m, ``veh_heading`` (P,) rad, velocity (P, 2)
    m/s, length / width (P,) m. Pedestrian: disc centre (P, 2) m, velocity (P, 2) m/s.
    0 when already touching; inf when they never touch or only after ``horizon`` s.
    """
    p = unrotate(np.asarray(ped_xy, float) - veh_xy, veh_heading)
    u = unrotate(np.asarray(ped_velocity, float) - veh_velocity, veh_heading)
    hl = 0.5 * np.asarray(veh_length, float) + contact.vehicle_margin
    hw = 0.5 * np.asarray(veh_width, float) + contact.vehicle_margin
    t = rounded_box_entry_time(p, u, hl, hw, contact.pedestrian_radius)
    return np.where(t <= horizon, t, np.inf)


def contact_gap(
    veh_xy: np.ndarray,
    veh_heading: np.ndarray,
    veh_length: np.ndarray,
    veh_width: np.ndarray,
    ped_xy: np.ndarray,
    contact: ContactGeometry = ContactGeometry(),
) -> np.ndarray:
    """Distance (m) between the grown vehicle rectangle and the pedestrian disc; <= 0 touching.

    Broadcasts over any leading axes (pairs, candidates, samples).
    """
    half_x = 0.5 * veh_length + contact.vehicle_margin
    half_y = 0.5 * veh_width + contact.vehicle_margin
    distance = rectangle_point_distance(veh_xy, veh_heading, half_x, half_y, ped_xy)
    return distance - contact.pedestrian_radius


def unprotected(
    gap: np.ndarray, ped_xy: np.ndarray, carriageway: shapely.Geometry | None = None
) -> np.ndarray:
    """``gap`` (...) with +inf where the pedestrian position ``ped_xy`` (..., 2) lies outside
    ``carriageway`` (a shapely geometry, e.g. NetGeometry.carriageway): a pedestrian off the
    carriageway cannot be hit. None: exposed everywhere."""
    if carriageway is None or carriageway.is_empty:
        return gap
    exposed = shapely.contains_xy(carriageway, ped_xy[..., 0], ped_xy[..., 1])
    return np.where(exposed, gap, np.inf)


def first_contact_time(gap: np.ndarray, times: np.ndarray) -> np.ndarray:
    """First time at which sampled ``gap`` (..., K) reaches 0, linearly interpolated between
    samples at ``times`` (K,) s; inf when it never does."""
    shape = gap.shape[:-1]
    g = gap.reshape(-1, gap.shape[-1])
    rows = np.arange(len(g))
    k = np.argmax(g <= 0.0, axis=1)
    g1 = g[rows, k]
    km = np.maximum(k - 1, 0)
    g0 = g[rows, km]
    with np.errstate(divide="ignore", invalid="ignore"):
        # an infinite gap before (a protected position) means contact starts at the sample
        frac = np.where(np.isfinite(g0), g0 / (g0 - g1), 1.0)
    frac = np.where(k > 0, np.clip(frac, 0.0, 1.0), 0.0)
    t = times[km] + (times[k] - times[km]) * frac
    return np.where(g1 <= 0.0, t, np.inf).reshape(shape)


# ---------------------------------------------------------------------------- vehicle paths
@dataclass(frozen=True)
class Path:
    """A centre-line polyline (M, 2) m with cumulative arc length (M,) m."""

    points: np.ndarray
    cum: np.ndarray

    @staticmethod
    def of(points: np.ndarray) -> Path:
        seg = np.linalg.norm(np.diff(points, axis=0), axis=1)
        return Path(np.asarray(points, float), np.concatenate([[0.0], np.cumsum(seg)]))

    @staticmethod
    def straight(xy: np.ndarray, heading: float, length: float = 1000.0) -> Path:
        """A straight path through ``xy`` along ``heading`` (for vehicles without a route)."""
        u = heading_vector(heading)
        return Path.of(np.stack([xy - length * u, xy + length * u]))

    def project(self, xy: np.ndarray) -> float:
        """Arc length (m) of the point of the path nearest to ``xy``."""
        p0, p1 = self.points[:-1], self.points[1:]
        seg = p1 - p0
        L2 = np.maximum(np.einsum("ij,ij->i", seg, seg), 1e-12)
        f = np.clip(np.einsum("ij,ij->i", xy - p0, seg) / L2, 0.0, 1.0)
        d = np.linalg.norm(p0 + f[:, None] * seg - xy, axis=1)
        k = int(np.argmin(d))
        return float(self.cum[k] + f[k] * math.sqrt(L2[k]))

    def at(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(xy (..., 2), heading (...)) at arc lengths ``s`` (any shape); beyond either end the
        end segment is continued straight."""
        k = np.clip(np.searchsorted(self.cum, s, side="right") - 1, 0, len(self.cum) - 2)
        p0 = self.points[k]
        seg = self.points[k + 1] - p0
        L = self.cum[k + 1] - self.cum[k]
        u = seg / np.maximum(L, 1e-12)[..., None]
        xy = p0 + u * (s - self.cum[k])[..., None]
        return xy, np.arctan2(u[..., 1], u[..., 0])


# ---------------------------------------------------------------------------- pedestrians
@njit(cache=True)
def _predict(
    xy: np.ndarray,
    u: np.ndarray,
    speed: np.ndarray,
    rows: np.ndarray,
    facing: np.ndarray,
    a: np.ndarray,
    b: np.ndarray,
    inward: np.ndarray,
    crossing: np.ndarray,
    open_crossings: np.ndarray,
    cos_max: float,
    reach: float,
    dart_speed: float,
) -> tuple[np.ndarray, np.ndarray]:
    """Velocities (P, 2) and dart-out flags (P,) of pedestrians at ``xy`` (P, 2) heading along
    ``u`` (P, 2) at ``speed`` (P,): each of ``rows`` (R,) (on a footway) steps in along the
    inward normal of the nearest usable kerb segment it faces within ``reach`` m (``facing``
    (R, K): its heading within the angle of each segment's normal); ``open_crossings`` (C,)
    (empty: all open) says which crossings' ends are usable."""
    n, m = len(xy), len(a)
    vel = np.empty((n, 2))
    for p in range(n):
        vel[p, 0] = speed[p] * u[p, 0]
        vel[p, 1] = speed[p] * u[p, 1]
    dart = np.zeros(n, np.bool_)
    ab = np.empty((m, 2))
    length2 = np.empty(m)
    usable = np.empty(m, np.bool_)
    for k in range(m):
        ab[k, 0] = b[k, 0] - a[k, 0]
        ab[k, 1] = b[k, 1] - a[k, 1]
        length2[k] = max(ab[k, 0] * ab[k, 0] + ab[k, 1] * ab[k, 1], 1e-12)
        usable[k] = crossing[k] < 0 or len(open_crossings) == 0 or open_crossings[crossing[k]]
    for i in range(len(rows)):
        p = rows[i]
        low = np.inf
        best = -1
        for k in range(m):
            # nearest point of segment k: the numpy steps of the reference, per scalar
            apx = xy[p, 0] - a[k, 0]
            apy = xy[p, 1] - a[k, 1]
            f = (apx * ab[k, 0] + apy * ab[k, 1]) / length2[k]
            f = min(max(f, 0.0), 1.0)
            tx = f * ab[k, 0] - apx
            ty = f * ab[k, 1] - apy
            dist = math.sqrt(tx * tx + ty * ty)
            ok = facing[i, k]
            if not ok and crossing[k] >= 0 and dist > 0.1:
                # crossing ends: also walking towards the crossing's end (round the corner)
                ok = u[p, 0] * tx + u[p, 1] * ty >= cos_max * max(dist, 1e-9)
            if ok and usable[k] and dist <= reach and dist < low:
                low = dist
                best = k
        if best >= 0:
            step = max(speed[p], dart_speed)
            vel[p, 0] = step * inward[best, 0]
            vel[p, 1] = step * inward[best, 1]
            dart[p] = True
    return vel, dart


def pedestrian_velocity(
    xy: np.ndarray,
    heading: np.ndarray,
    speed: np.ndarray,
    on_kerb: np.ndarray,
    kerbs: KerbSegments | None,
    config: SCTConfig = SCTConfig(),
    open_crossings: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Predicted velocities (P, 2) m/s and dart-out flags (P,) for P pedestrians.

    ``on_kerb`` (P,) marks pedestrians on a footway (sidewalk / walking area). Those within
    ``dart_out_distance`` of a kerb segment and facing it step in along its inward direction at
    walking speed; the others keep their velocity. Facing: the heading is within
    ``dart_out_max_angle_deg`` of the inward direction or, for crossing ends, of the direction
    to the crossing end (a pedestrian walking round the corner to the crossing). ``open_crossings`` (C,) bool: crossings pedestrians may enter now
    (signals); ends of closed crossings do not count. None: all open. Among several kerbs the
    nearest counts (the first of equals). Compiled (one pass); the facing test stays numpy's
    matrix product.
    """
    u = heading_vector(heading)
    if kerbs is None or len(kerbs) == 0 or not on_kerb.any():
        return speed[:, None] * u, np.zeros(len(xy), bool)
    rows = np.flatnonzero(on_kerb)
    cos_max = math.cos(math.radians(config.dart_out_max_angle_deg))
    facing = u[rows] @ kerbs.inward.T >= cos_max
    opened = np.zeros(0, bool) if open_crossings is None else np.asarray(open_crossings, bool)
    return _predict(
        np.ascontiguousarray(xy, float),
        u,
        np.asarray(speed, float),
        rows,
        facing,
        kerbs.a,
        kerbs.b,
        kerbs.inward,
        kerbs.crossing,
        opened,
        cos_max,
        float(config.dart_out_distance),
        float(config.dart_out_speed),
    )


def pedestrian_tracks(
    ped_xy: np.ndarray, ped_velocity: np.ndarray, speed_factors: np.ndarray, times: np.ndarray
) -> np.ndarray:
    """(P, H, K, 2) predicted positions, m: each pedestrian moving along its predicted velocity
    at each of the H ``speed_factors`` (x its predicted speed), at the K ``times`` s."""
    v = ped_velocity[:, None, :] * np.asarray(speed_factors, float)[None, :, None]
    return ped_xy[:, None, None, :] + v[:, :, None, :] * times[None, None, :, None]


def safety_cushion_time(
    veh_xy: np.ndarray,
    veh_heading: np.ndarray,
    veh_length: np.ndarray,
    veh_width: np.ndarray,
    ped_xy: np.ndarray,
    ped_velocity: np.ndarray,
    config: SCTConfig = SCTConfig(),
    carriageway: shapely.Geometry | None = None,
) -> np.ndarray:
    """SCT (s) of vehicle–pedestrian pairs from predicted vehicle poses.

    ``veh_xy`` (..., P, K, 2) and ``veh_heading`` (..., P, K): the vehicle rectangle centre and
    heading at the K sample times of ``config.times`` (from a Path and a speed profile);
    ``veh_length`` / ``veh_width`` (P,) m; ``ped_xy`` (P, 2) now and ``ped_velocity`` (P, 2)
    predicted. Leading axes (e.g. candidate speed profiles) broadcast. The earliest contact over
    the pedestrian speed hypotheses ``config.speed_factors``, counting only positions on the
    ``carriageway`` (see unprotected); inf: none within the horizon.
    """
    t = config.times
    ped = pedestrian_tracks(ped_xy, ped_velocity, config.speed_factors, t)
    gap = contact_gap(
        veh_xy[..., None, :, :],
        veh_heading[..., None, :],
        veh_length[:, None, None],
        veh_width[:, None, None],
        ped,
        config.contact,
    )
    return first_contact_time(unprotected(gap, ped, carriageway), t).min(axis=-1)


# ---------------------------------------------------------------------------- PET
@dataclass(frozen=True)
class PetEvent:
    """One road user reaching a pair's conflict zone ``pet`` s after the other left it (0: both
    in it at once)."""

    time: float
    vehicle: str
    pedestrian: str
    pet: float


def crossing_conflict(
    path: Path,
    s_vehicle: float,
    veh_length: float,
    veh_width: float,
    ped_xy: np.ndarray,
    ped_direction: np.ndarray,
    crossing_centre: np.ndarray,
    crossing_half_length: np.ndarray,
    ped_radius: float = 0.3,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Occupancy of the conflict zones of one vehicle with P pedestrians on crossings.

    The zone of a pair is where the vehicle's swept strip (its path, +- half its width) meets
    the pedestrian's (its line along the crossing, ``ped_direction`` (P, 2), +- ``ped_radius``),
    at the point X where the path crosses that line inside the crossing (centre (P, 2), half
    length (P,) m along it). Returns (has_zone, vehicle_in, pedestrian_in), each (P,) bool:
    the vehicle rectangle (centre at arc length ``s_vehicle`` m) overlaps the zone; the
    pedestrian disc overlaps the vehicle's strip at X.
    """
    a, b = path.points[:-1], path.points[1:]
    d = b - a  # (M, 2)
    seg_len = np.linalg.norm(d, axis=1)
    u = ped_direction[:, None, :]  # (P, 1, 2)
    ap = a[None] - ped_xy[:, None, :]  # (P, M, 2)
    det = -u[..., 0] * d[None, :, 1] + u[..., 1] * d[None, :, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        lam = (-ap[..., 0] * d[None, :, 1] + ap[..., 1] * d[None, :, 0]) / det
        mu = (u[..., 0] * ap[..., 1] - u[..., 1] * ap[..., 0]) / det
        x = ped_xy[:, None, :] + lam[..., None] * u
    along = np.einsum("pmj,pj->pm", x - crossing_centre[:, None, :], ped_direction)
    ok = (
        (np.abs(det) > 1e-9)
        & (mu >= 0)
        & (mu <= 1)
        & (np.abs(along) <= crossing_half_length[:, None])
    )
    has = ok.any(axis=1)
    k = np.argmax(ok, axis=1)
    rows = np.arange(len(ped_xy))
    s_x = path.cum[k] + mu[rows, k] * seg_len[k]
    sin = np.abs(det[rows, k]) / np.maximum(seg_len[k], 1e-12)
    sin = np.maximum(sin, 0.3)  # near-parallel paths: cap the stretch of the zone
    cot = np.sqrt(np.maximum(1.0 - sin**2, 0.0)) / sin
    veh_in = np.abs(s_vehicle - s_x) <= 0.5 * veh_length + ped_radius / sin + 0.5 * veh_width * cot
    ped_in = np.abs(lam[rows, k]) <= (0.5 * veh_width + ped_radius) / sin
    return has, has & veh_in, has & ped_in


class PostEncroachmentTracker:
    """Post-encroachment time per vehicle–pedestrian pair at crossings.

    Each step gives, per pair, whether each road user occupies the pair's conflict zone
    (crossing_conflict); PET is the time from one leaving it to the other entering it, and 0
    when both are in it at once. Exits are remembered for ``memory`` s, so PETs up to that
    are reported. A pair missing from a step counts as both outside.
    """

    def __init__(self, memory: float = 5.0) -> None:
        self.memory = memory
        self.reset()

    def reset(self) -> None:
        """Forget every pair (after steps were skipped)."""
        # key -> [vehicle in, pedestrian in, time vehicle left, time pedestrian left]
        self._pairs: dict[tuple[str, str], list] = {}

    def update(
        self,
        time: float,
        keys: list[tuple[str, str]],
        veh_in: np.ndarray,
        ped_in: np.ndarray,
    ) -> list[PetEvent]:
        """Advance to ``time`` (s) with the occupancy of each (vehicle, pedestrian) pair in
        ``keys``; return the PET events of this step."""
        events: list[PetEvent] = []
        seen = set()
        for key, vin, pin in zip(keys, veh_in.tolist(), ped_in.tolist(), strict=True):
            seen.add(key)
            st = self._pairs.get(key)
            if st is None:
                st = self._pairs[key] = [False, False, -math.inf, -math.inf]
            was_v, was_p, left_v, left_p = st
            if was_v and not vin:
                left_v = time
            if was_p and not pin:
                left_p = time
            if vin and pin and not (was_v and was_p):
                events.append(PetEvent(time, key[0], key[1], 0.0))
            elif vin and not was_v and time - left_p <= self.memory:
                events.append(PetEvent(time, key[0], key[1], time - left_p))
            elif pin and not was_p and time - left_v <= self.memory:
                events.append(PetEvent(time, key[0], key[1], time - left_v))
            self._pairs[key] = [vin, pin, left_v, left_p]
        for key in [k for k in self._pairs if k not in seen]:
            was_v, was_p, left_v, left_p = self._pairs[key]
            left_v = time if was_v else left_v
            left_p = time if was_p else left_p
            if time - max(left_v, left_p) > self.memory:
                del self._pairs[key]
            else:
                self._pairs[key] = [False, False, left_v, left_p]
        return events
