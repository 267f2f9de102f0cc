"""Paths in the plane that actors follow and positions refer to: trajectories (polyline,
clothoid, clothoid spline, NURBS) and routes along the roads, sampled into polylines."""
