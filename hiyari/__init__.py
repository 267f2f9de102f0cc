"""hiyari: automated-driving safety evaluation on SUMO with ray-cast sensors.

Subpackages: ``hiyari.net`` (road networks and the 3D road scene), ``hiyari.traffic`` (the
SUMO runtime and WorldState), ``hiyari.sensors`` (LiDAR, radar, camera), ``hiyari.risk``
(metrics, C&C driver boundaries, SCT), ``hiyari.bridge`` (closed loop, recording, replay, CLI).
"""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("hiyari")
except PackageNotFoundError:  # running from a source tree that was never installed
    __version__ = "0.0.0"
