"""Report of the pedestrian incident study: tables, plots and the CSV of every incident.

Everything is written into one folder, atomically per file: ``report.md``, ``summary.json``,
``incidents.csv`` (one row per incident, both arms), ``incidents_bar.png`` (the seed's chart:
incidents per arm), ``ttc_sct_hist.png`` (per-encounter minimum TTC and SCT), and
``incidents_by_hour.png``.
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict
from pathlib import Path

import numpy as np  # noqa: E402
from matplotlib.figure import Figure

from hiyari.atomic import atomic_path, write_text_atomic  # noqa: E402
from hiyari.bridge.studies.sct.study import ARMS, ArmResult, StudyConfig  # noqa: E402
from hiyari.bridge.studies.sct.summary import (  # noqa: E402
    SEED_BASELINE,
    SEED_REDUCTION,
    SEED_SCT,
    ArmSummary,
    pair,
    reduction,
    summarise,
)
from hiyari.risk.metrics.incidents import CSV_FIELDS  # noqa: E402


def write_report(
    folder: str | Path,
    config: StudyConfig,
    results: list[ArmResult],
    wall_seconds: float,
    sensitivity: tuple[float, list] | None = None,
) -> Path:
    """Write the study report into ``folder``; return the Markdown file's path.
    ``sensitivity``: (simulated hours per point, SensitivityPoint list) to include."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    summaries = summarise(config, results)
    _write_csv(folder / "incidents.csv", config, results)
    _save(incidents_figure(config, summaries), folder / "incidents_bar.png")
    _save(encounters_figure(config, results), folder / "ttc_sct_hist.png")
    _save(timeline_figure(config, results), folder / "incidents_by_hour.png")
    facts = {v: _residual_facts(config, results, v) for v in config.variants}
    summary = {
        "config": _config_dict(config),
        "wall_seconds": round(wall_seconds, 1),
        "arms": [asdict(s) for s in summaries],
        "reduction": {  # null: no baseline incidents (JSON has no nan)
            v: _finite(reduction(*(s.incidents for s in pair(summaries, v))))
            for v in config.variants
        },
        "seed": {"baseline": SEED_BASELINE, "sct": SEED_SCT, "reduction": SEED_REDUCTION},
    }
    write_text_atomic(folder / "summary.json", json.dumps(summary, indent=2, default=str))
    with_sensitivity = sensitivity is not None and bool(sensitivity[1])
    text = _markdown(config, summaries, wall_seconds, facts, with_sensitivity)
    if with_sensitivity:
        from hiyari.bridge.studies.report.sct_sensitivity import write_sensitivity

        write_sensitivity(folder, sensitivity[1], sensitivity[0])
        text += _sensitivity_markdown(*sensitivity)
    return write_text_atomic(folder / "report.md", text)


def _sensitivity_markdown(hours: float, points: list) -> str:
    lines = [
        "",
        "## Sensitivity",
        "",
        f"One parameter at a time around the main configuration, {hours:g} simulated hours per "
        "arm and point (unsignalised, same seed); SCT_safe and penetration points share their "
        "baseline. The seed's −68 % is the dashed line.",
        "",
        "| parameter | value | baseline incidents | SCT incidents | change | travel-time cost, s |",
        "|---|---:|---:|---:|---:|---:|",
    ]
    for p in points:
        lines.append(
            f"| {p.parameter} | {p.value:g} | {p.baseline_incidents} | {p.sct_incidents} | "
            f"{-p.reduction:+.0%} | {p.travel_time_cost:+.1f} |"
        )
    lines += ["", "![sensitivity](sensitivity.png)", ""]
    return "\n".join(lines)


def _finite(x: float) -> float | None:
    return x if math.isfinite(x) else None


def _config_dict(config: StudyConfig) -> dict:
    d = asdict(config)
    d["run_seconds"] = config.run_seconds
    return d


def _write_csv(path: Path, config: StudyConfig, results: list[ArmResult]) -> None:
    import csv

    with atomic_path(path) as tmp, tmp.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=["variant", "arm", "run", "seed", *CSV_FIELDS])
        w.writeheader()
        for r in results:
            for e in r.incidents:
                row = {"variant": r.variant, "arm": r.arm, "run": r.run, "seed": r.seed}
                w.writerow({**row, **asdict(e)})


def _save(fig: Figure, path: Path) -> None:
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110, bbox_inches="tight")


