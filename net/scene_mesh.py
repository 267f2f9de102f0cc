"""The static 3D scene as plain numpy arrays: what sensors ray-cast and viewers draw."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


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
