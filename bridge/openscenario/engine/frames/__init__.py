"""Conditions measured in the frames OpenSCENARIO's ``coordinateSystem`` names beyond the
entity's and the road's: along a lane's centre line (lane) and along an assigned trajectory
(trajectory). Evaluated in Python, beside the compiled trigger kernel."""
