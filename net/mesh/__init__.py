"""The static 3D scene: road surface, markings, kerbs, rails and buildings with materials; export."""
