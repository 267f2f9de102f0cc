"""Embree 4 called directly from compiled code: triangle scenes on shared numpy buffers and
nearest-hit queries one ray or eight rays (a packet) at a time.

The library is the one the ``embreex`` wheel ships (``embreex.libs/libembree4-*.so``); its C
functions are bound by name for numba (``ExternalFunction``), so the query loops run without
Python per ray, release the GIL and cache like every other kernel. Struct layouts follow
``rtcore_ray.h`` of Embree 4 (RTCRayHit and RTCRayHit8, with one instance level); only the
leading fields, whose offsets do not depend on build options, are read or written.

Scenes keep references to the vertex and index arrays they were built on (Embree reads them in
place). Frames: whatever the caller's vertices are in; directions need not be unit but are
(``t`` is then in metres).
"""

from __future__ import annotations

import ctypes
import glob
import os
import weakref
from functools import cache

import embreex
import numpy as np
from llvmlite import binding
from numba import types

from hiyari.jit import njit

RTC_GEOMETRY_TYPE_TRIANGLE = 0
RTC_BUFFER_TYPE_INDEX = 0
RTC_BUFFER_TYPE_VERTEX = 1
RTC_FORMAT_UINT3 = 0x5003
RTC_FORMAT_FLOAT3 = 0x9003
RTC_BUILD_QUALITY_LOW = 0
RTC_BUILD_QUALITY_MEDIUM = 1
RTC_BUILD_QUALITY_REFIT = 3
RTC_SCENE_FLAG_DYNAMIC = 1
RTC_SCENE_FLAG_ROBUST = 4
INVALID = 0xFFFFFFFF

#: RTCRayHit as float32 words: ray org 0-2, tnear 3, dir 4-6, time 7, tfar 8, mask 9, id 10,
#: flags 11; hit Ng 12-14, u 15, v 16, primID 17, geomID 18, instID 19 (+ instPrimID 20).
RAY_WORDS = 32
#: RTCRayHit8: the same fields as arrays of 8 (field k at words 8k .. 8k + 7).
PACKET = 8
PACKET_WORDS = 32 * PACKET


def _library_path() -> str:
    libs = os.path.join(os.path.dirname(os.path.dirname(embreex.__file__)), "embreex.libs")
    found = sorted(glob.glob(os.path.join(libs, "libembree4*.so*")))
    if not found:
        raise ImportError(f"no libembree4 shared library in {libs}")
    return found[0]


@cache
def _lib() -> ctypes.CDLL:
    path = _library_path()
    lib = ctypes.CDLL(path, mode=ctypes.RTLD_GLOBAL)
    binding.load_library_permanently(path)  # numba's ExternalFunctions resolve in it
    vp, u32, sz = ctypes.c_void_p, ctypes.c_uint32, ctypes.c_size_t
    sigs = {
        "rtcNewDevice": (vp, [ctypes.c_char_p]),
        "rtcReleaseDevice": (None, [vp]),
        "rtcNewScene": (vp, [vp]),
        "rtcReleaseScene": (None, [vp]),
        "rtcSetSceneBuildQuality": (None, [vp, u32]),
        "rtcSetSceneFlags": (None, [vp, u32]),
        "rtcCommitScene": (None, [vp]),
        "rtcNewGeometry": (vp, [vp, u32]),
        "rtcReleaseGeometry": (None, [vp]),
        "rtcSetGeometryBuildQuality": (None, [vp, u32]),
        "rtcSetSharedGeometryBuffer": (None, [vp, u32, u32, u32, vp, sz, sz, sz]),
        "rtcUpdateGeometryBuffer": (None, [vp, u32, u32]),
        "rtcCommitGeometry": (None, [vp]),
        "rtcAttachGeometry": (u32, [vp, vp]),
        "rtcGetDeviceError": (u32, [vp]),
    }
    for name, (res, args) in sigs.items():
        fn = getattr(lib, name)
        fn.restype, fn.argtypes = res, args
    return lib


