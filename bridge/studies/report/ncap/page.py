"""The ``hiyari ncap`` datasheet page: the protocol scores, the points table, a colour grid per
scenario (PNG files beside the page), every point that lost points with its recording and
replay, the runs not tested and why, the scoring rules with their sources, the configuration.
Also ``score.json`` with the totals."""

from __future__ import annotations

import html
import json
from pathlib import Path

from hiyari.atomic import write_text_atomic
from hiyari.bridge.studies.ncap import scoring, scoring2026
from hiyari.bridge.studies.ncap.protocols import CA2026
from hiyari.bridge.studies.ncap.study import NcapResult, activation_counts
from hiyari.bridge.studies.report.ncap.grids import write_grid

STYLE = """body{font-family:system-ui,sans-serif;margin:2em;max-width:1400px;color:#222}
table{border-collapse:collapse;font-size:13px;margin:.5em 0}td,th{border:1px solid #ccc;
padding:3px 7px;text-align:left;vertical-align:top}th{background:#f3f3f3}
img{max-width:100%;border:1px solid #ddd;margin:.3em 0}.assumed{color:#b26a00}"""


def _table(head: list[str], body: list[list[str]]) -> str:
    th = "".join(f"<th>{html.escape(h)}</th>" for h in head)
    trs = "".join("<tr>" + "".join(f"<td>{c}</td>" for c in r) + "</tr>" for r in body)
    return f"<table><tr>{th}</tr>{trs}</table>"


def _link(out: Path, rel: str) -> str:
    return f'<a href="{rel}">{html.escape(Path(rel).name)}</a>' if (out / rel).is_file() else "–"


def write_report(out: Path, result: NcapResult, config: dict) -> Path:
    """Write ``out/report.html``, ``out/grids/<test>.png`` and ``out/score.json``; return the
    page's path."""
    e = html.escape
    by_test = {t.key: t for t in result.tests}
    is_2026 = any(t.protocol == CA2026 for t in result.tests)
    if is_2026:
        docs = (f"<h1>Euro NCAP 2026 Crash Avoidance datasheet (Standard Range)</h1><p>Test "
                f"protocol: {e(scoring2026.CAFC_TEST)}. Assessment: "
                f"{e(scoring2026.CAFC_ASSESSMENT)}. ")  # fmt: skip
    else:
        docs = (f"<h1>Euro NCAP 2023 AEB datasheet</h1><p>Test protocols: "
                f"{e(scoring.C2C_TEST)}; {e(scoring.VRU_TEST)}. Assessment: "
                f"{e(scoring.C2C_ASSESSMENT)}; {e(scoring.VRU_ASSESSMENT)}. ")  # fmt: skip
    parts = [docs + '<span class="assumed">Values marked assumed were not found in the '
             "assessment protocols (see the rules below).</span></p>"]  # fmt: skip
    parts.append("<h2 id=scores>Scores</h2>" + _table(
        ["protocol", "points", "of", "%"],
        [[p.protocol.upper(), f"{p.points:.2f}", f"{p.max_points:.2f}", f"{p.percent:.1f}"]
         for p in result.protocols],
    ))  # fmt: skip
    body = []
    for p in result.protocols:
        for s in p.scenarios:
            t = by_test[s.scenario]
            of = f"{s.max_points:.2f}" + (" (assumed)" if t.points_assumed else "")
            body.append([e(s.scenario), e(t.title), e("/".join(t.lightings)), str(s.tested),
                         str(s.not_tested), f"{s.points:.3f}", of])  # fmt: skip
    near, false = activation_counts(result.rows.values())
    parts.append(f"<p>{near} near misses and {false} false activations (AEB stage or braking "
                 "beyond the ACC's comfort limit with no ground-truth conflict) over the runs; "
                 "runs not tested score nothing and are listed below.</p>")  # fmt: skip
    parts.append("<h2 id=points>Points per scenario</h2>" + _table(
        ["scenario", "test", "lighting", "points tested", "not tested", "points",
         "of"], body))  # fmt: skip
    parts.append("<h2 id=grids>Grids</h2>")
    for t in result.tests:
        pids = [pid for pid, r in result.rows.items() if r["test"] == t.key]
        if not pids:
            continue
        png = out / "grids" / f"{t.key}.png"
        write_grid(png, t, [result.rows[p] for p in pids], [result.points[p] for p in pids])
        parts.append(f'<h3>{e(t.key)}: {e(t.title)}</h3><img class=grid alt="{e(t.key)}" '
                     f'src="grids/{e(t.key)}.png">')  # fmt: skip
    lost = [pid for pid, s in result.points.items()
            if s.colour is not None and s.colour is not scoring.Colour.GREEN]  # fmt: skip
    rows = []
    for pid in lost:
        r, s = result.rows[pid], result.points[pid]
        rows.append([e(pid), e(r["lighting"]), e(str(r["row"])), e(str(r["col"])),
                     e(s.colour.value if s.colour else ""), e(str(r["impact_speed_kmh"])),
                     e(str(r["relative_impact_speed_kmh"])), e(str(r["reference_kmh"])),
                     e(str(r["warning_ttc_s"])), _link(out, f"recordings/{pid}.mcap"),
                     _link(out, f"replays/{pid}.html")])  # fmt: skip
    parts.append(f"<h2 id=lost>Points that lost points ({len(lost)})</h2>" + _table(
        ["point", "lighting", "row", "col", "colour", "impact km/h", "relative impact km/h",
         "reference km/h", "TTC at warning s", "recording", "replay"], rows))  # fmt: skip
    nt = [[e(pid), e(s.not_tested)] for pid, s in result.points.items() if s.colour is None]
    parts.append(f"<h2 id=not-tested>Runs not tested ({len(nt)})</h2>"
                 + (_table(["point", "why"], nt) if nt else "<p>none</p>"))  # fmt: skip
    parts.append("<h2 id=rules>Scoring rules</h2>" + _table(
        ["rule", "value", "source", "assumed"],
        [[e(r.name), e(r.shown or _value(r.value)), e(r.source),
          "assumed" if r.assumed else "found"]
         for r in (scoring2026.RULES if is_2026 else ()) + scoring.RULES]))  # fmt: skip
    parts.append("<h2 id=config>Configuration</h2>" + _table(
        ["", ""], [[e(k), e(str(v))] for k, v in config.items()]))  # fmt: skip
    page = out / "report.html"
    doc = (f"<!doctype html><html><head><meta charset=utf-8><title>Euro NCAP AEB datasheet"
           f"</title><style>{STYLE}</style></head><body>{''.join(parts)}</body></html>")  # fmt: skip
    write_text_atomic(page, doc)
    write_text_atomic(out / "score.json", json.dumps(_score_doc(result), indent=1) + "\n")
    return page


def _value(v: object) -> str:
    if isinstance(v, dict):
        return ", ".join(f"{k.value if hasattr(k, 'value') else k} {x}" for k, x in v.items())
    if isinstance(v, tuple):
        return ", ".join(f"{x[0].value} >= {x[1]}" if isinstance(x, tuple) else str(x) for x in v)
    return str(v)


def _score_doc(result: NcapResult) -> dict:
    return {
        p.protocol: {
            "points": round(p.points, 4),
            "max_points": p.max_points,
            "percent": round(p.percent, 2),
            "scenarios": {
                s.scenario: {
                    "points": round(s.points, 4),
                    "max_points": s.max_points,
                    "tested": s.tested,
                    "not_tested": s.not_tested,
                }
                for s in p.scenarios
            },  # fmt: skip
        }
        for p in result.protocols
    }
