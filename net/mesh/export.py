"""Write a SceneMesh for viewers (glTF / GLB, PLY) or as numpy arrays (.npz).

glTF is y-up by specification: GLB / glTF files hold (x, z, -y) of the network frame so that
viewers show the road lying flat; PLY and .npz keep the network frame (z up). Each material
becomes its own glTF mesh with a base colour (``net.materials.DISPLAY_RGB``); PLY carries a
colour per face.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import trimesh

from hiyari.atomic import atomic_path
from hiyari.errors import HiyariError
from hiyari.net.mesh.materials import DEFAULT_OPTICS, DISPLAY_RGB, Material
from hiyari.net.mesh.scene_mesh import SceneMesh

#: Network frame (z up) to glTF frame (y up).
_Z_UP_TO_Y_UP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])

SUFFIXES = (".glb", ".gltf", ".ply", ".npz")


def _gltf_scene(mesh: SceneMesh) -> trimesh.Scene:
    scene = trimesh.Scene()
    vertices = mesh.vertices @ _Z_UP_TO_Y_UP.T
    for mat in np.unique(mesh.material):
        m = Material(int(mat))
        faces = mesh.faces[mesh.material == mat]
        used, inverse = np.unique(faces, return_inverse=True)
        rgb = DISPLAY_RGB[m]
        pbr = trimesh.visual.material.PBRMaterial(
            name=m.name.lower(),
            baseColorFactor=[*rgb, 255],
            metallicFactor=1.0 if m == Material.BARRIER_METAL else 0.0,
            roughnessFactor=1.0 - DEFAULT_OPTICS[m].specular,
        )
        part = trimesh.Trimesh(
            vertices[used],
            inverse.reshape(-1, 3),
            process=False,
            visual=trimesh.visual.TextureVisuals(material=pbr),
        )
        scene.add_geometry(part, node_name=m.name.lower(), geom_name=m.name.lower())
    return scene


def export_mesh(mesh: SceneMesh, path: str | Path) -> Path:
    """Write ``mesh`` to ``path``; the suffix (.glb, .gltf, .ply, .npz) picks the format."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in SUFFIXES:
        raise HiyariError(f"{path}: unknown mesh format {suffix!r} (use {', '.join(SUFFIXES)})")
    if suffix == ".npz":
        return mesh.save_npz(path)
    if suffix == ".ply":
        colours = np.zeros((256, 4), dtype=np.uint8)
        for m in Material:
            colours[m] = (*DISPLAY_RGB[m], 255)
        tm = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)
        tm.visual.face_colors = colours[mesh.material]
        data = tm.export(file_type="ply")
    elif suffix == ".glb":
        data = _gltf_scene(mesh).export(file_type="glb")
    else:
        files = trimesh.exchange.gltf.export_gltf(_gltf_scene(mesh), embed_buffers=True)
        data = files["model.gltf"]
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)
    return path
