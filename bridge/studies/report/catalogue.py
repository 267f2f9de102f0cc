"""The safety-argument report of a catalogue run: a self-contained HTML page (figures
embedded), the same in Markdown with PNG files, from the cells' verdicts and the results rows.

Sections: the overall verdict (PASS only when every run passed; partial when ``--cells`` ran
a subset), how runs are judged (the pass rule with its impact tolerance), summary counts of
this report's runs and of the whole catalogue, the catalogue matrix (green: every run passed;
red: a failure), coverage statement (evaluated / not applicable / not supported, with the
reason for every excluded position and lane count and a key to the reasons), failures with
their parameters in users' units, cause, replay page and recording, per-combination
datasheets, the perception and vehicle-motion structures (JAMA §4.2-4.3, from the ``hiyari
perception`` pages), and the run configuration for tracing and reproduction (date, commit,
versions, seeds, ranges).
"""

from __future__ import annotations

import base64
import html
import io
from collections import Counter, defaultdict
from dataclasses import fields
from pathlib import Path

from matplotlib.figure import Figure

from hiyari.atomic import atomic_path, write_text_atomic
from hiyari.bridge.studies.catalogue.evaluation.campaign import supported
from hiyari.bridge.studies.catalogue.evaluation.expectation import IMPACT_TOLERANCE
from hiyari.bridge.studies.catalogue.evaluation.provenance import format_params
from hiyari.bridge.studies.catalogue.space.obstruction import Cell
from hiyari.bridge.studies.catalogue.space.parameters import Ranges
from hiyari.bridge.studies.catalogue.structures import read_pages, section_html, section_markdown
from hiyari.bridge.studies.report.catalogue_plots import datasheet_figure, matrix_figure

STYLE = """body{font-family:system-ui,sans-serif;margin:2em;max-width:1500px;color:#222}
table{border-collapse:collapse;font-size:13px;margin:.5em 0}td,th{border:1px solid #ccc;
padding:3px 7px;text-align:left;vertical-align:top}th{background:#f3f3f3}
img{max-width:100%;border:1px solid #ddd}.fail{color:#c62828;font-weight:600}
.pass{color:#2e7d32;font-weight:600}code{background:#f5f5f5;padding:0 3px}
.verdict{display:inline-block;font-size:28px;font-weight:700;color:#fff;padding:6px 18px;
border-radius:4px}.verdict.pass{background:#2e7d32;color:#fff}
.verdict.fail{background:#c62828;color:#fff}"""

#: What each not-applicable status of a cell means (the key under the coverage table).
STATUS_TEXT = {
    "no lane": "there is no lane at that position on this road (e.g. right of the ego on a "
    "two-lane road)",
    "undefined": "the motion is not defined from that position: a vehicle already in the "
    "ego's lane cannot cut in, and one with no lane beside it cannot cut out",
    "non-obstructing": "over the logical parameter ranges the vehicle's motion never enters "
    "the ego's path",
    "shielded": "the lead vehicle shields the ego; the §4.1.3 chain combinations cover it",
}

#: The same, in a few words (the summary table's labels).
SHORT_STATUS = {
    "no lane": "no lane at that position",
    "undefined": "the motion is not defined from that position",
    "non-obstructing": "never enters the ego's path",
    "shielded": "shielded by the lead; the §4.1.3 chains cover it",
}

PASS_RULE = (
    "Each concrete run is judged against the competent and careful (C&C) driver in the same "
    "case: the closed-form C&C model for the Annex G cut-in, cut-out and deceleration, the C&C "
    "reference driver in the same closed loop otherwise. <b>Preventable</b>: the C&C driver "
    "does not collide. A run <b>passes</b> when it has no collision where the case is "
    "Preventable; where the C&C driver collides too, when it has no collision or a relative "
    f"impact speed at most the C&amp;C driver's + {IMPACT_TOLERANCE:g} m/s. The report "
    "passes when every run passes."
)


def _png(fig: Figure, path: Path) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    data = buf.getvalue()
    with atomic_path(path) as tmp:
        Path(tmp).write_bytes(data)
    return data