def incidents_figure(config: StudyConfig, summaries: list[ArmSummary]) -> Figure:
    """Incidents per arm: the seed's Vissim study and hiyari's variants on separate axes (their
    simulated times and tools differ, so their counts do not share a scale)."""
    ours = []
    for v in config.variants:
        base, sct = pair(summaries, v)
        ours.append((v, base.incidents, sct.incidents))
    days = summaries[0].sim_days if summaries else config.days
    fig = Figure(figsize=(4.0 + 2.4 * len(ours), 4.4), layout="constrained")
    left, right = fig.subplots(1, 2, width_ratios=[1.4, 1.0 + len(ours)])
    panels = (
        (left, [("Vissim", SEED_BASELINE, SEED_SCT)], "DIVP seed, 2 simulated days"),
        (right, ours, f"hiyari, {days:.3g} simulated days per arm"),
    )
    for ax, groups, title in panels:
        x = np.arange(len(groups))
        w = 0.36
        b = ax.bar(x - w / 2, [g[1] for g in groups], w, label="standard drivers", color="#888")
        s = ax.bar(x + w / 2, [g[2] for g in groups], w, label="SCT drivers", color="#2a7")
        ax.bar_label(b, padding=2)
        ax.bar_label(s, padding=2)
        top = max(max(g[1], g[2]) for g in groups)
        for k, (_, nb, ns) in enumerate(groups):
            red = reduction(nb, ns)
            text = "no baseline\nincidents" if math.isnan(red) else f"{-red:+.0%}"
            ax.text(k, max(nb, ns) + 0.12 * top + 0.4, text, ha="center", fontweight="bold")
        ax.set_xticks(x, [g[0] for g in groups])
        ax.set_ylabel("incidents")
        ax.set_ylim(0, top * 1.35 + 2)
        ax.set_title(title, fontsize=10)
    left.legend(loc="upper right", fontsize=8)
    fig.suptitle(f"Pedestrian incidents, {config.vehicles_per_hour:g} veh/h")
    return fig


def encounters_figure(config: StudyConfig, results: list[ArmResult]) -> Figure:
    """Per-encounter minimum TTC and SCT, baseline against SCT arm, per variant."""
    h = config.metric_horizon
    bins = np.linspace(0.0, h, int(round(h / 0.25)) + 1)  # coarser than the 0.1 s step
    fig = Figure(figsize=(10, 3.4 * len(config.variants)), layout="constrained")
    axes = fig.subplots(len(config.variants), 2, squeeze=False)
    for row, v in enumerate(config.variants):
        for col, (name, field) in enumerate((("TTC", "min_ttc"), ("SCT", "min_sct"))):
            ax = axes[row, col]
            for arm, color in zip(ARMS, ("#888", "#2a7"), strict=True):
                vals = np.array(
                    [
                        getattr(e, field)
                        for r in results
                        if r.variant == v and r.arm == arm
                        for e in r.encounters
                    ]
                )
                vals = vals[np.isfinite(vals)]
                ax.hist(
                    vals, bins, histtype="step", lw=1.6, color=color, label=f"{arm} ({len(vals)})"
                )
            mark = config.incidents.ttc_threshold if name == "TTC" else config.controller.sct_safe
            if mark <= h:
                ax.axvline(mark, color="r", ls="--", lw=1)
            ax.set_title(f"{v}: minimum {name} per encounter\n(logged below {h:g} s)", fontsize=10)
            ax.set_xlabel(f"{name}, s")
            ax.set_ylabel("encounters")
            ax.set_ylim(bottom=0, top=max(ax.get_ylim()[1], 1.0))
            ax.legend()
    return fig


