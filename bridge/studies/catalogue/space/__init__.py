"""The catalogue's scenario space: the JAMA taxonomy, the geometric obstruction test, parameter
ranges, road layouts, concrete scenarios in the scenario model and their OpenSCENARIO export."""
