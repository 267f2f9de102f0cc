"""Radar: ray grids and presets, the radar equation, recognition into object lists."""
