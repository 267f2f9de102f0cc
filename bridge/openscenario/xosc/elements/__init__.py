"""Readers of the storyboard's elements (actions, conditions, global actions, positions,
traffic actions, trajectories): one XML element to one model dataclass, SI units."""
