"""The compiled first-contact kernel equals contact_gap + first_contact_time bit for bit."""

from __future__ import annotations

import numpy as np

from hiyari.risk.metrics.contact import ContactGeometry, contact_gap, first_contact_time
from hiyari.risk.sct.contact_kernel import first_contacts


def _reference(vxy, vh, length, width, contact, tracks, exposed, a, t, times):
    gap = contact_gap(vxy[a], vh[a], length[a, None], width[a, None], tracks[t], contact)  # (n, K)
    gap = np.where(exposed[t], gap, np.inf)
    return first_contact_time(gap, times), gap[:, 0] > 0


def test_kernel_equals_numpy_bit_for_bit():
    rng = np.random.default_rng(7)
    times = np.arange(51) * 0.2
    n_a, n_t = 40, 60
    # vehicles driving along x through the pedestrians' area, pedestrians crossing it
    start = rng.uniform(-30, 0, (n_a, 1, 2))
    speed = rng.uniform(0, 15, (n_a, 1, 1))
    heading = rng.uniform(-np.pi, np.pi, (n_a, len(times)))
    vxy = start + speed * times[None, :, None] * np.stack([np.cos(heading), np.sin(heading)], -1)
    tracks = (
        rng.uniform(-10, 10, (n_t, 1, 2)) + rng.normal(0, 1.5, (n_t, 1, 2)) * times[None, :, None]
    )
    tracks[:5] = vxy[:5]  # touching from the first sample
    exposed = rng.random((n_t, len(times))) < 0.8
    exposed[5:10] = False  # protected throughout
    length, width = rng.uniform(3, 12, n_a), rng.uniform(1.5, 2.6, n_a)
    a = np.repeat(np.arange(n_a), n_t)
    t = np.tile(np.arange(n_t), n_a)
    contact = ContactGeometry(0.2, 0.3)
    first, apart = first_contacts(
        vxy, heading, length, width, 0.2, 0.3, tracks, exposed, a, t, times
    )
    ref_first, ref_apart = _reference(
        vxy, heading, length, width, contact, tracks, exposed, a, t, times
    )
    assert np.isfinite(first).sum() > 100 and np.isinf(first).sum() > 100  # both kinds occur
    assert (first == 0).any() and not apart.all()  # contacts from the first sample too
    assert np.array_equal(first, ref_first)
    assert np.array_equal(apart, ref_apart)
    assert first.tobytes() == ref_first.tobytes()


def test_kernel_interpolates_between_samples():
    # a point pedestrian standing 5 m ahead of a 4 m x 2 m car driving at 10 m/s along +x:
    # the front (2 m ahead of the centre) reaches x = 5 - 0.3 at t = 0.27 s
    times = np.arange(11) * 0.1
    vxy = np.stack([10.0 * times, np.zeros_like(times)], -1)[None]
    tracks = np.tile([5.0, 0.0], (1, len(times), 1))
    first, apart = first_contacts(
        vxy,
        np.zeros((1, len(times))),
        np.array([4.0]),
        np.array([2.0]),
        0.0,
        0.3,
        tracks,
        np.ones((1, len(times)), bool),
        np.array([0]),
        np.array([0]),
        times,
    )
    assert apart[0]
    assert abs(first[0] - 0.27) < 1e-12
