"""Draw one frame of a recording into a viser scene (used by the live server and the export).

Scene tree (each frame node is a layer that can be hidden): ``/road`` (the mesh, one node per
material, or a grid when the run recorded no mesh), ``/vehicles`` (boxes coloured by class,
the ego in pink with a label), ``/pedestrians`` (upright prisms), ``/lidar/<sensor>``
(points coloured by intensity or by what they hit), ``/radar/<sensor>`` (detections coloured
by range rate or by what they hit), ``/objects/<source>`` (perceived objects and fused tracks
as wireframe boxes).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import viser

from hiyari.bridge.record import style as style
from hiyari.bridge.record.foxglove_convert import yaw_quats
from hiyari.bridge.record.reader import Recording
from hiyari.sensors.outputs import HIT_NONE, HIT_STATIC
from hiyari.traffic.world_state import WorldState

LIDAR_COLOR_MODES = ("intensity", "truth")
#: Chase view (the live "Follow ego" and the static page): metres behind and above the ego.
FOLLOW_BEHIND_M = 22.0
FOLLOW_ABOVE_M = 24.0

_CUBE_V = np.array(
    [
        [-0.5, -0.5, -0.5],
        [0.5, -0.5, -0.5],
        [0.5, 0.5, -0.5],
        [-0.5, 0.5, -0.5],
        [-0.5, -0.5, 0.5],
        [0.5, -0.5, 0.5],
        [0.5, 0.5, 0.5],
        [-0.5, 0.5, 0.5],
    ]
)
_CUBE_F = np.array(
    [
        [0, 2, 1],
        [0, 3, 2],
        [4, 5, 6],
        [4, 6, 7],
        [0, 1, 5],
        [0, 5, 4],
        [1, 2, 6],
        [1, 6, 5],
        [2, 3, 7],
        [2, 7, 6],
        [3, 0, 4],
        [3, 4, 7],
    ]
)


def _prism(sides: int) -> tuple[np.ndarray, np.ndarray]:
    """A unit-diameter, unit-height upright prism centred at the origin (pedestrians)."""
    a = np.linspace(0, 2 * np.pi, sides, endpoint=False)
    ring = np.stack([0.5 * np.cos(a), 0.5 * np.sin(a)], 1)
    v = np.concatenate(
        [
            np.c_[ring, np.full(sides, -0.5)],
            np.c_[ring, np.full(sides, 0.5)],
            [[0, 0, -0.5], [0, 0, 0.5]],
        ]
    )
    i = np.arange(sides)
    j = (i + 1) % sides
    bottom, top = 2 * sides, 2 * sides + 1
    faces = np.concatenate(
        [
            np.stack([i, j, sides + j], 1),
            np.stack([i, sides + j, sides + i], 1),
            np.stack([np.full(sides, bottom), j, i], 1),
            np.stack([np.full(sides, top), sides + i, sides + j], 1),
        ]
    )
    return v, faces


_PRISM_V, _PRISM_F = _prism(10)


@dataclass(frozen=True)
class ReplayOptions:
    """How the replay draws a recording."""

    lidar_colors: str = "intensity"  # "intensity" or "truth" (colour of the actor hit)
    sensor_max_age_s: float = 0.5  # sensor data older than this at a frame is not drawn
    lidar_point_size: float = 0.08  # m
    radar_point_size: float = 0.6  # m
    range_rate_scale: float = 15.0  # m/s mapped to full blue / red


@dataclass
class FrameInfo:
    """What the heads-up display shows for one frame."""

    index: int
    time: float
    vehicles: int
    pedestrians: int
    ego_id: str | None
    ego_pose: tuple[np.ndarray, float] | None  # (box centre xyz, heading rad) of the ego
    ego_status: dict[str, Any] | None
    environment: dict[str, str]
    collisions: list[dict[str, Any]] = field(default_factory=list)
    camera: dict[str, np.ndarray] = field(default_factory=dict)  # sensor -> RGB image


def stack_ttc_text(status: dict[str, Any], digits: int = 1) -> str:
    """The ego stack's own smallest TTC over its tracks, labelled as such ("stack TTC 1.2 s";
    "stack TTC —" when it has no target). It is what the stack's AEB acts on, not a measured
    contact: 0 s means a track is already in the ego's path (e.g. standing in front of the
    stopped ego)."""
    ttc = status.get("ttc_s")
    return "stack TTC —" if ttc is None else f"stack TTC {ttc:.{digits}f} s"


def ego_frame_transform(ego_pose: tuple[np.ndarray, float]) -> tuple[np.ndarray, np.ndarray]:
    """(position, wxyz) of the world frame seen from the ego: the transform that puts the
    ego's box centre at the origin heading along +x (a rotation about z by -heading)."""
    centre, heading = ego_pose
    c, s = math.cos(heading), math.sin(heading)
    rotated = np.array([c * centre[0] + s * centre[1], -s * centre[0] + c * centre[1], centre[2]])
    wxyz = np.array([math.cos(-0.5 * heading), 0.0, 0.0, math.sin(-0.5 * heading)])
    return -rotated, wxyz