_lib()
_intersect1 = types.ExternalFunction(
    "rtcIntersect1", types.void(types.uintp, types.uintp, types.uintp)
)
_intersect8 = types.ExternalFunction(
    "rtcIntersect8", types.void(types.uintp, types.uintp, types.uintp, types.uintp)
)


class Device:
    """One Embree device (its thread pool is not used: queries run on the caller's threads)."""

    def __init__(self) -> None:
        lib = _lib()
        self.handle = lib.rtcNewDevice(b"threads=1")
        if not self.handle:
            raise RuntimeError("Embree: rtcNewDevice failed")
        weakref.finalize(self, lib.rtcReleaseDevice, self.handle)


class TriangleScene:
    """One triangle mesh in an Embree scene over the caller's arrays (kept, not copied).

    Scenes are robust (watertight triangle tests): the hits are embreex's, bit for bit, and do
    not depend on the BVH, so a refitted scene answers as a rebuilt one. ``refit=True`` builds
    for refitting: :meth:`move` then updates the vertex positions (same triangles) and refits
    the BVH instead of rebuilding it.
    """

    def __init__(
        self, device: Device, vertices: np.ndarray, faces: np.ndarray, refit: bool = False
    ) -> None:
        lib = _lib()
        self.device = device
        vertices = np.asarray(vertices, np.float32)
        # Embree may read 16 bytes at the last vertex: one float of padding
        self._vbuf = np.zeros(vertices.size + 1, np.float32)
        self._vbuf[:-1] = vertices.ravel()
        self.faces = np.ascontiguousarray(faces, np.uint32)
        self.handle = lib.rtcNewScene(device.handle)
        weakref.finalize(self, lib.rtcReleaseScene, self.handle)
        flags = RTC_SCENE_FLAG_ROBUST
        if refit:
            flags |= RTC_SCENE_FLAG_DYNAMIC
            lib.rtcSetSceneBuildQuality(self.handle, RTC_BUILD_QUALITY_LOW)
        lib.rtcSetSceneFlags(self.handle, flags)
        geom = lib.rtcNewGeometry(device.handle, RTC_GEOMETRY_TYPE_TRIANGLE)
        if refit:
            lib.rtcSetGeometryBuildQuality(geom, RTC_BUILD_QUALITY_REFIT)
        lib.rtcSetSharedGeometryBuffer(
            geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, self._vbuf.ctypes.data, 0, 12,
            len(vertices),
        )  # fmt: skip
        lib.rtcSetSharedGeometryBuffer(
            geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, self.faces.ctypes.data, 0, 12,
            len(self.faces),
        )  # fmt: skip
        lib.rtcCommitGeometry(geom)
        lib.rtcAttachGeometry(self.handle, geom)
        self._geom = geom
        lib.rtcReleaseGeometry(geom)  # the scene holds it
        lib.rtcCommitScene(self.handle)
        err = lib.rtcGetDeviceError(device.handle)
        if err:
            raise RuntimeError(f"Embree: error {err} building a scene")

    def move(self, vertices: np.ndarray) -> None:
        """New positions (V, 3) of the same vertices; the BVH is refitted (built with
        refit=True) or rebuilt."""
        lib = _lib()
        if np.size(vertices) != len(self._vbuf) - 1:
            raise ValueError("move: not the scene's vertex count")
        self._vbuf[:-1] = np.asarray(vertices, np.float32).ravel()
        lib.rtcUpdateGeometryBuffer(self._geom, RTC_BUFFER_TYPE_VERTEX, 0)
        lib.rtcCommitGeometry(self._geom)
        lib.rtcCommitScene(self.handle)

    def intersect(
        self,
        origins: np.ndarray,
        directions: np.ndarray,
        tfar: np.ndarray | float,
        packets: bool = True,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Nearest hit of each ray (origins, directions (N, 3) float32) closer than ``tfar``
        (m, (N,) or one for all): (primitive (N,) int32, -1 on a miss; t (N,) float32, ``tfar``
        on a miss; geometric normal (N, 3) float32, unnormalised). ``packets``: 8 rays per
        Embree query (else one)."""
        n = len(directions)
        if np.ndim(tfar) == 0:
            tfar = np.full(n, tfar, np.float32)
        prim = np.empty(n, np.int32)
        t = np.empty(n, np.float32)
        ng = np.empty((n, 3), np.float32)
        kernel = intersect_packets if packets else intersect_rays
        kernel(
            self.handle,
            np.ascontiguousarray(origins, np.float32),
            np.ascontiguousarray(directions, np.float32),
            np.ascontiguousarray(tfar, np.float32),
            prim,
            t,
            ng,
        )
        return prim, t, ng


@njit(cache=True, nogil=True)
def intersect_rays(
    scene: int,
    origins: np.ndarray,
    directions: np.ndarray,
    tfar: np.ndarray,
    prim: np.ndarray,
    t: np.ndarray,
    ng: np.ndarray,
) -> None:
    """rtcIntersect1 per ray into ``prim``, ``t``, ``ng`` (see TriangleScene.intersect)."""
    # 16-byte aligned ray
    raw = np.zeros(RAY_WORDS + 4, np.float32)
    off = (4 - (raw.ctypes.data // 4) % 4) % 4
    buf = raw[off : off + RAY_WORDS]
    bits = buf.view(np.uint32)
    ptr = buf.ctypes.data
    for p in range(len(directions)):
        buf[0], buf[1], buf[2], buf[3] = origins[p, 0], origins[p, 1], origins[p, 2], 0.0
        buf[4], buf[5], buf[6], buf[7] = directions[p, 0], directions[p, 1], directions[p, 2], 0.0
        buf[8] = tfar[p]
        bits[9], bits[10], bits[11] = INVALID, 0, 0
        bits[18], bits[19] = INVALID, INVALID
        _intersect1(scene, ptr, 0)
        if bits[18] != INVALID:
            prim[p] = np.int32(bits[17])
        else:
            prim[p] = -1
        t[p] = buf[8]
        ng[p, 0], ng[p, 1], ng[p, 2] = buf[12], buf[13], buf[14]


@njit(cache=True, nogil=True)
def intersect_packets(
    scene: int,
    origins: np.ndarray,
    directions: np.ndarray,
    tfar: np.ndarray,
    prim: np.ndarray,
    t: np.ndarray,
    ng: np.ndarray,
) -> None:
    """rtcIntersect8 on consecutive groups of 8 rays (the last one masked) into ``prim``,
    ``t``, ``ng`` (see TriangleScene.intersect)."""
    # 32-byte aligned packet and valid mask
    raw = np.zeros(PACKET_WORDS + 8, np.float32)
    off = (8 - (raw.ctypes.data // 4) % 8) % 8
    buf = raw[off : off + PACKET_WORDS]
    bits = buf.view(np.uint32)
    vraw = np.zeros(16, np.int32)
    voff = (8 - (vraw.ctypes.data // 4) % 8) % 8
    valid = vraw[voff : voff + PACKET]
    ptr, vptr = buf.ctypes.data, valid.ctypes.data
    n = len(directions)
    for a in range(0, n, PACKET):
        m = min(PACKET, n - a)
        for k in range(PACKET):
            if k < m:
                p = a + k
                valid[k] = -1
                buf[k], buf[8 + k], buf[16 + k] = origins[p, 0], origins[p, 1], origins[p, 2]
                buf[32 + k], buf[40 + k] = directions[p, 0], directions[p, 1]
                buf[48 + k] = directions[p, 2]
                buf[64 + k] = tfar[p]
            else:
                valid[k] = 0
            buf[24 + k], buf[56 + k] = 0.0, 0.0
            bits[72 + k], bits[80 + k], bits[88 + k] = INVALID, 0, 0
            bits[144 + k], bits[152 + k] = INVALID, INVALID
        _intersect8(vptr, scene, ptr, 0)
        for k in range(m):
            p = a + k
            if bits[144 + k] != INVALID:
                prim[p] = np.int32(bits[136 + k])
            else:
                prim[p] = -1
            t[p] = buf[64 + k]
            ng[p, 0], ng[p, 1], ng[p, 2] = buf[96 + k], buf[104 + k], buf[112 + k]
