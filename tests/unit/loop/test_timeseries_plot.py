"""Issue 15 item 6: the run time series shades what the controller did. An AEB stage decided
for one sample but latched to a standstill is shaded for its whole braking, by level; ACC
braking is labelled as such."""

from __future__ import annotations

import numpy as np
from matplotlib.patches import Rectangle

from hiyari.bridge.loop.result import RunResult
from hiyari.bridge.studies.report.timeseries import plot_timeseries, timeseries_figure
from hiyari.units import G


def _latched_aeb_run() -> RunResult:
    """0.05 s steps: ACC brakes at 3 m/s² from 1.0 to 3.0 s, the AEB decides 'partial' for the one
    sample at 2.0 s and applies 0.4 g from 2.2 s (0.2 s actuation delay) until 6.0 s."""
    r = RunResult("cut-in #0")
    s = r.series
    for k in range(160):
        t = 0.05 * k
        aeb = 0.4 * G if 2.2 - 1e-9 <= t < 6.0 else 0.0
        acc = -3.0 if 1.0 - 1e-9 <= t < 3.0 else 0.0
        s.t.append(t)
        s.ego_speed.append(15.0)
        s.ego_accel_cmd.append(min(acc, -aeb) if aeb else acc)
        s.gap.append(20.0)
        s.ttc_true.append(3.0)
        s.ttc_stack.append(3.0)
        s.aeb_stage.append(2 if k == 40 else 0)
        s.aeb_decel.append(aeb)
    return r


def _covered(ax: object, colour_of: dict, label: str) -> list[tuple[float, float]]:
    spans = []
    for patch in ax.patches:
        if isinstance(patch, Rectangle) and np.allclose(patch.get_facecolor(), colour_of[label]):
            x0 = patch.get_x()
            spans.append((round(x0, 6), round(x0 + patch.get_width(), 6)))
    return sorted(spans)


def test_latched_aeb_and_acc_braking_are_shaded(tmp_path):
    fig = timeseries_figure(_latched_aeb_run())
    legend = fig.legends[0]
    pairs = zip(legend.texts, legend.legend_handles, strict=True)
    colour_of = {t.get_text(): h.get_facecolor() for t, h in pairs if isinstance(h, Rectangle)}
    assert {"AEB braking 0.4 g", "ACC braking (< -0.3 m/s²)"} <= set(colour_of)
    assert any("AEB decides partial at 2.00 s" in t.get_text() for t in legend.texts)
    for ax in fig.axes:
        assert _covered(ax, colour_of, "AEB braking 0.4 g") == [(2.2, 6.0)]
        assert _covered(ax, colour_of, "ACC braking (< -0.3 m/s²)") == [(1.0, 2.2)]
    assert plot_timeseries(_latched_aeb_run(), tmp_path / "ts.png").stat().st_size > 20_000
