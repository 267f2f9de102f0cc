"""LiDAR: scan patterns and presets, the ray-cast scan, recognition into object lists."""
