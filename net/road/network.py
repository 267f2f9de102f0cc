"""One road network per run, read once: a handle that the scenario builder, the sensors' scene
and the recorder share instead of each parsing the .net.xml again.

Everything is built lazily on first use and kept: the sumolib net (topology, routes), lane
frames (road coordinates along a lane), the RoadGeometry (lanes, borders, markings,
heights: the scene mesh and OSI ground truth are built from it) and the mapped buildings
(the polygon file beside the net that ``hiyari net import`` writes for an OpenStreetMap map,
or the polygon files of a SUMO scenario).
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import cached_property
from pathlib import Path

import numpy as np
import sumolib

from hiyari.errors import HiyariError
from hiyari.net.road.buildings import Building, poly_path, read_buildings
from hiyari.net.road.geometry import RoadGeometry
from hiyari.net.road.lane_frame import RoadFrame


class RoadNetwork:
    """A SUMO network file and what is read from it, each read at most once."""

    def __init__(self, path: str | Path, polygons: Sequence[str | Path] | None = None) -> None:
        """``polygons``: SUMO polygon files with the buildings (None: ``poly_path(path)``,
        the file an OpenStreetMap import writes beside the net, when it exists)."""
        self.path = Path(path)
        if polygons is None:
            beside = poly_path(self.path)
            polygons = [beside] if beside.is_file() else []
        self.polygons = tuple(Path(p) for p in polygons)
        self._frames: dict[str, RoadFrame] = {}

    def __repr__(self) -> str:
        return f"RoadNetwork({str(self.path)!r})"

    @cached_property
    def sumo(self) -> sumolib.net.Net:
        """The sumolib net (edges, lanes, connections, shortest paths)."""
        if not self.path.is_file():
            raise HiyariError(f"{self.path}: road network file not found")
        try:
            return sumolib.net.readNet(str(self.path))
        except Exception as exc:  # sumolib raises whatever its XML parser raised
            raise HiyariError(f"{self.path}: cannot read the road network: {exc}") from None

    @cached_property
    def geometry(self) -> RoadGeometry:
        """Lanes, borders, polygons, junctions, markings and heights (RoadGeometry)."""
        return RoadGeometry.from_net(self.path)

    @cached_property
    def buildings(self) -> tuple[Building, ...]:
        """The mapped buildings of ``polygons`` (footprints in network metres, heights)."""
        return tuple(b for p in self.polygons for b in read_buildings(p))

    def lane_frame(self, lane_id: str) -> RoadFrame:
        """Road coordinates along the centre line of ``lane_id``."""
        frame = self._frames.get(lane_id)
        if frame is None:
            try:
                lane = self.sumo.getLane(lane_id)
            except KeyError:
                raise HiyariError(f"{self.path}: no lane {lane_id!r}") from None
            pts = np.array([p[:2] for p in lane.getShape()], dtype=float)
            frame = self._frames[lane_id] = RoadFrame.from_points(
                pts, lane.getEdge().getID(), lane.getIndex()
            )
        return frame