def _params(text: str) -> dict[str, float]:
    return {k: float(v) for k, v in (kv.split("=") for kv in text.split(";") if kv)}


def cell_stats(rows: list[dict]) -> dict[str, tuple[int, int]]:
    """cell key -> (passed, runs)."""
    out: dict[str, list[int]] = defaultdict(lambda: [0, 0])
    for r in rows:
        out[r["cell"]][0] += r["passed"] == "True"
        out[r["cell"]][1] += 1
    return {k: (v[0], v[1]) for k, v in out.items()}


def coverage(cells: list[Cell]) -> dict[str, int]:
    """Counts of catalogue cells by coverage class (runnable, not applicable by status, not
    supported)."""
    n = Counter()
    for c in cells:
        if supported(c):
            n["applicable, run by hiyari"] += 1
        elif c.valid:
            n["applicable, not yet runnable (intersection runs)"] += 1
        else:
            n[f"not applicable: {c.status} ({SHORT_STATUS.get(c.status, c.status)})"] += 1
    return dict(n)


def verdict(rows: list[dict]) -> str:
    """The overall verdict: PASS when there are runs and every one passed, else FAIL."""
    return "PASS" if rows and all(r["passed"] == "True" for r in rows) else "FAIL"


def _summary(cells: list[Cell], rows: list[dict]) -> tuple[list[list[str]], str]:
    """The summary table and the one-line explanation under the verdict."""
    stats = cell_stats(rows)
    runnable = sum(supported(c) for c in cells)
    n_pass = sum(r["passed"] == "True" for r in rows)
    prevent = [r for r in rows if r["preventable"] == "True"]
    crashed = sum(r["passed"] == "crashed" for r in rows)
    untested = sum(r["passed"] == "not tested" for r in rows)
    prevent_fail = sum(r["passed"] not in ("True", "crashed", "not tested") for r in prevent)
    worse = len(rows) - n_pass - prevent_fail - crashed - untested
    tested = [r for r in rows if r["passed"] not in ("crashed", "not tested")]
    collisions = sum(r["collision"] == "True" for r in tested)
    near = sum(int(r.get("near_misses") or 0) for r in tested)
    false = sum(int(r.get("false_activations") or 0) for r in rows)
    partial = len(stats) < runnable
    scope = (f"{len(stats)} of the {runnable} applicable cells run (partial: a --cells "
             "selection)" if partial else f"all {runnable} applicable cells run")  # fmt: skip
    if not rows:
        line = "no runs"
    elif n_pass == len(rows):
        line = f"all {len(rows)} runs passed; {scope}"
    else:
        line = (f"{len(rows) - n_pass - untested} of {len(rows)} runs failed ({prevent_fail} "
                f"collisions where the C&C driver avoids one, {worse} impacts harder than the "
                f"C&C driver's + {IMPACT_TOLERANCE:g} m/s, {crashed} crashed); {untested} not "
                f"tested (never passed); {scope}")  # fmt: skip
    table = [
        ["verdict", verdict(rows)],
        ["concrete runs", f"{len(rows)} in {len(stats)} cells"],
        ["passed", f"{n_pass} ({100 * n_pass / max(len(rows), 1):.1f} %)"],
        ["failed: collision where the C&C driver avoids one", str(prevent_fail)],
        [f"failed: impact > C&C driver's + {IMPACT_TOLERANCE:g} m/s", str(worse)],
        ["Preventable runs (C&C avoids) passed", f"{len(prevent) - prevent_fail} / {len(prevent)}"],
        [
            "not tested (braked hard, stopped or left the lane before the disturbance)",
            str(untested),
        ],
        ["tested runs: collisions / near misses", f"{collisions} / {near}"],
        ["false activations (AEB or hard braking, no ground-truth conflict)", str(false)],
        ["crashed runs (worker process died; the same command again retries them)", str(crashed)],
        ["catalogue cells (position x lane count)", str(len(cells))],
    ]
    for key, count in sorted(coverage(cells).items()):
        table.append([key, str(count)])
        if key == "applicable, run by hiyari":
            table.append(["  of which run in this report", str(len(stats))])
    return table, line


