"""An Init AssignRouteAction SUMO cannot drive (its waypoints leave the insertion edge for an
edge it does not lead to): one line naming the file, the entity and the route, exit 1, in the
dry run as in the run, nothing written (before: libsumo's TraCIException as a traceback)."""

from __future__ import annotations

from pathlib import Path

import pytest
from openscenario_files import scenario_xml, teleport_speed, write

from hiyari.bridge.cli.main import main


@pytest.mark.parametrize("dry", [True, False])
def test_route_sumo_cannot_drive_is_one_line(tmp_path: Path, capsys, dry: bool) -> None:  # noqa: ANN001
    """The Ego drives +s on lane -4 of the ALKS straight road; its route's second waypoint is
    on lane 3, which drives -s on SUMO's other edge: no connection from one to the other."""
    route = """<Route name="Across" closed="false">
<Waypoint routeStrategy="shortest"><Position><LanePosition roadId="0" laneId="-4" s="5"/></Position></Waypoint>
<Waypoint routeStrategy="shortest"><Position><LanePosition roadId="0" laneId="3" s="500"/></Position></Waypoint></Route>"""
    init = teleport_speed("Ego", -4, 5.0, 10.0).replace(
        "</Private>",
        f"<PrivateAction><RoutingAction><AssignRouteAction>{route}</AssignRouteAction>"
        "</RoutingAction></PrivateAction></Private>",
    )
    path = write(tmp_path / "across.xosc", scenario_xml({"Ego": ""}, init))
    out = tmp_path / "out"
    argv = ["run", str(path), "-o", str(out), "-q", *(["--dry-run"] if dry else [])]
    assert main(argv) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("hiyari: error: "), err
    assert str(path) in err[0] and "Ego cannot drive its route 'Across' in SUMO" in err[0]
    assert "no connection from edge" in err[0]
    assert not out.exists()
