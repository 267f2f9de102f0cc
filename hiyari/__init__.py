"""hiyari: automated-driving safety evaluation on SUMO with ray-cast sensors.

Subpackages: ``hiyari.net`` (road networks and the 3D road scene), ``hiyari.traffic`` (the
SUMO runtime and WorldState), ``hiyari.sensors`` (LiDAR, radar, camera), ``hiyari.risk``
(metrics, C&C driver boundaries, SCT), ``hiyari.bridge`` (closed loop, recording, replay, CLI).
"""

from hiyari.version import __version__

__all__ = ["__version__"]
