"""Sensors against ground truth: where a judged condition's verdict differs from perfect
perception's on the same point, the perception limit that explains it.

The judge runs the same points under perfect perception (every actor within 150 m and 180 deg,
exact, no occlusion) and under the sensor stack. Each run records when the point's target
first came into line of sight of the ego (ground truth: no other actor's footprint between
them, hiyari.risk.metrics.visibility) and when the stack's fused tracks first held it. A
differing verdict is explained, in this order, by:

- ``run failed``: the run crashed or raised (no perception question);
- ``false activation``: the sensor run braked before the manoeuvre started (not tested), so
  the stack acted on something that was not a conflict;
- ``disturbance preset``: the condition had a disturbance (rain, fog, night, ...) and the
  target was tracked late or never;
- ``occlusion``: the target came into line of sight only after perfect perception had braked,
  or never;
- ``not detected``: the target was in sight, and the stack never tracked it;
- ``range``: the target was in sight but first tracked beyond :data:`RANGE_FRACTION` of the
  rig's longest sensor range (it was tracked as soon as it came within reach);
- ``tracking latency``: in sight and within range, tracked later than perfect perception
  braked (detection, confirmation over several frames, velocity estimation);
- ``closed loop``: the sensor run did better than perfect perception (its braking started on
  an estimate, not on the truth): not a perception limit, listed so nothing is hidden.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from hiyari.sensors.rig import SensorRig

#: A target first tracked beyond this fraction of the rig's longest range was range-limited.
RANGE_FRACTION = 0.9
PERFECT = "perfect"


@dataclass(frozen=True)
class Difference:
    """One point whose verdict under ``condition`` differs from perfect perception's."""

    id: str
    scenario: str
    condition: str
    perfect: str  # verdict with perfect perception
    verdict: str  # verdict under ``condition``
    cause: str
    detail: str

    def row(self) -> dict[str, str]:
        """The differences.csv row."""
        return dict(vars(self))


def rig_reach_m() -> float:
    """The longest range of the default sensor rig, m."""
    return max(s.config.max_range_m for s in SensorRig.default().sensors)


def _num(row: dict, key: str) -> float:
    value = row.get(key)
    return float(value) if value not in (None, "") else math.nan


def explain(perfect: dict, sensed: dict, reach_m: float) -> tuple[str, str]:
    """(cause, detail) of a verdict difference between the perfect-perception row and the row
    of another condition for the same point (judge rows: times s, ranges m). ``reach_m``: the
    longest range of the sensor rig."""
    if sensed["verdict"] in ("crashed", "error"):
        return "run failed", str(sensed.get("error", ""))
    if sensed["verdict"] == "not tested" and perfect["verdict"] != "not tested":
        return "false activation", f"braked before the manoeuvre: {sensed['untested_cause']}"
    if perfect["verdict"] in ("fail", "not tested") and sensed["verdict"] == "pass":
        return "closed loop", "the sensor run avoided what perfect perception did not"
    braked = _num(perfect, "aeb_brake_time_s")
    sight, sight_range = _num(sensed, "target_in_sight_s"), _num(sensed, "target_in_sight_range_m")
    tracked, tracked_range = (
        _num(sensed, "target_tracked_s"),
        _num(sensed, "target_tracked_range_m"),
    )
    when = (
        f"in sight at {sight:.2f} s ({sight_range:.1f} m), "
        f"tracked at {tracked:.2f} s ({tracked_range:.1f} m); "
        f"perfect perception braked at {braked:.2f} s"
    )
    preset = sensed["condition"].partition("/")[2]
    if preset and preset != "clear":
        return "disturbance preset", f"{preset}: {when}"
    if math.isnan(sight) or (not math.isnan(braked) and sight > braked):
        return "occlusion", when
    if math.isnan(tracked):
        return "not detected", f"in sight at {sight:.2f} s ({sight_range:.1f} m), never tracked"
    if tracked_range >= RANGE_FRACTION * reach_m:
        return "range", f"{when}; the rig reaches {reach_m:.0f} m"
    return "tracking latency", when


def differences(rows: list[dict], reach_m: float) -> list[Difference]:
    """Every point whose verdict under a condition other than perfect perception differs from
    its verdict with perfect perception (judge rows of both; none without a perfect one)."""
    truth = {r["id"]: r for r in rows if r["condition"] == PERFECT}
    out = []
    for r in rows:
        p = truth.get(r["id"])
        if r["condition"] == PERFECT or p is None or p["verdict"] == r["verdict"]:
            continue
        cause, detail = explain(p, r, reach_m)
        out.append(
            Difference(r["id"], r["scenario"], r["condition"], p["verdict"], r["verdict"],
                       cause, detail)
        )  # fmt: skip
    return out
