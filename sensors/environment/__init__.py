"""The environment the sensors share: weather, light, soiling, and the disturbance presets."""
