"""The live browser replay: a viser server with a timeline, playback controls and layer
toggles over a :class:`ReplayScene`."""

from __future__ import annotations

import threading
import time
from dataclasses import replace

import numpy as np
import viser

from hiyari.bridge.record.reader import Recording
from hiyari.bridge.replay.scene import (
    FOLLOW_ABOVE_M,
    FOLLOW_BEHIND_M,
    LIDAR_COLOR_MODES,
    FrameInfo,
    ReplayOptions,
    ReplayScene,
    stack_ttc_text,
)

SPEEDS = ("0.25x", "0.5x", "1x", "2x", "4x", "8x")
#: How often the playback thread advances the timeline, per wall-clock second.
PLAYBACK_HZ = 20.0


def hud_markdown(info: FrameInfo, frames: int) -> str:
    """The heads-up text for one frame: time, counts, ego status, environment, collisions."""
    lines = [
        f"**t = {info.time:.2f} s** · frame {info.index + 1} / {frames}",
        f"vehicles {info.vehicles} · pedestrians {info.pedestrians}",
    ]
    s = info.ego_status
    if s is not None:
        lines.append(
            f"**ego {info.ego_id or ''}** {s['speed_mps'] * 3.6:.1f} km/h · "
            f"{stack_ttc_text(s, 2)} · "
            f"AEB **{s['aeb_state']}** · accel cmd {s['accel_cmd_mps2']:+.2f} m/s²"
        )
    elif info.ego_id is not None:
        lines.append(f"**ego {info.ego_id}** (no ego status recorded)")
    if info.environment:
        lines.append("environment: " + ", ".join(f"{k} {v}" for k, v in info.environment.items()))
    if info.collisions:
        last = info.collisions[-1]
        lines.append(
            f"collisions so far: **{len(info.collisions)}** (latest {last['a']}–{last['b']} "
            f"at {last['time']:.1f} s)"
        )
    return "  \n".join(lines)


