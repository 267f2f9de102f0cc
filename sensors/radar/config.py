"""Millimetre-wave radar parameters: ray grid, radar equation, resolution, RCS per class.

The ray grids are the seed's (divp-H section 2.3, Table 61): narrow 15 deg / 0.2 deg
horizontal x 15 deg / 0.5 deg vertical for far targets ahead, wide 60 deg / 0.5 deg x
25 deg / 0.5 deg for near targets to the side. The reference unit is the seed's 1 TX / 4 RX
board (TI AWR1642-class) whose gain falls 10 dB at +-40 deg.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from hiyari.errors import HiyariError
from hiyari.net.mesh.materials import Material
from hiyari.sensors.environment.atmosphere import AtmosphereModel
from hiyari.traffic.actor_class import ActorClass

SPEED_OF_LIGHT = 299_792_458.0
BOLTZMANN = 1.380649e-23


@dataclass(frozen=True)
class RcsModel:
    """Radar cross-section of an actor by class and aspect, dBsm (toolkit choices from
    typical 77 GHz measurements: cars 10-20 dBsm, pedestrians about -8 dBsm).

    sigma_dB(phi) = front cos^2 phi (phi < 90 deg) + rear cos^2 phi (phi > 90 deg) + side sin^2 phi,
    phi the angle between the actor's heading and the direction from the actor to the radar.
    """

    front_dbsm: dict[ActorClass, float] = field(
        default_factory=lambda: {
            ActorClass.CAR: 10.0,
            ActorClass.TRUCK: 18.0,
            ActorClass.BUS: 18.0,
            ActorClass.MOTORCYCLE: 3.0,
            ActorClass.BICYCLE: -3.0,
            ActorClass.PEDESTRIAN: -8.0,
        }
    )
    side_dbsm: dict[ActorClass, float] = field(
        default_factory=lambda: {
            ActorClass.CAR: 15.0,
            ActorClass.TRUCK: 25.0,
            ActorClass.BUS: 25.0,
            ActorClass.MOTORCYCLE: 5.0,
            ActorClass.BICYCLE: 0.0,
            ActorClass.PEDESTRIAN: -8.0,
        }
    )
    rear_dbsm: dict[ActorClass, float] = field(
        default_factory=lambda: {
            ActorClass.CAR: 10.0,
            ActorClass.TRUCK: 20.0,
            ActorClass.BUS: 20.0,
            ActorClass.MOTORCYCLE: 3.0,
            ActorClass.BICYCLE: -3.0,
            ActorClass.PEDESTRIAN: -8.0,
        }
    )


@dataclass(frozen=True)
class RadarConfig:
    """One radar: ray grid, transmitter and receiver, resolution cells and noise."""

    name: str
    """Preset or user name."""
    h_fov_deg: float
    """Horizontal extent of the ray grid, degrees (seed Table 61)."""
    h_step_deg: float
    """Horizontal ray spacing, degrees (seed Table 61)."""
    v_fov_deg: float
    """Vertical extent of the ray grid, degrees (seed Table 61)."""
    v_step_deg: float
    """Vertical ray spacing, degrees (seed Table 61)."""
    rate_hz: float = 20.0
    """Cycles per second."""
    frequency_hz: float = 76.5e9
    """Carrier frequency, Hz (77 GHz band)."""
    tx_power_dbm: float = 12.0
    """Transmit power, dBm (AWR1642-class: 12.5 dBm)."""
    tx_gain_dbi: float = 10.5
    """Transmit antenna boresight gain, dBi (AWR1642BOOST patch array ~10.5 dBi)."""
    rx_gain_dbi: float = 10.5
    """Receive antenna boresight gain, dBi."""
    system_loss_db: float = 3.0
    """Radome, cabling and processing losses, dB (toolkit choice)."""
    noise_figure_db: float = 15.0
    """Receiver noise figure, dB (AWR1642-class: 14-15 dB)."""
    noise_bandwidth_hz: float = 100.0
    """Noise bandwidth after range-Doppler integration, Hz (1 / ~10 ms coherent frame)."""
    temperature_k: float = 290.0
    """Receiver reference temperature, K."""
    snr_threshold_db: float = 12.0
    """CFAR detection threshold on the cell SNR, dB (toolkit choice)."""
    max_range_m: float = 150.0
    """Largest range processed, m."""
    range_resolution_m: float = 0.4
    """Range cell size, m (c / 2B with B ~ 375 MHz)."""
    velocity_resolution_m_s: float = 0.15
    """Doppler cell size, m/s."""
    max_velocity_m_s: float = 60.0
    """Unambiguous range-rate magnitude, m/s."""
    n_tx: int = 1
    """Transmit channels (seed: 1 TX)."""
    n_rx: int = 4
    """Receive channels (seed: 4 RX); azimuth cells are 2 / (n_tx n_rx) rad wide."""
    azimuth_10db_deg: float = 40.0
    """Two-way-per-antenna gain falls 10 dB at this azimuth, degrees (seed: about +-40 deg)."""
    elevation_10db_deg: float = 10.0
    """Gain falls 10 dB at this elevation, degrees (toolkit choice)."""
    azimuth_error_deg: float = 1.0
    """Standard deviation of the azimuth error floor, degrees (seed: DBF error <= 2 deg within
    +-30 deg, mounting included)."""
    false_alarms_per_cycle: float = 0.3
    """Mean number of noise detections per cycle (Poisson; toolkit choice)."""
    false_alarm_snr_spread: float = 0.3
    """Noise detections exceed the threshold by an exponential factor of this mean (linear)."""
    multipath: bool = False
    """Add ghost detections mirrored by guard rails and walls (seed: tunnel wall ghost)."""
    multipath_materials: tuple[Material, ...] = (Material.BARRIER_METAL, Material.BUILDING)
    """Static materials that reflect radar specularly enough to make ghosts."""
    multipath_loss_db: float = 6.0
    """Loss per wall bounce, dB (toolkit choice)."""
    rcs: RcsModel = field(default_factory=RcsModel)
    """RCS per actor class and aspect."""
    atmosphere: AtmosphereModel = field(default_factory=AtmosphereModel)
    """Rain and fog attenuation."""

    @property
    def wavelength_m(self) -> float:
        """Carrier wavelength, m."""
        return SPEED_OF_LIGHT / self.frequency_hz

    @property
    def azimuth_resolution_rad(self) -> float:
        """Width of an azimuth cell, rad (Rayleigh limit of an N-element half-wave array)."""
        return 2.0 / (self.n_tx * self.n_rx)

    @property
    def noise_power_w(self) -> float:
        """Thermal noise power after integration, W (k T B F)."""
        return (
            BOLTZMANN
            * self.temperature_k
            * self.noise_bandwidth_hz
            * 10 ** (self.noise_figure_db / 10)
        )

    @property
    def radar_constant(self) -> float:
        """P_t G_t G_r lambda^2 / ((4 pi)^3 L), W m^2: received power = this x RCS / r^4."""
        pt = 10 ** ((self.tx_power_dbm - 30) / 10)
        g = 10 ** ((self.tx_gain_dbi + self.rx_gain_dbi) / 10)
        return (
            pt * g * self.wavelength_m**2 / ((4 * math.pi) ** 3 * 10 ** (self.system_loss_db / 10))
        )

    def validate(self) -> RadarConfig:
        """Return self, or raise HiyariError naming the impossible parameter."""
        n = self.name
        for label, value in (
            ("h_fov_deg", self.h_fov_deg),
            ("h_step_deg", self.h_step_deg),
            ("v_fov_deg", self.v_fov_deg),
            ("v_step_deg", self.v_step_deg),
            ("rate_hz", self.rate_hz),
            ("frequency_hz", self.frequency_hz),
            ("noise_bandwidth_hz", self.noise_bandwidth_hz),
            ("max_range_m", self.max_range_m),
            ("range_resolution_m", self.range_resolution_m),
            ("velocity_resolution_m_s", self.velocity_resolution_m_s),
            ("max_velocity_m_s", self.max_velocity_m_s),
            ("azimuth_10db_deg", self.azimuth_10db_deg),
            ("elevation_10db_deg", self.elevation_10db_deg),
        ):
            if not (value > 0 and math.isfinite(value)):
                raise HiyariError(f"radar {n}: {label} must be positive, got {value}")
        if self.h_fov_deg > 180 or self.v_fov_deg > 90:
            raise HiyariError(
                f"radar {n}: ray grid wider than 180 x 90 degrees ({self.h_fov_deg} x {self.v_fov_deg})"
            )
        if self.h_step_deg > self.h_fov_deg or self.v_step_deg > self.v_fov_deg:
            raise HiyariError(f"radar {n}: ray spacing larger than the field of view")
        if self.n_tx < 1 or self.n_rx < 1:
            raise HiyariError(
                f"radar {n}: needs at least 1 TX and 1 RX channel, got {self.n_tx} / {self.n_rx}"
            )
        if self.false_alarms_per_cycle < 0 or self.azimuth_error_deg < 0:
            raise HiyariError(
                f"radar {n}: false_alarms_per_cycle and azimuth_error_deg must be >= 0"
            )
        return self

    @staticmethod
    def preset(name: str) -> RadarConfig:
        """A preset by name; HiyariError lists the known ones."""
        try:
            return RADAR_PRESETS[name]
        except KeyError:
            known = ", ".join(RADAR_PRESETS)
            raise HiyariError(f"unknown radar preset {name!r} (known: {known})") from None


RADAR_PRESETS: dict[str, RadarConfig] = {
    "narrow": RadarConfig("narrow", 15.0, 0.2, 15.0, 0.5),
    "wide": RadarConfig("wide", 60.0, 0.5, 25.0, 0.5, max_range_m=80.0),
}
