"""3D replay of a recording in the browser (viser): scene, server, static export."""