def _table(head: list[str], body: list[list[str]]) -> str:
    th = "".join(f"<th>{html.escape(h)}</th>" for h in head)
    trs = "".join("<tr>" + "".join(f"<td>{c}</td>" for c in row) + "</tr>" for row in body)
    return f"<table><tr>{th}</tr>{trs}</table>"


def _md_table(head: list[str], body: list[list[str]]) -> str:
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    lines += ["| " + " | ".join(str(c).replace("|", "/") for c in row) + " |" for row in body]
    return "\n".join(lines)


def _where(cells: list[Cell]) -> str:
    """ "front (2, 3 lanes), rear (2 lanes)": positions with their lane counts."""
    lanes: dict[str, list[str]] = defaultdict(list)
    for c in cells:
        lanes[c.position.value].append(str(c.lanes))
    return ", ".join(f"{p} ({', '.join(n)} lanes)" for p, n in lanes.items())


def _coverage_rows(cells: list[Cell]) -> list[list[str]]:
    by_combo: dict[str, list[Cell]] = defaultdict(list)
    for c in cells:
        by_combo[c.combination.key].append(c)
    rows = []
    for key, group in by_combo.items():
        kept = _where([c for c in group if c.valid]) or "none"
        reasons: dict[str, list[Cell]] = defaultdict(list)
        for c in group:
            if not c.valid:
                reasons[c.reason].append(c)
        why = "; ".join(f"{reason}: {_where(cs)}" for reason, cs in reasons.items())
        rows.append([key, group[0].combination.title, kept, why])
    return rows


def _failures(rows: list[dict], out: Path) -> list[list[str]]:
    """One row per failed run: id, cell, parameters in users' units, Preventable, cause and
    links to its replay page and recording (when written)."""
    body = []
    for r in rows:
        if r["passed"] == "True":
            continue
        links = []
        for suffix, label in ((".html", "replay"), (".mcap", "recording (.mcap)")):
            if (out / "recordings" / f"{r['run_id']}{suffix}").is_file():
                links.append(f'<a href="recordings/{r["run_id"]}{suffix}">{label}</a>')
        body.append([r["run_id"], r["cell"], html.escape(format_params(r["_params"])),
                     "yes" if r["preventable"] == "True" else "no",
                     html.escape(r["cause"]), " · ".join(links) or "–"])  # fmt: skip
    return body


def _status_key(cells: list[Cell]) -> list[list[str]]:
    present = sorted({c.status for c in cells if not c.valid})
    return [[f"not applicable: {s}", STATUS_TEXT.get(s, s)] for s in present]


