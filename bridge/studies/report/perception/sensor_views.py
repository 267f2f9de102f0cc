"""Files and PNG views of one sensor frame: point clouds, radar detections, camera images,
and object lists, written atomically."""

from __future__ import annotations

import csv
from pathlib import Path

import cv2
import numpy as np  # noqa: E402
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.patches import Rectangle

from hiyari.atomic import atomic_path  # noqa: E402
from hiyari.sensors.outputs import CameraFrame, ObjectList, PointCloud, RadarDetections  # noqa: E402


def write_objects_csv(objects: ObjectList, path: Path) -> Path:
    """One row per object: id, class, position, velocity, size, confidence, truth (, box)."""
    with atomic_path(path) as tmp, tmp.open("w", newline="") as f:
        w = csv.writer(f)
        head = [
            "object_id",
            "cls",
            "x",
            "y",
            "z",
            "vx",
            "vy",
            "vz",
            "length",
            "width",
            "height",
            "confidence",
            "truth",
        ]
        if objects.box_2d is not None:
            head += ["u0", "v0", "u1", "v1"]
        w.writerow(head)
        for i in range(len(objects)):
            row = [
                int(objects.object_id[i]),
                int(objects.cls[i]),
                *np.round(objects.position[i], 3),
            ]
            row += [*np.round(objects.velocity[i], 3), *np.round(objects.size[i], 3)]
            row += [round(float(objects.confidence[i]), 3), objects.truth[i]]
            if objects.box_2d is not None:
                row += [*np.round(objects.box_2d[i], 1)]
            w.writerow(row)
    return path


def write_point_cloud(cloud: PointCloud, path: Path) -> Path:
    """The scan as .npz: xyz, intensity, range, hit, truth (ids), sensor_to_world, time."""
    with atomic_path(path) as tmp, tmp.open("wb") as f:
        np.savez_compressed(
            f,
            xyz=cloud.xyz,
            intensity=cloud.intensity,
            range=cloud.range,
            hit=cloud.hit,
            truth=cloud.truth_ids().astype(str),
            sensor_to_world=cloud.sensor_to_world,
            time=cloud.time,
        )
    return path


def write_radar_csv(det: RadarDetections, path: Path) -> Path:
    """One row per detection with its ground truth."""
    truth = np.where(
        det.hit >= 0, det.actor_ids[np.maximum(det.hit, 0)], np.where(det.hit == -1, "static", "")
    )
    with atomic_path(path) as tmp, tmp.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(
            [
                "range_m",
                "range_rate_m_s",
                "azimuth_deg",
                "elevation_deg",
                "snr_db",
                "power_dbm",
                "truth",
            ]
        )
        for i in range(len(det)):
            w.writerow(
                [
                    round(float(det.range[i]), 3),
                    round(float(det.range_rate[i]), 3),
                    round(float(np.degrees(det.azimuth[i])), 3),
                    round(float(np.degrees(det.elevation[i])), 3),
                    round(float(det.snr_db[i]), 2),
                    round(float(det.power_dbm[i]), 2),
                    truth[i],
                ]
            )
    return path


def _boxes(ax: Axes, objects: ObjectList) -> None:
    for p, s, t in zip(objects.position, objects.size, objects.truth, strict=True):
        length, width = np.nan_to_num(s[:2], nan=1.0)
        colour = "tab:gray" if t == "static" else ("tab:red" if t == "" else "tab:green")
        ax.add_patch(
            Rectangle(
                (p[1] - width / 2, p[0] - length / 2), width, length, fill=False, ec=colour, lw=1
            )
        )
        if t not in ("", "static"):
            ax.annotate(t, (p[1], p[0]), fontsize=6, color=colour)


def plot_point_cloud(
    cloud: PointCloud, objects: ObjectList, path: Path, title: str, extent: float = 60.0
) -> Path:
    """Bird's-eye view (x forward up, y left to the left), intensity colours, object boxes."""
    fig = Figure(figsize=(7, 7))
    ax = fig.subplots()
    near = (np.abs(cloud.xyz[:, 0]) < extent) & (np.abs(cloud.xyz[:, 1]) < extent)
    xyz, inten = cloud.xyz[near], cloud.intensity[near]
    sc = ax.scatter(
        xyz[:, 1], xyz[:, 0], c=np.log10(np.maximum(inten, 1e-6)), s=0.3, cmap="viridis"
    )
    actor = cloud.hit[near] >= 0
    ax.scatter(xyz[actor, 1], xyz[actor, 0], s=1.5, c="tab:orange", label="on actors (truth)")
    ghost = cloud.hit[near] == -2
    if ghost.any():
        ax.scatter(xyz[ghost, 1], xyz[ghost, 0], s=1.5, c="tab:red", label="no surface (ghosts)")
    _boxes(ax, objects)
    ax.set_xlim(extent, -extent)
    ax.set_ylim(-extent, extent)
    ax.set_aspect("equal")
    ax.set_xlabel("y left (m)")
    ax.set_ylabel("x forward (m)")
    ax.legend(loc="lower left", fontsize=7)
    fig.colorbar(sc, ax=ax, label="log10 intensity", shrink=0.7)
    ax.set_title(title)
    return _save(fig, path)


def plot_radar(det: RadarDetections, objects: ObjectList, path: Path, title: str) -> Path:
    """Bird's-eye view of detections coloured by range rate, sized by SNR, with objects."""
    fig = Figure(figsize=(7, 7))
    ax = fig.subplots()
    xyz = det.xyz()
    sc = ax.scatter(
        xyz[:, 1],
        xyz[:, 0],
        c=det.range_rate,
        s=4 + 2 * np.maximum(det.snr_db - 10, 0),
        cmap="coolwarm",
        vmin=-20,
        vmax=20,
    )
    _boxes(ax, objects)
    far = max(20.0, float(np.max(det.range, initial=20.0)) * 1.05)
    ax.set_xlim(far / 2, -far / 2)
    ax.set_ylim(0, far)
    ax.set_aspect("equal")
    ax.set_xlabel("y left (m)")
    ax.set_ylabel("x forward (m)")
    fig.colorbar(sc, ax=ax, label="range rate (m/s)", shrink=0.7)
    ax.set_title(title)
    return _save(fig, path)


def write_image(image: np.ndarray, path: Path) -> Path:
    """An RGB uint8 image as PNG."""
    ok, buf = cv2.imencode(".png", np.ascontiguousarray(image[..., ::-1]))
    with atomic_path(path) as tmp:
        tmp.write_bytes(buf.tobytes())
    return path


def write_camera(frame: CameraFrame, annotated: np.ndarray, folder: Path) -> list[Path]:
    """The raw image and the annotated view."""
    return [
        write_image(frame.image, folder / "camera.png"),
        write_image(annotated, folder / "camera_objects.png"),
    ]


def _save(fig: Figure, path: Path) -> Path:
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    return path
