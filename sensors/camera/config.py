"""Camera geometry and recognition parameters: pinhole with radial distortion, presets.

Sensor frame x forward (optical axis), y left, z up. Normalised undistorted coordinates are
x_u = -y / x (right positive) and y_u = -z / x (down positive); the distortion maps radius
r_u to r_d = r_u (1 + k1 r_u^2 + k2 r_u^4); pixels are u = fx x_d + cx, v = fy y_d + cy. The
focal length is chosen so that the horizontal field of view spans the image width.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hiyari.errors import HiyariError


@dataclass(frozen=True)
class CameraConfig:
    """A camera: image, optics, frame rate and the recognition model's parameters."""

    name: str
    """Preset or user name."""
    width_px: int
    """Image width, pixels."""
    height_px: int
    """Image height, pixels."""
    horizontal_fov_deg: float
    """Horizontal field of view, degrees (seed default 120)."""
    k1: float = 0.0
    """First radial distortion coefficient (negative: barrel)."""
    k2: float = 0.0
    """Second radial distortion coefficient."""
    rate_hz: float = 30.0
    """Frames per second (seed: 30 fps)."""
    max_range_m: float = 200.0
    """Farthest object the recogniser reports, m."""
    height_50_px: float = 20.0
    """Box height at which detection probability is 50 % in good contrast, px (toolkit
    choice; typical CNN detectors need 20-30 px)."""
    height_scale_px: float = 4.0
    """Width of the logistic in box height, px."""
    contrast_threshold: float = 0.05
    """Weber contrast at 50 % detection in bright light (toolkit choice)."""
    contrast_scale: float = 0.35
    """Width of the logistic in ln(contrast / threshold)."""
    noise_luminance_cd_m2: float = 3.0
    """Scene luminance at which sensor noise doubles the contrast threshold, cd/m^2; below
    it the threshold grows as 1/sqrt(L) (de Vries-Rose; toolkit choice for an automotive
    HDR sensor)."""
    min_visible_fraction: float = 0.25
    """Visible share of an object below which it is never detected (occlusion)."""
    size_prior_error: float = 0.10
    """Relative spread of the object-size prior used for monocular ranging (toolkit choice)."""
    pixel_error_px: float = 1.0
    """Standard deviation of box edges and centre, px."""
    false_positives_per_frame: float = 0.005
    """Mean random false detections per frame (Poisson)."""
    false_positive_range_m: tuple[float, float] = (5.0, 50.0)
    """Range interval from which a false detection's range estimate is drawn, m."""
    spot_false_positive_probability: float = 0.3
    """Chance per frame that a soiling spot is taken for an object (jama-C: spots make ghosts)."""
    render_width_px: int = 480
    """Width of the rendered image, px (the recogniser uses full resolution analytically)."""

    @property
    def fx(self) -> float:
        """Focal length, px (square pixels)."""
        xu = math.tan(math.radians(self.horizontal_fov_deg) / 2)
        return (self.width_px / 2) / (xu * (1 + self.k1 * xu**2 + self.k2 * xu**4))

    def intrinsics(self, scale: float = 1.0) -> np.ndarray:
        """(3, 3) pinhole matrix for the image scaled by ``scale``."""
        f = self.fx * scale
        return np.array(
            [
                [f, 0.0, self.width_px * scale / 2],
                [0.0, f, self.height_px * scale / 2],
                [0.0, 0.0, 1.0],
            ]
        )

    def validate(self) -> CameraConfig:
        """Return self, or raise HiyariError naming the impossible parameter."""
        n = self.name
        if self.width_px < 16 or self.height_px < 16:
            raise HiyariError(
                f"camera {n}: image must be at least 16 x 16 px, got {self.width_px} x {self.height_px}"
            )
        if not 1.0 <= self.horizontal_fov_deg < 180.0:
            raise HiyariError(
                f"camera {n}: horizontal_fov_deg must be in [1, 180) for a pinhole model, got {self.horizontal_fov_deg}"
            )
        if not self.rate_hz > 0:
            raise HiyariError(f"camera {n}: rate_hz must be positive, got {self.rate_hz}")
        if self.render_width_px < 16:
            raise HiyariError(
                f"camera {n}: render_width_px must be >= 16, got {self.render_width_px}"
            )
        # the distortion must stay monotonic out to the field-of-view edge and the image corner
        edge_u = math.tan(math.radians(self.horizontal_fov_deg) / 2)
        r = np.linspace(0.0, 4.0 * max(edge_u, 1.0), 4000)
        rd = r * (1 + self.k1 * r**2 + self.k2 * r**4)
        falling = np.flatnonzero(np.diff(rd) <= 0)
        fold = len(r) - 1 if not len(falling) else falling[0]
        corner_d = (
            math.hypot(self.width_px / 2, self.height_px / 2) / self.fx
            if edge_u < r[fold]
            else np.inf
        )
        if edge_u >= r[fold] or corner_d >= rd[fold]:
            raise HiyariError(
                f"camera {n}: distortion k1={self.k1}, k2={self.k2} folds over inside the image"
            )
        if self.height_50_px <= 0 or self.height_scale_px <= 0 or self.contrast_threshold <= 0:
            raise HiyariError(f"camera {n}: recognition thresholds must be positive")
        return self

    def distort(self, xu: np.ndarray, yu: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Undistorted normalised coordinates -> distorted ones."""
        r2 = xu * xu + yu * yu
        f = 1 + self.k1 * r2 + self.k2 * r2 * r2
        return xu * f, yu * f

    def undistort(self, xd: np.ndarray, yd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Distorted normalised coordinates -> undistorted ones (Newton on the radius)."""
        rd = np.hypot(xd, yd)
        r = rd.copy()
        for _ in range(20):
            f = r * (1 + self.k1 * r**2 + self.k2 * r**4) - rd
            df = 1 + 3 * self.k1 * r**2 + 5 * self.k2 * r**4
            new = r - f / df
            if np.array_equal(new, r):  # a fixed point: the remaining steps change nothing
                break
            r = new
        scale = np.where(rd > 0, r / np.maximum(rd, 1e-12), 1.0)
        return xd * scale, yd * scale

    def project(self, xyz: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(N, 3) sensor-frame points -> (N, 2) pixels and (N,) in-front flag."""
        xyz = np.asarray(xyz, dtype=np.float64).reshape(-1, 3)
        front = xyz[:, 0] > 1e-3
        x = np.where(front, xyz[:, 0], 1e-3)
        xd, yd = self.distort(-xyz[:, 1] / x, -xyz[:, 2] / x)
        f = self.fx
        return np.stack([f * xd + self.width_px / 2, f * yd + self.height_px / 2], 1), front

    def pixel_rays(self, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        """(N, 3) unit sensor-frame directions through pixels (u, v) of the full image."""
        f = self.fx
        xu, yu = self.undistort(
            (np.asarray(u) - self.width_px / 2) / f, (np.asarray(v) - self.height_px / 2) / f
        )
        d = np.stack([np.ones_like(xu), -xu, -yu], -1)
        return d / np.linalg.norm(d, axis=-1, keepdims=True)

    @staticmethod
    def preset(name: str) -> CameraConfig:
        """A preset by name; HiyariError lists the known ones."""
        try:
            return CAMERA_PRESETS[name]
        except KeyError:
            known = ", ".join(CAMERA_PRESETS)
            raise HiyariError(f"unknown camera preset {name!r} (known: {known})") from None


CAMERA_PRESETS: dict[str, CameraConfig] = {
    # Seed (divp-G B1): 120 deg, 1-2 Mpix, 30 fps; barrel distortion (about 25 % at the edge).
    "wide": CameraConfig("wide", 1920, 1080, 120.0, k1=-0.12, k2=0.012),
    # A narrow tele camera for far targets (toolkit choice).
    "tele": CameraConfig("tele", 1920, 1080, 30.0),
}
