"""Whether two SUMO nets are the same road (net/sumo/files.road_difference): the check that a
user's SUMO scenario runs on the conversion of the road an OpenSCENARIO file names."""

from __future__ import annotations

from pathlib import Path

from hiyari.net.sumo.files import road_difference


def _net(folder: Path, name: str, lanes: dict[str, list[float]]) -> Path:
    """A net file with these ordinary edges and lane lengths (m), one internal edge."""
    edges = "".join(
        f'<edge id="{e}" from="a" to="b">'
        + "".join(f'<lane id="{e}_{i}" index="{i}" length="{n}" shape="0,0 {n},0"/>'
                  for i, n in enumerate(lengths))
        + "</edge>"
        for e, lengths in lanes.items()
    )  # fmt: skip
    internal = '<edge id=":b_0" function="internal"><lane id=":b_0_0" length="3.0"/></edge>'
    path = folder / f"{name}.net.xml"
    path.write_text(f'<net version="1.20">{internal}{edges}</net>')
    return path


ROAD = {"0": [500.0, 500.0], "-0": [500.0, 500.0]}


def test_same_road_within_the_length_tolerance(tmp_path):
    ref = _net(tmp_path, "ref", ROAD)
    assert road_difference(_net(tmp_path, "same", {**ROAD, "0": [500.05, 499.95]}), ref) is None


def test_each_difference_is_named(tmp_path):
    ref = _net(tmp_path, "ref", ROAD)
    extra = _net(tmp_path, "extra", {**ROAD, "1": [80.0]})
    assert road_difference(extra, ref) == "edge 1 is not in the reference"
    missing = _net(tmp_path, "missing", {"0": [500.0, 500.0]})
    assert road_difference(missing, ref) == "edge -0 is missing"
    narrower = _net(tmp_path, "narrow", {**ROAD, "0": [500.0]})
    assert road_difference(narrower, ref) == "edge 0 has 1 lane(s), not 2"
    longer = _net(tmp_path, "longer", {**ROAD, "-0": [500.0, 500.2]})
    assert (
        road_difference(longer, ref)
        == "edge -0's lanes are [500.0, 500.2] m long, not [500.0, 500.0] m"
    )
