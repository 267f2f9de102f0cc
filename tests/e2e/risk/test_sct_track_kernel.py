"""The SCT model's fused per-step passes equal the numpy / shapely code they replace, bit for bit:
the pedestrians' predictions (track_kernel), the carriageway test on repeated points, the
controller's reach bound, the crossing occupancy of pairs, and a step evaluated on rows of the
full state against the same step on the state cut down to those rows (as the study did)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
import shapely

from hiyari.bridge.loop.drivers.sct_controller import SCTController
from hiyari.kinematics import heading_vector
from hiyari.net.sumo.build import IntersectionParams, build_intersection
from hiyari.risk.metrics.contact import (
    crossing_conflict,
    pedestrian_tracks,
    pedestrian_velocity,
)
from hiyari.risk.metrics.pedestrian_geometry import NetGeometry
from hiyari.risk.sct.area_kernel import AreaTest, locate_xy
from hiyari.risk.sct.contact_kernel import within_reach
from hiyari.risk.sct.model import SCTModel
from hiyari.traffic.actor_class import ActorClass
from hiyari.traffic.world_state import WorldState

#: compiled kernels against numpy formulas: CI runs these again with numpy's dispatch limited
pytestmark = pytest.mark.kernels

ARMS = ("n", "e", "s", "w")


@pytest.fixture(scope="module")
def geometry(tmp_path_factory: pytest.TempPathFactory) -> NetGeometry:
    net = build_intersection(tmp_path_factory.mktemp("track") / "x.net.xml", IntersectionParams())
    return NetGeometry.from_net(net)


def _scene(
    rng: np.random.Generator, geometry: NetGeometry, model: SCTModel, outside: int = 0
) -> WorldState:
    """Vehicles on random routes near the junction, pedestrians on kerbs, crossings and the
    carriageway's boundary (some standing still), and ``outside`` actors of each kind far
    away, interleaved by id as SUMO lists them."""
    nv, npd = int(rng.integers(1, 5)), int(rng.integers(1, 8))
    centre = geometry.junction_xy[0]
    vehicles, persons = [], []
    for k in range(nv):
        a, b = rng.choice(len(ARMS), 2, replace=False)
        vid = f"veh{k}"
        model.set_route(vid, (f"{ARMS[a]}_in", f"{ARMS[b]}_out"))
        path = model._paths[vid]
        s = rng.uniform(0.7, 1.0) * np.linalg.norm(path.points[0] - centre)
        p, h = path.at(np.array(s))
        vehicles.append((vid, p + rng.normal(0.0, 0.2, 2), float(h) + rng.normal(0.0, 0.02)))
    ring = shapely.get_coordinates(shapely.get_rings(shapely.get_parts(geometry.carriageway)))
    lanes = sorted(geometry.footway_lanes) + list(geometry.crossings.lanes)
    cr = geometry.crossings
    for k in range(npd):
        c = int(rng.integers(len(cr)))
        xy = cr.centre[c] + rng.uniform(-1.3, 1.3) * cr.half_length[c] * cr.direction[c]
        if k % 3 == 0:  # on a vertex of the carriageway: GEOS decides
            xy = ring[int(rng.integers(len(ring)))]
        persons.append((f"ped{k}", xy, rng.uniform(-np.pi, np.pi), lanes[rng.integers(len(lanes))]))
    for k in range(outside):
        vehicles.append((f"veh{k}x", centre + 500.0 + k, 0.0))
        persons.append((f"ped{k}x", centre - 500.0 - k, 1.0, lanes[0]))
    vehicles.sort(key=lambda v: v[0])
    persons.sort(key=lambda p: p[0])
    nv, npd = len(vehicles), len(persons)
    n = nv + npd
    speed = np.concatenate(
        [rng.uniform(0, 14, nv) * (rng.random(nv) > 0.2), rng.uniform(0, 2, npd)]
    )
    speed[nv::2] = 0.0  # pedestrians standing still: their tracks repeat one point
    size = np.concatenate([np.full(nv, 4.5), np.full(npd, 0.5)])
    lane = np.array([""] * nv + [p[3] for p in persons], dtype=object)
    return WorldState(
        0.0,
        np.array([v[0] for v in vehicles] + [p[0] for p in persons], object),
        np.array([ActorClass.CAR] * nv + [ActorClass.PEDESTRIAN] * npd, np.int8),
        np.column_stack(
            [np.array([v[1] for v in vehicles] + [p[1] for p in persons]), np.zeros(n)]
        ),
        np.array([v[2] for v in vehicles] + [p[2] for p in persons]),
        speed,
        np.concatenate([rng.uniform(-3, 2, nv), np.zeros(npd)]),
        size,
        size * 0.4,
        size,
        lane,
        lane.copy(),
    )


def _contains(area: shapely.Geometry | None, points: np.ndarray) -> np.ndarray:
    if area is None:
        return np.ones(points.shape[:-1], bool)
    return shapely.contains_xy(area, points[..., 0], points[..., 1])


@pytest.mark.parametrize("area", ["rings", "geos", "none"])
def test_predictions_equal_numpy_and_shapely(geometry: NetGeometry, area: str) -> None:
    """prepare's one pass gives pedestrian_velocity, pedestrian_tracks, the pair metrics'
    constant-velocity tracks and shapely.contains_xy of both, with the carriageway counted in
    locate_xy (GEOS for the boundary points), given to GEOS whole, or absent."""
    rings = AreaTest(geometry.carriageway).rings  # to count the boundary points met
    if area == "geos":  # a collection: AreaTest cannot count it, GEOS answers every point
        geometry = replace(geometry, carriageway=shapely.GeometryCollection([geometry.carriageway]))
    model = SCTModel(geometry if area != "none" else None)
    routes = SCTModel(geometry)  # the scenes' vehicle routes
    carriageway = model.carriageway
    rng = np.random.default_rng(5)
    boundary = darts = 0
    for _ in range(150):
        state = _scene(rng, geometry, routes)
        opened = rng.random(len(geometry.crossings)) > 0.3
        for predict in (True, False):
            view = model.prepare(state, opened, predict)
            ped = view.ped_rows
            xy, heading, speed = state.xyz[ped, :2], state.heading[ped], state.speed[ped]
            u = heading_vector(heading)
            cv = xy[:, None, :] + (u * speed[:, None])[:, None, :] * model.times[None, :, None]
            assert view.cv_tracks.tobytes() == cv.tobytes()
            assert np.array_equal(view.cv_exposed, _contains(carriageway, cv))
            if not predict:
                assert view.tracks is None and view.exposed is None
                assert np.isnan(view.ped_velocity).all() and not view.dart_out.any()
                continue
            on_kerb = np.array([ln in geometry.footway_lanes for ln in state.lane[ped]], bool)
            kerbs = geometry.kerbs if area != "none" else None
            vel, dart = pedestrian_velocity(
                xy, heading, speed, on_kerb, kerbs, model.config, opened
            )
            tracks = pedestrian_tracks(xy, vel, model.config.speed_factors, model.times)
            assert view.ped_velocity.tobytes() == vel.tobytes()
            assert np.array_equal(view.dart_out, dart)
            assert view.tracks.tobytes() == tracks.tobytes()
            assert np.array_equal(view.exposed, _contains(carriageway, tracks))
            darts += int(dart.sum())
        boundary += int((locate_xy(view.cv_tracks.reshape(-1, 2), *rings) < 0).sum())
    # the scenes exercise the dart-out (no kerbs without a geometry) and GEOS's boundary
    # answers, not only plain walkers
    assert (darts > 20 or area == "none") and boundary > 20


def test_repeated_points_take_the_answer_of_the_first(geometry: NetGeometry) -> None:
    """locate_xy answers a run of equal points as each point alone (inside, outside and on
    the boundary)."""
    rings = AreaTest(geometry.carriageway).rings
    ring = shapely.get_coordinates(shapely.get_rings(shapely.get_parts(geometry.carriageway)))
    rng = np.random.default_rng(3)
    lo, hi = ring.min(axis=0), ring.max(axis=0)
    points = np.concatenate([rng.uniform(lo, hi, (300, 2)), ring])
    runs = np.repeat(points[rng.permutation(len(points))], rng.integers(1, 6, len(points)), 0)
    alone = np.array([locate_xy(p[None], *rings)[0] for p in runs])
    got = locate_xy(runs, *rings)
    assert np.array_equal(got, alone)
    assert {-1, 0, 1} <= set(got.tolist())


def test_step_on_rows_equals_step_on_the_cut_state(geometry: NetGeometry) -> None:
    """A step evaluated on vehicle and pedestrian rows of the full state (the study now) gives
    the view, pair metrics, crossing occupancy, reach bound and plans of the same step on the
    state cut down to those rows (the study before), bit for bit."""
    model = SCTModel(geometry)
    ctrl = SCTController(model)
    rng = np.random.default_rng(9)
    occupied = 0
    for _ in range(100):
        full = _scene(rng, geometry, model, outside=int(rng.integers(0, 3)))
        far = np.hypot(*(full.xyz[:, :2] - geometry.junction_xy[0]).T) > 400.0
        vin = np.flatnonzero(full.is_vehicle & ~far)
        pin = np.flatnonzero(full.is_pedestrian & ~far)
        rows = np.concatenate([vin, pin])
        cut = full.select(rows)
        vi, pj = (a.ravel() for a in np.meshgrid(vin, pin, indexing="ij"))
        remap = np.full(len(full), -1)
        remap[rows] = np.arange(len(rows))
        opened = rng.random(len(geometry.crossings)) > 0.3
        a = model.prepare(cut, opened, True)
        b = model.prepare(full, opened, True, (vin, pin))
        assert np.array_equal(b.veh_rows, vin) and np.array_equal(b.ped_rows, pin)
        assert np.array_equal(a.veh_slot[remap[vin]], b.veh_slot[vin])
        assert np.array_equal(a.ped_slot[remap[pin]], b.ped_slot[pin])
        for name in ("s0", "ped_velocity", "dart_out", "crossing", "tracks", "exposed"):
            assert getattr(a, name).tobytes() == getattr(b, name).tobytes(), name
        for got, want in zip(
            model.pair_metrics(b, vi, pj), model.pair_metrics(a, remap[vi], remap[pj]), strict=True
        ):
            assert got.tobytes() == want.tobytes()
        for got, want in zip(
            model.crossing_occupancy(b, vi, pj),
            model.crossing_occupancy(a, remap[vi], remap[pj]),
            strict=True,
        ):
            assert np.array_equal(got, want)
            occupied += int(got.sum())
        assert np.array_equal(ctrl._within_reach(b), ctrl._within_reach(a))
        v_max = rng.uniform(8, 14, len(vin))
        a_free = rng.uniform(1.5, 3.0, len(vin))
        engaged = rng.random(len(vin)) > 0.5
        got = ctrl.decide(b, vin, v_max, a_free, engaged)
        want = ctrl.decide(a, remap[vin], v_max, a_free, engaged)
        assert got.tobytes() == want.tobytes()
    assert occupied > 0


def test_reach_bound_and_crossing_occupancy_equal_their_numpy_form(
    geometry: NetGeometry,
) -> None:
    """The controller's reach bound equals its numpy form (circumscribed circles, speeds from
    np.linalg.norm), and the crossing occupancy of pairs equals crossing_conflict pair by
    pair (pedestrians on no crossing: no zone)."""
    model = SCTModel(geometry)
    ctrl = SCTController(model)
    rng = np.random.default_rng(13)
    zones = 0
    for _ in range(100):
        state = _scene(rng, geometry, model)
        view = model.prepare(state, None, True)
        v, p = view.veh_rows, view.ped_rows
        sc, t = model.config, ctrl.config.sct_safe
        want = within_reach(
            np.ascontiguousarray(state.xyz[v, :2]),
            np.ascontiguousarray(state.xyz[p, :2]),
            0.5 * np.hypot(state.length[v], state.width[v]) + sc.vehicle_margin,
            sc.pedestrian_radius,
            state.speed[v],
            np.linalg.norm(view.ped_velocity, axis=1) * max(sc.speed_factors),
            t,
            0.5 * ctrl.config.max_accel * t * t,
        )
        assert np.array_equal(ctrl._within_reach(view), want)
        vi, pj = (a.ravel() for a in np.meshgrid(v, p, indexing="ij"))
        got = model.crossing_occupancy(view, vi, pj, 0.3)
        cr = geometry.crossings
        for i in range(len(vi)):
            k = view.crossing[view.ped_slot[pj[i]]]
            if k < 0:
                assert not (got[0][i] or got[1][i] or got[2][i])
                continue
            want = crossing_conflict(
                view.paths[view.veh_slot[vi[i]]],
                float(view.s0[view.veh_slot[vi[i]]]),
                float(state.length[vi[i]]),
                float(state.width[vi[i]]),
                state.xyz[pj[i] : pj[i] + 1, :2],
                cr.direction[k : k + 1],
                cr.centre[k : k + 1],
                cr.half_length[k : k + 1],
                0.3,
            )
            assert [bool(g[i]) for g in got] == [bool(w[0]) for w in want]
            zones += bool(got[0][i])
    assert zones > 20
