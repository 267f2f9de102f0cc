"""Vehicle-motion disturbances (JAMA 4.3): a planar single-track ego with a friction circle,
road friction, crosswind, ruts and cross slope, and the grip-use (adhesion utilisation) bands."""
