"""The road network is read once per run and shared by the scenario, the sensors' scene and
the recorder."""

from __future__ import annotations

import pytest
import sumolib

from hiyari.bridge.loop.spec import StackContext, default_stack
from hiyari.bridge.loop.toml_runs import preset_spec
from hiyari.bridge.openscenario.presets.toml_file import ConcreteScenario
from hiyari.errors import HiyariError
from hiyari.net.road import geometry as geometry_module
from hiyari.net.road.network import RoadNetwork


def test_cut_in_reads_its_net_once(tmp_path, monkeypatch):
    calls = {"sumolib": 0, "geometry": 0}
    read_net, from_net = sumolib.net.readNet, geometry_module.RoadGeometry.from_net

    def counted_read(*args, **kwargs):
        calls["sumolib"] += 1
        return read_net(*args, **kwargs)

    def counted_geometry(path):
        calls["geometry"] += 1
        return from_net(path)

    monkeypatch.setattr(sumolib.net, "readNet", counted_read)
    monkeypatch.setattr(geometry_module.RoadGeometry, "from_net", staticmethod(counted_geometry))
    params = {"ve0_kmh": 60.0, "vo0_kmh": 30.0, "dx0_m": 40.0, "vy_ms": 1.0}
    cs = ConcreteScenario("cut-in", "x", 0, 1, 5.0, 0.05, params, perception="sensors")
    spec = preset_spec(cs, tmp_path)
    network = spec.road.network
    ctx = StackContext(network, spec.ego, "ego", spec.ego.set_speed, spec.scenario)
    stack = default_stack(ctx)
    assert stack.perception.scene.static_mesh is not None
    assert network.geometry is network.geometry  # kept, not rebuilt
    assert calls == {"sumolib": 1, "geometry": 1}
    # the engine's road / lane / s frame is that same net's
    assert spec.road.lanes.net == network.path


def test_missing_net_is_one_line_error(tmp_path):
    with pytest.raises(HiyariError, match="not found"):
        _ = RoadNetwork(tmp_path / "nope.net.xml").sumo
    bad = tmp_path / "bad.net.xml"
    bad.write_text("<net><edge")
    with pytest.raises(HiyariError, match="bad.net.xml"):
        _ = RoadNetwork(bad).sumo
