"""OpenStreetMap import: netconvert's OSM workflow with SUMO's type maps (convert), a repaired
copy of the user's file (repair: sidewalks, crossings, bounding box; levels: bridge and tunnel
heights) and the repairs of the converted net's junctions (junction_repair)."""

from hiyari.net.sumo.osm.convert import NETCONVERT_OPTIONS, OsmImportOptions, import_osm

__all__ = ["NETCONVERT_OPTIONS", "OsmImportOptions", "import_osm"]
