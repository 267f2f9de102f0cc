"""One road network per run, read once: a handle that the scenario builder, the sensors' scene
and the recorder share instead of each parsing the .net.xml again.

Everything is built lazily on first use and kept: the sumolib net (topology, routes), lane
frames (road coordinates along a lane) and the RoadGeometry (lanes, borders, markings,
heights: the scene mesh and OSI ground truth are built from it).
"""

from __future__ import annotations

from functools import cached_property
from pathlib import Path

import numpy as np
import sumolib

from hiyari.errors import HiyariError
from hiyari.net.road.geometry import RoadGeometry
from hiyari.net.road.lane_frame import RoadFrame


class RoadNetwork:
    """A SUMO network file and what is read from it, each read at most once."""

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
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
