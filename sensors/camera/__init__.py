"""Camera: geometry and presets, analytic recognition, optional rendered image."""