def write_report(out: Path, cells: list[Cell], rows: list[dict], config: dict,
                 ranges: Ranges | None = None, structures: Path | None = None) -> Path:  # fmt: skip
    """Write ``out/report.html``, ``out/report.md`` and the PNGs; return the HTML path.
    ``structures``: the folder the ``hiyari perception`` pages were written to (their section
    lists the missing ones as not evaluated)."""
    ranges = ranges or Ranges()
    limits = {
        f.name: getattr(ranges, f.name)
        for f in fields(ranges)
        if isinstance(getattr(ranges, f.name), tuple)
    }
    out.mkdir(parents=True, exist_ok=True)
    for r in rows:
        r["_params"] = _params(r["params"])
    stats = cell_stats(rows)
    figs: list[tuple[str, bytes]] = [
        ("matrix.png", _png(matrix_figure(cells, stats), out / "matrix.png"))
    ]
    by_combo: dict[str, dict[str, list[dict]]] = defaultdict(lambda: defaultdict(list))
    titles = {c.combination.key: c.combination.title for c in cells}
    for r in rows:
        by_combo[r["combination"]][f"{r['position']}, {r['lanes']} lanes"].append(r)
    sheets = []
    for key in sorted(by_combo):
        name = f"datasheets/{key}.png"
        fig = datasheet_figure(f"{key}: {titles[key]}", by_combo[key], limits)
        sheets.append((key, name, _png(fig, out / name)))
    summary, line = _summary(cells, rows)
    result = verdict(rows)
    fail_head = ["run", "cell", "parameters", "Preventable", "cause", "replay and recording"]
    fails = _failures(rows, out)
    cov_head = ["No.", "combination", "evaluated positions", "excluded, and why"]
    cov_rows = _coverage_rows(cells)
    key = _status_key(cells)
    conf_rows = [[html.escape(k), html.escape(str(v))] for k, v in config.items()]
    b64 = {name: base64.b64encode(data).decode() for name, data in figs}
    legend = ("Green: every run of the cell passed; red: at least one failed; white: "
              "applicable, not run in this report; grey –: not applicable.")  # fmt: skip
    body = [
        "<h1>Safety argument: JAMA traffic-disturbance catalogue</h1>",
        f"<p><span id='verdict' class='verdict {result.lower()}'>{result}</span> "
        f"{html.escape(line)}</p>",
        f"<p id='rule'>{PASS_RULE}</p>",
        "<h2>Summary</h2>",
        _table(["", ""], [[html.escape(k), v] for k, v in summary]),
        "<h2>Catalogue matrix</h2>",
        f"<p>{legend}</p>",
        f'<img id="matrix" alt="catalogue matrix" src="data:image/png;base64,{b64["matrix.png"]}">',
        "<h2>Coverage</h2>",
        "<p>Every combination is expanded over the surrounding-vehicle positions and lane counts; "
        "a position is kept when its motion can obstruct the ego's path (geometric test over the "
        "logical parameter ranges).</p>",
        _table(cov_head, [[html.escape(c) for c in r] for r in cov_rows]),
        "<p>Key to the excluded cells:</p>",
        f"<div id='status-key'>{_table(['', 'meaning'], key)}</div>",
        f"<h2>Failures ({len(fails)})</h2>",
        _table(fail_head, fails) if fails else "<p class='pass'>No failures.</p>",
        "<h2>Datasheets</h2>",
    ]
    for combo, _, data in sheets:
        enc = base64.b64encode(data).decode()
        body.append(f'<h3>{combo}</h3><img alt="{combo}" src="data:image/png;base64,{enc}">')
    pages = read_pages(structures)
    body += section_html(pages)
    body += ["<h2 id='configuration'>Run configuration</h2>", _table(["", ""], conf_rows)]
    page = (f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>hiyari safety argument"
            f"</title><style>{STYLE}</style></head><body>{''.join(body)}</body></html>")  # fmt: skip
    write_text_atomic(out / "report.html", page)
    rule = html.unescape(PASS_RULE.replace("<b>", "**").replace("</b>", "**"))
    md_fails = [[*f[:2], html.unescape(f[2]), f[3], html.unescape(f[4]),
                 " / ".join(f"recordings/{f[0]}{x}" for x in (".html", ".mcap")
                            if (out / "recordings" / f"{f[0]}{x}").is_file()) or "–"]
                for f in fails]  # fmt: skip
    md = [
        "# Safety argument: JAMA traffic-disturbance catalogue", "",
        f"**{result}**: {line}", "", rule, "",
        "## Summary", "", _md_table(["", ""], summary), "",
        "## Catalogue matrix", "", legend, "", "![matrix](matrix.png)", "",
        "## Coverage", "", _md_table(cov_head, cov_rows), "",
        "Key to the excluded cells:", "", _md_table(["", "meaning"], key), "",
        f"## Failures ({len(fails)})", "",
        _md_table(fail_head, md_fails) if fails else "No failures.", "",
        "## Datasheets", "", *[f"![{k}]({n})" for k, n, _ in sheets], "",
        *section_markdown(pages, structures, out),
        "## Run configuration", "", _md_table(["", ""], [[k, str(v)] for k, v in config.items()]),
    ]  # fmt: skip
    write_text_atomic(out / "report.md", "\n".join(md) + "\n")
    return out / "report.html"
