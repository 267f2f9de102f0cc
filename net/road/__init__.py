"""Road geometry read once from a SUMO net: lanes, sidewalks, crossings, markings, heights."""
