"""The static 3D scene as plain numpy arrays: what sensors ray-cast and viewers draw."""

from __future__ import annotations

import zipfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from hiyari.atomic import atomic_path
from hiyari.errors import HiyariError


@dataclass(frozen=True, eq=False)
class SceneMesh:
    """Triangles in SUMO network coordinates (metres, z up), one Material id per face."""

    vertices: np.ndarray  # (V, 3) float64
    faces: np.ndarray  # (F, 3) int32, counter-clockwise seen from outside / above
    material: np.ndarray  # (F,) uint8: net.materials.Material

    def __post_init__(self) -> None:
        if self.vertices.ndim != 2 or self.vertices.shape[1] != 3:
            raise ValueError("vertices must be (V, 3)")
        if self.faces.ndim != 2 or self.faces.shape[1] != 3:
            raise ValueError("faces must be (F, 3)")
        if self.material.shape != (len(self.faces),):
            raise ValueError("material must have one id per face")

    @property
    def triangles(self) -> np.ndarray:
        """(F, 3, 3) float64 vertex coordinates per face."""
        return self.vertices[self.faces]

    @staticmethod
    def concatenate(parts: list[SceneMesh]) -> SceneMesh:
        """One mesh from several (vertex indices shifted)."""
        if not parts:
            return SceneMesh(np.zeros((0, 3)), np.zeros((0, 3), np.int32), np.zeros(0, np.uint8))
        offsets = np.cumsum([0] + [len(p.vertices) for p in parts[:-1]])
        return SceneMesh(
            np.concatenate([p.vertices for p in parts]).astype(np.float64),
            np.concatenate([p.faces + o for p, o in zip(parts, offsets, strict=True)]).astype(
                np.int32
            ),
            np.concatenate([p.material for p in parts]).astype(np.uint8),
        )

    def save_npz(self, path: str | Path) -> Path:
        """Write ``vertices``, ``faces`` and ``material`` arrays to an .npz file atomically."""
        with atomic_path(path) as tmp, tmp.open("wb") as f:
            np.savez_compressed(f, vertices=self.vertices, faces=self.faces, material=self.material)
        return Path(path)

    @staticmethod
    def load_npz(path: str | Path) -> SceneMesh:
        """Read a mesh written by ``save_npz``; HiyariError naming the file if it is not one."""
        try:
            with np.load(path) as data:
                return SceneMesh(data["vertices"], data["faces"], data["material"])
        except (OSError, KeyError, ValueError, EOFError, zipfile.BadZipFile) as exc:
            raise HiyariError(f"{path}: not a hiyari scene mesh (.npz): {exc}") from None
