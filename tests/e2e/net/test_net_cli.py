"""``hiyari net``: build, import and mesh from the command line; bad input as one line."""

from __future__ import annotations

import numpy as np
import pytest
from paths import SHARED

from hiyari.bridge.cli.main import main
from hiyari.net.mesh.scene_mesh import SceneMesh
from hiyari.net.road.geometry import RoadGeometry
from hiyari.net.sumo.plain_xml import build_net

ALKS = SHARED / "data" / "opendrive" / "alks"


def test_build_then_mesh(tmp_path, capsys):
    net = tmp_path / "ex.net.xml"
    assert (
        main(["net", "build", "expressway", "-o", str(net), "--lanes", "3", "--no-off-ramp"]) == 0
    )
    assert str(net) in capsys.readouterr().out
    g = RoadGeometry.from_net(net)
    assert len(g.edges["east_merge"].lanes) == 4 and "offramp" not in g.edges
    glb, npz = tmp_path / "scene.glb", tmp_path / "scene.npz"
    assert main(["net", "mesh", str(net), "-o", str(glb), "-o", str(npz)]) == 0
    out = capsys.readouterr().out
    assert str(glb) in out and str(npz) in out and "triangles" in out
    mesh = SceneMesh.load_npz(npz)
    assert len(mesh.faces) > 1000 and glb.stat().st_size > 10_000


@pytest.mark.parametrize("kind", ["city", "intersection", "r157"])
def test_build_kinds(tmp_path, capsys, kind):
    net = tmp_path / f"{kind}.net.xml"
    extra = ["--blocks-x", "1", "--blocks-y", "1"] if kind == "city" else []
    assert main(["net", "build", kind, "-o", str(net), *extra]) == 0
    assert net.is_file() and str(net) in capsys.readouterr().out


def test_import_alks(tmp_path, capsys):
    net = tmp_path / "alks.net.xml"
    xodr = ALKS / "alks_road_right_radius_1000m.xodr"
    assert main(["net", "import", str(xodr), "-o", str(net)]) == 0
    assert str(net) in capsys.readouterr().out
    g = RoadGeometry.from_net(net)
    assert np.isclose(g.offset, 0.0).all()  # OpenDRIVE coordinates kept


def test_mesh_of_a_net_without_drivable_lanes(tmp_path, capsys):
    nodes = [{"id": "a", "x": 0, "y": 0}, {"id": "b", "x": 50, "y": 0}]
    edges = [{"id": "path", "from": "a", "to": "b", "allow": "pedestrian", "width": 2.0}]
    net = build_net(tmp_path / "walk.net.xml", nodes, edges, [], "footpath")
    out = tmp_path / "out" / "scene.glb"
    assert main(["net", "mesh", str(net), "-o", str(out)]) == 1
    err = capsys.readouterr().err
    assert err == f"hiyari: error: {net}: network has no drivable lanes\n"
    assert not out.parent.exists()


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["net", "import", "{bad}", "-o", "{out}"], "not well-formed XML"),
        (["net", "mesh", "{bad}", "-o", "{out}.glb"], "not well-formed XML"),
        (["net", "build", "r157", "-o", "{out}", "--length", "10"], "length must be >= 100"),
        (["net", "build", "expressway", "-o", "{out}", "--gradient", "0.5"], "gradient"),
    ],
)
def test_bad_input_one_line_exit_1(tmp_path, capsys, args, words):
    bad = tmp_path / "bad.xml"
    bad.write_text("<OpenDRIVE><road")
    out = tmp_path / "out" / "result.net.xml"
    argv = [a.format(bad=bad, out=out) for a in args]
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert err.startswith("hiyari: error: ") and words in err and err.count("\n") == 1
    assert not out.parent.exists() or list(out.parent.iterdir()) == []
