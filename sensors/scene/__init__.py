"""The Embree scene: the static road mesh plus one shape per actor, updated every step."""