def timeline_figure(config: StudyConfig, results: list[ArmResult]) -> Figure:
    """Incidents per simulated hour across the whole study time, per arm and variant (per
    minute when the study is shorter than two hours)."""
    total = config.days * 86400.0
    unit, name = (3600.0, "hour") if total >= 7200.0 else (60.0, "minute")
    edges = np.append(np.arange(0.0, total / unit, 1.0), total / unit)
    fig = Figure(figsize=(10, 2.8 * len(config.variants)), layout="constrained")
    axes = fig.subplots(len(config.variants), 1, squeeze=False)
    for row, v in enumerate(config.variants):
        ax = axes[row, 0]
        for arm, color in zip(ARMS, ("#888", "#2a7"), strict=True):
            counts = np.zeros(len(edges) - 1)
            for r in results:
                if r.variant != v or r.arm != arm:
                    continue
                for e in r.incidents:
                    t = r.run * config.run_seconds + (0.0 if math.isnan(e.time) else e.time)
                    counts[min(int(t // unit), len(counts) - 1)] += 1
            ax.stairs(counts, edges, color=color, label=arm, lw=1.6)
        ax.set_title(f"{v}: incidents per simulated {name}", fontsize=10)
        ax.set_xlabel(f"simulated {name}s")
        ax.set_ylabel("incidents")
        ax.set_xlim(0, edges[-1])
        ax.set_ylim(bottom=0, top=max(ax.get_ylim()[1], 1.0))
        ax.legend()
    return fig


def _residual_facts(config: StudyConfig, results: list[ArmResult], variant: str) -> list[str]:
    """Measured facts behind the closing note: where the remaining incidents happen and
    what the contacts were."""
    walkingareas = ("_w",)  # SUMO walking-area lane ids look like ':C_w0_0'
    out = []
    if config.crossing_priority and variant == "unsignalised":
        out.append(
            "Baseline drivers: SUMO's, at zebra crossings (crossings have priority, so drivers "
            "yield to pedestrians on them or stepping onto them, as the traffic rules require)."
        )
    elif variant == "unsignalised":
        out.append(
            "Baseline drivers: SUMO's at crossings without priority (--minor-crossings): "
            "pedestrians wait for gaps and drivers keep the right of way."
        )
    for arm in ARMS:
        inc = [e for r in results if r.variant == variant and r.arm == arm for e in r.incidents]
        if not inc:
            continue
        corner = sum(any(w in e.pedestrian_lane for w in walkingareas) for e in inc)
        coll = [e for e in inc if e.collision]
        sct = np.array([e.min_sct for e in inc])
        line = (
            f"{variant}, {arm} arm: {len(inc)} incidents; in {corner} ({corner / len(inc):.0%}) "
            f"the pedestrian was still on a junction corner (walking area) at the worst moment; "
            f"median minimum SCT {np.median(sct):.2f} s"
        )
        if coll:
            speeds = np.array([e.vehicle_speed for e in coll])
            on_crossing = sum(":" in e.pedestrian_lane and "_c" in e.pedestrian_lane for e in coll)
            on_corner = sum(any(w in e.pedestrian_lane for w in walkingareas) for e in coll)
            line += (
                f"; {len(coll)} contacts: {on_crossing} with the pedestrian on a crossing, "
                f"{on_corner} on a corner walking area (a turning car's corner over the kerb "
                f"line of SUMO's corner geometry), {len(coll) - on_crossing - on_corner} "
                f"elsewhere; vehicle speed median {np.nanmedian(speeds):.1f} m/s"
            )
        out.append(line + ".")
    return out


def _setting(c: StudyConfig) -> str:
    """Where the study ran and with what demand, as the report's first sentence."""
    crossings = (
        f"the crossings {', '.join(c.crossings)}"
        if c.crossings
        else "every crossing with a sidewalk at both ends"
    )
    walkers = f"{c.persons_per_hour:g} pedestrians/h (Poisson) walking across {crossings}"
    if c.sumocfg:
        return f"Inside the SUMO scenario {c.sumocfg} (its own vehicles and persons); {walkers}"
    if c.map_net:
        return (f"On the map {c.map_net}, its junctions as they are; {c.vehicles_per_hour:g} "
                f"passenger cars/h (Poisson, fringe to fringe) and {walkers}")  # fmt: skip
    return (f"Four-leg intersection with a crossing on every leg; {c.vehicles_per_hour:g} "
            f"passenger cars/h and {c.persons_per_hour:g} pedestrians/h (Poisson, fringe to "
            "fringe)")  # fmt: skip


def _markdown(
    config: StudyConfig,
    summaries: list[ArmSummary],
    wall: float,
    facts: dict[str, list[str]],
    with_sensitivity: bool = False,
) -> str:
    c = config
    lines = [
        "# Pedestrian incident study: SUMO drivers vs Safety Cushion Time drivers",
        "",
        f"{_setting(c)}; "
        f"{c.days:g} simulated days per arm and variant at {c.step_length:g} s, split into "
        f"{c.runs} run(s) with seeds {c.seed}..{c.seed + c.runs - 1}, identical in both arms. "
        f"SCT arm: {c.penetration:.0%} of vehicles driven by the SCT model "
        f"(SCT_safe {c.controller.sct_safe:g} s). Wall time {wall:.0f} s.",
        "",
        f"Incident: minimum TTC < {c.incidents.ttc_threshold:g} s, or PET at a crossing "
        f"< {c.incidents.pet_threshold:g} s, or contact; once per vehicle–pedestrian pair.",
        "",
        "| variant | arm | vehicles | incidents | TTC | PET | collisions | mean travel time, s "
        "| mean delay, s | ped. delay, s |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for s in summaries:
        lines.append(
            f"| {s.variant} | {s.arm} | {s.vehicles} | {s.incidents} | {s.ttc_incidents} | "
            f"{s.pet_incidents} | {s.collisions} | {s.mean_travel_time:.1f} | "
            f"{s.mean_time_loss:.1f} | {s.mean_pedestrian_time_loss:.1f} |"
        )
    lost = [s for s in summaries if s.crashed_runs]
    if lost:
        lines += [
            "",
            "**Incomplete**: "
            + ", ".join(f"{s.variant} {s.arm}: {s.crashed_runs} run(s)" for s in lost)
            + " crashed (the worker process died) and are left out of every figure here; "
            "the arms are not comparable until the same command is run again.",
        ]
    lines += [
        "",
        "| | baseline incidents | SCT incidents | reduction | travel-time cost |",
        "|---|---:|---:|---:|---:|",
        f"| DIVP seed (Vissim) | {SEED_BASELINE} | {SEED_SCT} | {SEED_REDUCTION:.0%} | "
        "not reported |",
    ]
    short, undecided = [], []
    for v in c.variants:
        base, sct = pair(summaries, v)
        red = reduction(base.incidents, sct.incidents)
        cost = sct.mean_travel_time - base.mean_travel_time
        rel = cost / base.mean_travel_time if base.mean_travel_time else math.nan
        lines.append(
            f"| hiyari, {v} | {base.incidents} | {sct.incidents} | "
            f"{'n/a' if math.isnan(red) else f'{red:.0%}'} | {cost:+.1f} s ({rel:+.1%}) |"
        )
        if math.isnan(red):
            undecided.append(v)
        elif red < SEED_REDUCTION:
            short.append((v, red))
    lines += [
        "",
        "![incidents per arm](incidents_bar.png)",
        "",
        "![minimum TTC and SCT per encounter](ttc_sct_hist.png)",
        "",
        "![incidents per hour](incidents_by_hour.png)",
        "",
        "Every incident is listed in `incidents.csv` (positions in SUMO network metres and "
        "speeds in m/s at the worst moment).",
        "",
        "## Closing note",
        "",
    ]
    lines += [f"- {f}" for v in c.variants for f in facts.get(v, [])]
    lines.append("")
    if undecided:
        lines += [
            f"No baseline incidents in {', '.join(undecided)} over {c.days:g} simulated days "
            f"(the seed counted {SEED_BASELINE} in 2 days): there is nothing to reduce, so no "
            "reduction is given. A longer run (--days) is needed to compare with the seed.",
            "",
        ]
    range_note = (
        "the sensitivity section shows the range the model gives."
        if with_sensitivity
        else "`--sensitivity HOURS` adds a section with the range the model gives."
    )
    if short:
        names = ", ".join(f"{v} ({r:.0%})" for v, r in short)
        lines += [
            f"The reduction falls short of the seed's {SEED_REDUCTION:.0%} for: {names}.",
            "",
            "Why: the SCT driver keeps a cushion of SCT_safe to every pedestrian it can "
            "foresee (constant velocity, or stepping in from the kerb when facing the road or "
            "a crossing). What remains are pedestrians who become a threat when the car is "
            "already close: SUMO's pedestrians walk round the junction corner and turn onto a "
            "crossing, or start to cross, within a second or two of an approaching car; the "
            "minimum SCT of these encounters (above) shows the driver had well under SCT_safe "
            "of warning, and braking is bounded to 0.4 g with a 3 m/s^3 jerk. The seed's "
            "Vissim drivers, pedestrian model and incident criterion are not published, so its "
            "baseline count and what can be removed differ: " + range_note,
            "",
            "What would change it: anticipating pedestrians who approach a crossing end "
            "(a dart-out zone that follows the walking direction, not only the heading within "
            "1.5 m), a larger SCT_safe (more delay), a pedestrian model that looks for cars "
            "before stepping in, and the incident thresholds (--ttc-threshold, "
            "--pet-threshold).",
        ]
    elif not undecided:
        lines.append(
            f"The reduction reaches the seed's {SEED_REDUCTION:.0%} in every variant, at the "
            "travel-time cost in the table."
        )
    return "\n".join(lines) + "\n"
