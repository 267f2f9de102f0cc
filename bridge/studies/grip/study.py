"""Grip-limit study: the generated expressway curve at the ODD speeds under each road friction,
with a crosswind gust and a rutted stretch on the arc; where each run crosses the JAMA bands."""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from hiyari.bridge.studies.grip.road import MotionDisturbance, expressway_profile
from hiyari.net.sumo.build import ExpresswayParams
from hiyari.risk.dynamics.grip import BAND_NAMES, BANDS, ROAD_MU
from hiyari.risk.dynamics.vehicle import Run, VehicleParams, simulate
from hiyari.units import kmh_to_mps


@dataclass(frozen=True)
class GripStudy:
    """Roads, speeds, surfaces and disturbances of the study."""

    road: ExpresswayParams = field(
        default_factory=lambda: ExpresswayParams(length=1800.0, on_ramp=False, off_ramp=False)
    )
    """The expressway main line: R 460 m arc (JAMA R_min at 100 km/h), 6 % superelevation."""
    speeds_kmh: tuple[float, ...] = (80.0, 100.0, 120.0)
    """ODD speeds driven through the curve, km/h."""
    surfaces: tuple[str, ...] = ("dry", "wet", "snow", "ice")
    disturbance: MotionDisturbance = MotionDisturbance(
        gust_m_s=10.0, gust_station_m=1300.0, rut_depth_m=0.025, rut_from_m=1350.0, rut_to_m=1450.0
    )
    """A 10 m/s gust (JAMA boundary) at mid-arc and a 25 mm rut (JAMA repair target) after it."""
    vehicle: VehicleParams = field(default_factory=VehicleParams)


@dataclass(frozen=True)
class GripResult:
    """One run of the study."""

    surface: str
    mu: float
    speed_kmh: float
    run: Run

    @property
    def max_grip_use(self) -> float:
        """Highest grip use of the run (fraction)."""
        return float(np.max(self.run.grip_use))

    def exceedances(self) -> list[tuple[float, float] | None]:
        """Per JAMA band edge (30, 75, 100 %): station span (first, last) above it, or None."""
        out: list[tuple[float, float] | None] = []
        for edge in BANDS:
            above = self.run.s[self.run.grip_use > edge]
            out.append((float(above[0]), float(above[-1])) if len(above) else None)
        return out

    @property
    def band_name(self) -> str:
        """JAMA region of the highest grip use."""
        return BAND_NAMES[int(np.searchsorted(np.asarray(BANDS), self.max_grip_use))]


def run_study(study: GripStudy | None = None, progress: bool = False) -> list[GripResult]:
    """Every speed x surface of ``study``."""
    from tqdm import tqdm

    st = study or GripStudy()
    jobs = [(sf, v) for sf in st.surfaces for v in st.speeds_kmh]
    out = []
    for surface, v in tqdm(jobs, desc="grip study", disable=not progress):
        mu = ROAD_MU[surface]
        road = expressway_profile(st.road, replace(st.disturbance, mu=mu))
        out.append(GripResult(surface, mu, v, simulate(road, float(kmh_to_mps(v)), st.vehicle)))
    return out