class ReplayApp:
    """A replay server for one recording on ``host:port`` (127.0.0.1 by default)."""

    def __init__(
        self,
        recording: Recording,
        host: str = "127.0.0.1",
        port: int = 8080,
        options: ReplayOptions | None = None,
    ) -> None:
        self.rec = recording
        self.server = viser.ViserServer(
            host=host, port=port, label=f"hiyari replay: {recording.path.name}", verbose=False
        )
        self.scene = ReplayScene(self.server, recording, options)
        position, look_at = self.scene.camera_pose()
        self.server.initial_camera.position = tuple(position)
        self.server.initial_camera.look_at = tuple(look_at)
        self.server.initial_camera.far = 10 * self.scene.extent
        self._lock = threading.RLock()
        self._playing = False
        self._clock = (time.perf_counter(), float(recording.times[0]))
        self.frame = 0
        self._stop = threading.Event()
        self._build_gui()
        self.show(0)
        self._thread = threading.Thread(target=self._playback, name="replay-playback", daemon=True)
        self._thread.start()

    @property
    def url(self) -> str:
        """Where a browser opens the replay."""
        return f"http://{self.server.get_host()}:{self.server.get_port()}/"

    # ------------------------------------------------------------------ GUI
    def _build_gui(self) -> None:
        gui, rec = self.server.gui, self.rec
        times = rec.times
        step = float(np.median(np.diff(times))) if len(times) > 1 else 0.1
        meta = rec.metadata
        title = f"**{rec.path.name}** · {meta.get('scenario') or 'run'}"
        if meta.get("seed"):
            title += f" · seed {meta['seed']}"
        gui.add_markdown(title + ("  \n⚠ " + rec.problem if rec.problem else ""))
        self.hud = gui.add_markdown("")
        with gui.add_folder("Timeline"):
            self.slider = gui.add_slider(
                "Time (s)",
                min=round(float(times[0]), 6),
                max=round(float(max(times[-1], times[0] + step)), 6),
                step=round(step, 6),
                initial_value=round(float(times[0]), 6),
            )
            self.play = gui.add_button("Play / pause")
            self.back = gui.add_button("Step back")
            self.forward = gui.add_button("Step forward")
            self.speed = gui.add_dropdown("Speed", SPEEDS, initial_value="1x")
            self.follow = gui.add_checkbox("Follow ego", initial_value=False)
        self.slider.on_update(self._on_slider)
        self.speed.on_update(lambda _: self._restart_clock())
        self.follow.on_update(lambda _: self.show(self.frame))
        self.play.on_click(lambda _: self.toggle_play())
        self.back.on_click(lambda _: self.step(-1))
        self.forward.on_click(lambda _: self.step(+1))
        with gui.add_folder("Layers"):
            for name in self.scene.layers:
                box = gui.add_checkbox(name, initial_value=True)
                box.on_update(lambda e, n=name: self.scene.set_layer_visible(n, e.target.value))
            if rec.lidar_sensors or rec.radar_sensors:
                colors = gui.add_dropdown(
                    "Point colours",
                    LIDAR_COLOR_MODES,
                    initial_value=self.scene.options.lidar_colors,
                )
                colors.on_update(lambda e: self._set_point_colors(e.target.value))
        self.images: dict[str, viser.GuiImageHandle] = {}
        if rec.camera_sensors:
            with gui.add_folder("Camera"):
                for sensor in rec.camera_sensors:
                    first = rec.camera_at(sensor, 0).image
                    self.images[sensor] = gui.add_image(first, label=sensor)

    def _on_slider(self, event: viser.GuiEvent) -> None:
        with self._lock:
            self.show(self.rec.frame_at(self.slider.value))
            if event.client is not None:  # moved by hand while playing: continue from there
                self._restart_clock()

    def _restart_clock(self) -> None:
        self._clock = (time.perf_counter(), float(self.rec.times[self.frame]))

    def _set_point_colors(self, mode: str) -> None:
        with self._lock:
            self.scene.options = replace(self.scene.options, lidar_colors=mode)
            self.show(self.frame)

    # ------------------------------------------------------------------ playback
    def show(self, k: int) -> FrameInfo:
        """Draw frame ``k`` and update the heads-up display and camera panels."""
        with self._lock:
            info = self.scene.draw(k)
            self.frame = info.index
            self.hud.content = hud_markdown(info, len(self.rec))
            for sensor, image in info.camera.items():
                if sensor in self.images:
                    self.images[sensor].image = image
            if self.follow.value and info.ego_pose is not None:
                self._chase(*info.ego_pose)
            return info

    def _chase(self, centre: np.ndarray, heading: float) -> None:
        """Put every client's camera behind and above the ego, looking at it."""
        back = np.array([np.cos(heading), np.sin(heading), 0.0]) * FOLLOW_BEHIND_M
        position = centre - back + [0.0, 0.0, FOLLOW_ABOVE_M]
        for client in self.server.get_clients().values():
            with client.atomic():  # position first: setting it shifts look_at along
                client.camera.position = tuple(position)
                client.camera.look_at = tuple(centre)

    def step(self, delta: int) -> None:
        """Pause and move ``delta`` frames along the timeline."""
        with self._lock:
            self._playing = False
            k = int(np.clip(self.frame + delta, 0, len(self.rec) - 1))
            self.slider.value = round(float(self.rec.times[k]), 6)
            if self.frame != k:  # the slider did not move (value rounding): draw directly
                self.show(k)

    def toggle_play(self) -> None:
        """Start or pause playback (restarts from the beginning at the end)."""
        with self._lock:
            if not self._playing and self.frame >= len(self.rec) - 1:
                self.slider.value = round(float(self.rec.times[0]), 6)
            self._playing = not self._playing
            self._restart_clock()

    def _playback(self) -> None:
        while not self._stop.wait(1.0 / PLAYBACK_HZ):
            with self._lock:
                if not self._playing:
                    continue
                wall0, sim0 = self._clock
                speed = float(self.speed.value.rstrip("x"))
                t = sim0 + (time.perf_counter() - wall0) * speed
                if t >= self.rec.times[-1]:
                    t, self._playing = float(self.rec.times[-1]), False
                k = self.rec.frame_at(t)
                if k != self.frame:
                    self.slider.value = round(float(self.rec.times[k]), 6)

    def close(self) -> None:
        """Stop playback and the server."""
        self._stop.set()
        self._thread.join(timeout=2.0)
        self.server.stop()
