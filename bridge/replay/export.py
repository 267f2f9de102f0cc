"""Static replay: one self-contained HTML file that plays a recording in a browser without
Python.

viser records every scene message sent while a scene serializer is open, with the sleeps
between frames, and ``StateSerializer.as_html`` embeds that recording in its prebuilt
client (zstd-compressed, base64). The page has viser's own player: play / pause, a timeline
and playback speed. GUI panels are not part of a serialized scene, so the heads-up text
(time, ego status, collisions) is drawn as a 3D label and camera images are left out.

View: a page's camera is the browser's, not part of the scene, so it cannot be moved frame by
frame. To follow the ego (the default when the recording has one), every frame moves the
scene's layers so that the ego stays at the origin heading along +x, and the fixed camera
looks at it from behind and above, as the live replay's "Follow ego" does; the whole-scene
view over the road is ``follow_ego=False``. The export runs a viser server in-process only
to serialize the scene: its console banner is not shown.

Size: LiDAR clouds are the bulk of a page. The export (never the recording) keeps every
``lidar_every``-th point of a scan, sends a scan only when it changed (SUMO steps faster than
the LiDAR turns) and stores it in float16 about the scan's lowest corner (~3 cm at 120 m,
below the display's point size); the label on the page says so.
"""

from __future__ import annotations

import contextlib
import io
from pathlib import Path

import numpy as np
import viser
from tqdm import tqdm

from hiyari.atomic import atomic_path
from hiyari.bridge.record.reader import Recording
from hiyari.bridge.replay.scene import (
    FOLLOW_ABOVE_M,
    FOLLOW_BEHIND_M,
    FrameInfo,
    ReplayOptions,
    ReplayScene,
    stack_ttc_text,
)
from hiyari.errors import HiyariError


class _ExportScene(ReplayScene):
    """ReplayScene that thins LiDAR clouds for a static page and skips unchanged ones."""

    def __init__(
        self,
        server: viser.ViserServer,
        recording: Recording,
        options: ReplayOptions | None,
        every: int,
    ) -> None:
        super().__init__(server, recording, options)
        self.lidar_every = every
        self._sent: dict[str, np.ndarray] = {}

    def _points(self, name: str, pts: np.ndarray | None, colors: np.ndarray, size: float) -> None:
        if not name.startswith("/lidar/") or pts is None or len(pts) == 0:
            self._sent.pop(name, None)
            super()._points(name, pts, colors, size)
            return
        pts, colors = pts[:: self.lidar_every], colors[:: self.lidar_every]
        last = self._sent.get(name)
        if last is not None and last.shape == pts.shape and np.array_equal(last, pts):
            return
        self._sent[name] = pts
        corner = np.floor(pts.min(0))
        self._clouds[name] = self.server.scene.add_point_cloud(
            name,
            (pts - corner).astype(np.float16),
            colors,
            point_size=size,
            precision="float16",
            point_shading="flat",
            position=tuple(corner),
        )


def hud_label(info: FrameInfo, lidar_every: int = 1) -> str:
    """One-line heads-up text for the static replay (says how LiDAR clouds were thinned)."""
    text = f"t = {info.time:.1f} s · {info.vehicles} vehicles · {info.pedestrians} pedestrians"
    s = info.ego_status
    if s is not None:
        text += f" · ego {s['speed_mps'] * 3.6:.0f} km/h, {stack_ttc_text(s)}, AEB {s['aeb_state']}"
    if info.collisions:
        text += f" · collisions {len(info.collisions)}"
    if lidar_every > 1:
        text += f" · LiDAR: 1 in {lidar_every} points shown (the recording has all)"
    return text


def frame_range(recording: Recording, start: float | None, end: float | None, every: int) -> range:
    """Frame indices between ``start`` and ``end`` (s, inclusive), every ``every``-th."""
    if every < 1:
        raise HiyariError(f"--every must be >= 1, got {every}")
    t = recording.times
    k0 = 0 if start is None else int(np.searchsorted(t, start - 1e-9))
    k1 = len(t) - 1 if end is None else int(np.searchsorted(t, end + 1e-9, side="right")) - 1
    if k0 > k1 or k0 >= len(t):
        raise HiyariError(
            f"{recording.path}: no frames between {start} and {end} s "
            f"(the recording spans {t[0]:.2f}-{t[-1]:.2f} s)"
        )
    return range(k0, k1 + 1, every)


def export_html(
    recording: Recording,
    out: str | Path,
    options: ReplayOptions | None = None,
    frames: range | None = None,
    progress: bool = True,
    lidar_every: int = 8,
    follow_ego: bool = True,
) -> Path:
    """Write a self-contained HTML replay of ``frames`` (default: all) to ``out``, with every
    ``lidar_every``-th LiDAR point (1: all); the view follows the ego when ``follow_ego`` and
    the recording has one, else it shows the whole scene."""
    if lidar_every < 1:
        raise HiyariError(f"lidar_every must be >= 1, got {lidar_every}")
    frames = frames if frames is not None else range(len(recording))
    follow = follow_ego and len(frames) > 0 and recording.world_and_ego(frames[0])[1] is not None
    with contextlib.redirect_stdout(io.StringIO()):  # viser prints a banner on start and stop
        server = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
        try:
            html = _serialize(server, recording, options, frames, progress, lidar_every, follow)
        finally:
            server.stop()
    out = Path(out)
    with atomic_path(out) as tmp:
        tmp.write_text(html)
    return out


def _serialize(server: viser.ViserServer, recording: Recording, options: ReplayOptions | None,
               frames: range, progress: bool, lidar_every: int, follow: bool) -> str:  # fmt: skip
    """Draw ``frames`` into ``server``'s scene under a serializer; the page's HTML."""
    scene = _ExportScene(server, recording, options, lidar_every)
    camera = server.initial_camera
    if follow:
        camera.position = (-FOLLOW_BEHIND_M, 0.0, FOLLOW_ABOVE_M)
        camera.look_at = (0.0, 0.0, 0.0)
        label_at = np.array([0.0, 10.0, 0.45 * FOLLOW_ABOVE_M])  # its text starts left of the ego
    else:
        position, look_at = scene.camera_pose()
        camera.position, camera.look_at = tuple(position), tuple(look_at)
        label_at = scene.centre + np.array([0.0, 0.55 * scene.extent, 5.0])
    camera.far = 10 * scene.extent
    label = server.scene.add_label("/hud", "", position=tuple(label_at))
    serializer = server.get_scene_serializer()
    previous = None
    for k in tqdm(frames, unit="frame", desc="export", disable=not progress):
        t = float(recording.times[k])
        if previous is not None:
            serializer.insert_sleep(t - previous)
        info = scene.draw(k)
        if follow and info.ego_pose is not None:
            scene.follow(info.ego_pose)
        label.text = hud_label(info, lidar_every)
        previous = t
    return serializer.as_html()