class ReplayScene:
    """Owns the scene nodes of one recording on one viser server."""

    def __init__(
        self, server: viser.ViserServer, recording: Recording, options: ReplayOptions | None = None
    ) -> None:
        self.server = server
        self.rec = recording
        self.options = options or ReplayOptions()
        if self.options.lidar_colors not in LIDAR_COLOR_MODES:
            raise ValueError(f"lidar colours must be one of {LIDAR_COLOR_MODES}")
        self._batched: dict[str, tuple[Any, int]] = {}
        self._clouds: dict[str, Any] = {}
        scene = server.scene
        # Shadows add a render pass per frame and tell an engineer nothing here.
        scene.configure_default_lights(cast_shadow=False)
        names = ["road", "vehicles", "pedestrians", "lidar", "radar", "objects"]
        names += [f"lidar/{s}" for s in recording.lidar_sensors]
        names += [f"radar/{s}" for s in recording.radar_sensors]
        names += [f"objects/{s}" for s in recording.object_sources]
        #: Layer name -> its frame node; hide a layer with :meth:`set_layer_visible`.
        self.layers: dict[str, Any] = {n: scene.add_frame(f"/{n}", show_axes=False) for n in names}
        self.centre, self.extent = self._bounds()
        self._add_road()
        self._ego_label = scene.add_label("/vehicles/ego_label", "ego", visible=False)

    # ------------------------------------------------------------------ static
    def _bounds(self) -> tuple[np.ndarray, float]:
        """Centre and size (m) of where the actors go (sampled frames), else of the mesh."""
        frames = np.unique(np.linspace(0, len(self.rec) - 1, 20).astype(int))
        pts = np.concatenate([self.rec.world(int(k)).xyz for k in frames])
        mesh = self.rec.mesh()
        if len(pts) == 0 and mesh is not None:
            pts = mesh.vertices
        if len(pts) == 0:
            return np.zeros(3), 50.0
        lo, hi = pts.min(0), pts.max(0)
        return (lo + hi) / 2, float(max(np.max(hi - lo), 20.0))

    def _add_road(self) -> None:
        scene = self.server.scene
        mesh = self.rec.mesh()
        if mesh is None:
            scene.add_grid(
                "/road/grid",
                width=self.extent * 1.2,
                height=self.extent * 1.2,
                cell_size=10.0,
                section_size=50.0,
                position=(self.centre[0], self.centre[1], 0.0),
            )
            return
        for m in np.unique(mesh.material):
            faces = mesh.faces[mesh.material == m]
            used, inverse = np.unique(faces.ravel(), return_inverse=True)
            scene.add_mesh_simple(
                f"/road/material_{int(m)}",
                mesh.vertices[used].astype(np.float32),
                inverse.reshape(-1, 3).astype(np.uint32),
                color=style.material_color(int(m)),
                side="double",
                flat_shading=True,
                cast_shadow=False,
                receive_shadow=False,
            )

    def follow(self, ego_pose: tuple[np.ndarray, float]) -> None:
        """Move every layer so the ego is at the origin heading along +x (a static page's
        fixed camera then follows it)."""
        position, wxyz = ego_frame_transform(ego_pose)
        for name, frame in self.layers.items():
            if "/" not in name:
                frame.position = tuple(position)
                frame.wxyz = tuple(wxyz)

    def camera_pose(self) -> tuple[np.ndarray, np.ndarray]:
        """(position, look-at) of a view over the whole scene, from the south-west."""
        d = self.extent
        look = self.centre.copy()
        return look + np.array([-0.2 * d, -0.4 * d, 0.4 * d]), look

    # ------------------------------------------------------------------ dynamic
    def _batched_mesh(
        self,
        name: str,
        verts: np.ndarray,
        faces: np.ndarray,
        positions: np.ndarray,
        wxyzs: np.ndarray,
        scales: np.ndarray,
        colors: np.ndarray,
        wireframe: bool = False,
    ) -> None:
        """Create or update an instanced mesh (re-created when the instance count changes)."""
        handle, count = self._batched.get(name, (None, -1))
        n = len(positions)
        if n == 0:
            if handle is not None:
                handle.visible = False
            return
        if handle is None or count != n:
            if handle is not None:
                handle.remove()
            handle = self.server.scene.add_batched_meshes_simple(
                name,
                verts,
                faces,
                batched_wxyzs=wxyzs,
                batched_positions=positions,
                batched_scales=scales,
                batched_colors=colors,
                wireframe=wireframe,
                lod="off",
                cast_shadow=False,
                receive_shadow=False,
            )
            self._batched[name] = (handle, n)
            return
        handle.batched_positions = positions
        handle.batched_wxyzs = wxyzs
        handle.batched_scales = scales
        handle.batched_colors = colors
        handle.visible = True

    def _draw_truth(self, state: WorldState, ego_id: str | None) -> None:
        ped = state.is_pedestrian
        centre = state.xyz.copy()
        centre[:, 2] += 0.5 * state.height
        colors = style.class_colors(state.cls)
        is_ego = state.ids == ego_id if ego_id is not None else np.zeros(len(state), bool)
        colors[is_ego] = style.EGO_COLOR
        size = np.stack([state.length, state.width, state.height], 1)
        q = yaw_quats(state.heading)
        veh = ~ped
        self._batched_mesh(
            "/vehicles/boxes", _CUBE_V, _CUBE_F, centre[veh], q[veh], size[veh], colors[veh]
        )
        ped_size = np.stack([state.width, state.width, state.height], 1)
        self._batched_mesh(
            "/pedestrians/prisms",
            _PRISM_V,
            _PRISM_F,
            centre[ped],
            q[ped],
            ped_size[ped],
            colors[ped],
        )
        if is_ego.any():
            k = int(np.flatnonzero(is_ego)[0])
            self._ego_label.position = tuple(centre[k] + [0.0, 0.0, state.height[k]])
            self._ego_label.visible = True
        else:
            self._ego_label.visible = False

    def _truth_colors(
        self, hit: np.ndarray, actor_ids: np.ndarray, state: WorldState
    ) -> np.ndarray:
        cls_of = dict(zip(state.ids.tolist(), state.cls.tolist(), strict=True))
        actor_cls = np.array([cls_of.get(a, -1) for a in actor_ids.tolist()], np.int64)
        colors = np.empty((len(hit), 3), np.uint8)
        colors[hit == HIT_STATIC] = style.HIT_STATIC_COLOR
        colors[hit == HIT_NONE] = style.HIT_NONE_COLOR
        on = hit >= 0
        colors[on] = style.class_colors(actor_cls[hit[on]])
        return colors

    def _points(self, name: str, pts: np.ndarray | None, colors: np.ndarray, size: float) -> None:
        """Replace a point cloud node (hidden when there is nothing to draw)."""
        if pts is None or len(pts) == 0:
            if name in self._clouds:
                self._clouds[name].visible = False
            return
        self._clouds[name] = self.server.scene.add_point_cloud(
            name,
            pts.astype(np.float32),
            colors,
            point_size=size,
            precision="float32",
            point_shading="flat",
        )

    def _draw_sensors(self, k: int, state: WorldState) -> None:
        o = self.options
        for sensor in self.rec.lidar_sensors:
            pc = self.rec.point_cloud(sensor, k, o.sensor_max_age_s)
            if pc is None:
                self._points(f"/lidar/{sensor}/points", None, np.zeros((0, 3)), 0.0)
                continue
            t = pc.sensor_to_world
            world = pc.xyz.astype(np.float64) @ t[:3, :3].T + t[:3, 3]
            if o.lidar_colors == "truth":
                colors = self._truth_colors(pc.hit, pc.actor_ids, state)
            else:
                colors = style.intensity_colors(pc.intensity)
            self._points(f"/lidar/{sensor}/points", world, colors, o.lidar_point_size)
        for sensor in self.rec.radar_sensors:
            det = self.rec.radar(sensor, k, o.sensor_max_age_s)
            if det is None:
                self._points(f"/radar/{sensor}/points", None, np.zeros((0, 3)), 0.0)
                continue
            t = det.sensor_to_world
            world = det.xyz() @ t[:3, :3].T + t[:3, 3]
            if o.lidar_colors == "truth":
                colors = self._truth_colors(det.hit, det.actor_ids, state)
            else:
                colors = style.signed_colors(det.range_rate, o.range_rate_scale)
            self._points(f"/radar/{sensor}/points", world, colors, o.radar_point_size)
        for source in self.rec.object_sources:
            objs = self.rec.objects(source, k, o.sensor_max_age_s)
            name = f"/objects/{source}/boxes"
            if objs is None or len(objs) == 0:
                self._batched_mesh(name, _CUBE_V, _CUBE_F, *[np.zeros((0, 3))] * 4)
                continue
            t = np.asarray(objs.frame_to_world, np.float64)
            world = objs.position @ t[:3, :3].T + t[:3, 3]
            yaw = math.atan2(t[1, 0], t[0, 0])
            size = np.where(np.isfinite(objs.size), objs.size, 1.0)
            world[:, 2] = np.where(np.isfinite(world[:, 2]), world[:, 2], 0.0)
            n = len(objs)
            colors = np.tile(np.array(style.source_color(source), np.uint8), (n, 1))
            self._batched_mesh(
                name,
                _CUBE_V,
                _CUBE_F,
                world,
                yaw_quats(np.full(n, yaw)),
                size,
                colors,
                wireframe=True,
            )

    def draw(self, k: int) -> FrameInfo:
        """Show frame ``k``; returns what the heads-up display needs."""
        k = range(len(self.rec))[k]
        state, ego_id = self.rec.world_and_ego(k)
        with self.server.atomic():
            self._draw_truth(state, ego_id)
            self._draw_sensors(k, state)
        cameras = {}
        for sensor in self.rec.camera_sensors:
            frame = self.rec.camera(sensor, k, self.options.sensor_max_age_s)
            if frame is not None:
                cameras[sensor] = frame.image
        ped = int(state.is_pedestrian.sum())
        ego_pose = None
        if ego_id is not None and np.any(state.ids == ego_id):
            e = state.index(ego_id)
            ego_pose = (state.xyz[e] + [0.0, 0.0, 0.5 * state.height[e]], float(state.heading[e]))
        return FrameInfo(
            index=k,
            time=float(self.rec.times[k]),
            vehicles=len(state) - ped,
            pedestrians=ped,
            ego_id=ego_id,
            ego_pose=ego_pose,
            ego_status=self.rec.ego_status(k, max_age=1.0),
            environment=self.rec.environment(k),
            collisions=self.rec.collisions_until(k),
            camera=cameras,
        )

    def set_layer_visible(self, layer: str, visible: bool) -> None:
        """Show or hide one layer (a key of :attr:`layers`, e.g. "lidar" or "lidar/top")."""
        self.layers[layer].visible = visible
