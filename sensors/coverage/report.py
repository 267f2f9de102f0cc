"""Coverage as text (Markdown): principles x disturbances per sensor (the figure is drawn by
bridge.studies.report.perception.coverage)."""

from __future__ import annotations

from hiyari.sensors.coverage.coverage import MergedRow, PrincipleCoverage


def coverage_markdown(
    per_sensor: dict[str, list[PrincipleCoverage]], merged: list[MergedRow]
) -> str:
    """Markdown: one table per sensor (principle, factors, covered by / why not), then the
    merged list."""
    lines = ["# JAMA perception-disturbance principle coverage", ""]
    for sensor, cov in per_sensor.items():
        n = sum(c.covered for c in cov)
        lines += [
            f"## {sensor}: {n} of {len(cov)} principles exercised",
            "",
            "| principle | name | factor rows | exercised by (range) | not simulable because |",
            "|---|---|---:|---|---|",
        ]
        for c in cov:
            lines.append(
                f"| {c.principle} | {c.name} | {c.factors} | {'; '.join(c.ranges) or '-'} "
                f"| {'; '.join(c.reasons) or '-'} |"
            )
        lines.append("")
    lines += [
        "## Merged list (multi-sensor system, JAMA 4.2.1.5)",
        "",
        "| disturbance | range | " + " | ".join(per_sensor) + " |",
        "|---|---|" + "---|" * len(per_sensor),
    ]
    for m in merged:
        cells = [", ".join(m.principles.get(s, ())) or "-" for s in per_sensor]
        lines.append(f"| {m.disturbance} | {m.range} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"
