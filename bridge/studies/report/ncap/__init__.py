"""The Euro NCAP datasheet of ``hiyari ncap``: colour grids per scenario, the points table, the
points that lost points with their recordings and replays, the runs not tested."""
