"""Surface materials of the static scene and of actors, with what each sensor sees of them.

Reflectances are diffuse (Lambertian) fractions: ``lidar`` at 905 nm, ``visible`` for the
camera (albedo). ``specular`` is the share of a dark glossy surface's return that leaves in the
mirror direction (the seed's black-leather case). ``radar_rcs_m2`` applies per square metre of
area facing the radar (for static surfaces); actor RCS comes from sensors' per-class tables.
Values are the toolkit's defaults (see docs/models.md section 3), not measured data.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum


class Material(IntEnum):
    """Material id stored per triangle (uint8)."""

    ASPHALT = 0
    LANE_PAINT = 1
    CONCRETE = 2  # kerbs, sidewalks
    BARRIER_METAL = 3  # guard rails
    BUILDING = 4
    VEHICLE_PAINT = 5
    VEHICLE_GLASS = 6
    CLOTHING = 7  # ordinary pedestrian clothing
    DARK_CLOTHING = 8  # black leather: low diffuse, high specular
    SKIN = 9
    RETROREFLECTOR = 10  # licence plates, lamps
    GRASS = 11


@dataclass(frozen=True)
class MaterialOptics:
    """Optical and radar properties of one material (fractions 0..1)."""

    lidar: float
    visible: float
    specular: float = 0.0
    radar_rcs_m2: float = 0.0


DEFAULT_OPTICS: dict[Material, MaterialOptics] = {
    Material.ASPHALT: MaterialOptics(lidar=0.10, visible=0.08, radar_rcs_m2=0.001),
    Material.LANE_PAINT: MaterialOptics(lidar=0.60, visible=0.70, radar_rcs_m2=0.001),
    Material.CONCRETE: MaterialOptics(lidar=0.30, visible=0.35, radar_rcs_m2=0.01),
    Material.BARRIER_METAL: MaterialOptics(0.45, 0.50, 0.3, radar_rcs_m2=1.0),
    Material.BUILDING: MaterialOptics(lidar=0.35, visible=0.40, radar_rcs_m2=0.5),
    Material.VEHICLE_PAINT: MaterialOptics(0.50, 0.45, 0.2, radar_rcs_m2=1.0),
    Material.VEHICLE_GLASS: MaterialOptics(0.05, 0.10, 0.6, radar_rcs_m2=0.1),
    Material.CLOTHING: MaterialOptics(lidar=0.40, visible=0.35, radar_rcs_m2=0.05),
    Material.DARK_CLOTHING: MaterialOptics(0.06, 0.04, 0.5, radar_rcs_m2=0.05),
    Material.SKIN: MaterialOptics(lidar=0.45, visible=0.40, radar_rcs_m2=0.05),
    Material.RETROREFLECTOR: MaterialOptics(lidar=0.95, visible=0.90, radar_rcs_m2=0.5),
    Material.GRASS: MaterialOptics(lidar=0.40, visible=0.20, radar_rcs_m2=0.002),
}

#: Display colours (sRGB 0..255) for viewers; chosen for legibility, not measured.
DISPLAY_RGB: dict[Material, tuple[int, int, int]] = {
    Material.ASPHALT: (70, 70, 74),
    Material.LANE_PAINT: (240, 240, 235),
    Material.CONCRETE: (170, 168, 160),
    Material.BARRIER_METAL: (190, 196, 204),
    Material.BUILDING: (196, 170, 140),
    Material.VEHICLE_PAINT: (40, 90, 170),
    Material.VEHICLE_GLASS: (30, 40, 50),
    Material.CLOTHING: (120, 100, 90),
    Material.DARK_CLOTHING: (20, 20, 22),
    Material.SKIN: (224, 180, 150),
    Material.RETROREFLECTOR: (250, 250, 200),
    Material.GRASS: (90, 140, 70),
}
