"""The safety-argument report of a catalogue run: a self-contained HTML page (figures
embedded), the same in Markdown with PNG files, from the cells' verdicts and the results rows.

Sections: summary, catalogue matrix, coverage statement (evaluated / not applicable / not
supported, with the reason for every excluded position and lane count), failures with their
cause and recording, per-combination datasheets, the perception and vehicle-motion structures
(JAMA §4.2-4.3, from the ``hiyari perception`` pages), run configuration for reproduction.
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
from hiyari.bridge.studies.catalogue.space.obstruction import Cell
from hiyari.bridge.studies.catalogue.space.parameters import Ranges
from hiyari.bridge.studies.catalogue.structures import read_pages, section_html, section_markdown
from hiyari.bridge.studies.report.catalogue_plots import datasheet_figure, matrix_figure

STYLE = """body{font-family:system-ui,sans-serif;margin:2em;max-width:1500px;color:#222}
table{border-collapse:collapse;font-size:13px;margin:.5em 0}td,th{border:1px solid #ccc;
padding:3px 7px;text-align:left;vertical-align:top}th{background:#f3f3f3}
img{max-width:100%;border:1px solid #ddd}.fail{color:#c62828;font-weight:600}
.pass{color:#2e7d32;font-weight:600}code{background:#f5f5f5;padding:0 3px}"""


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
    """Counts of cells by coverage class (evaluated, not applicable by status, not supported)."""
    n = Counter()
    for c in cells:
        if supported(c):
            n["evaluated"] += 1
        elif c.valid:
            n["not supported (intersection runs)"] += 1
        else:
            n[f"not applicable: {c.status}"] += 1
    return dict(n)


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
    body = []
    for r in rows:
        if r["passed"] == "True":
            continue
        rec = out / "recordings" / f"{r['run_id']}.mcap"
        link = (
            f'<a href="recordings/{r["run_id"]}.mcap">{r["run_id"]}.mcap</a>'
            if rec.is_file()
            else "–"
        )
        body.append([r["run_id"], r["cell"], html.escape(r["params"]),
                     "yes" if r["preventable"] == "True" else "no",
                     html.escape(r["cause"]), link])  # fmt: skip
    return body


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
    n_pass = sum(r["passed"] == "True" for r in rows)
    prevent = [r for r in rows if r["preventable"] == "True"]
    prevent_pass = sum(r["passed"] == "True" for r in prevent)
    cov = coverage(cells)
    summary = [
        ["concrete runs", str(len(rows))],
        ["passed", f"{n_pass} ({100 * n_pass / max(len(rows), 1):.1f} %)"],
        ["Preventable runs (C&C avoids) passed", f"{prevent_pass} / {len(prevent)}"],
        [
            "crashed runs (worker process died; the same command again retries them)",
            str(sum(r["passed"] == "crashed" for r in rows)),
        ],  # fmt: skip
        ["cells (position x lane count)", str(len(cells))],
        *[[k, str(v)] for k, v in sorted(cov.items())],
    ]
    fail_head = ["run", "cell", "parameters (SI)", "Preventable", "cause", "recording"]
    fails = _failures(rows, out)
    cov_head = ["No.", "combination", "evaluated positions", "excluded, and why"]
    cov_rows = _coverage_rows(cells)
    conf_rows = [[k, html.escape(str(v))] for k, v in config.items()]
    b64 = {name: base64.b64encode(data).decode() for name, data in figs}
    body = [
        "<h1>Safety argument: JAMA traffic-disturbance catalogue</h1>",
        "<p>Each concrete run is judged against the competent and careful (C&amp;C) driver: "
        "pass = no collision where the C&amp;C driver avoids one (Preventable), and no harder "
        "impact than the C&amp;C driver's elsewhere.</p>",
        "<h2>Summary</h2>",
        _table(["", ""], summary),
        "<h2>Catalogue matrix</h2>",
        f'<img id="matrix" alt="catalogue matrix" src="data:image/png;base64,{b64["matrix.png"]}">',
        "<h2>Coverage</h2>",
        "<p>Every combination is expanded over the surrounding-vehicle positions and lane counts; "
        "a position is kept when its motion can obstruct the ego's path (geometric test over the "
        "logical parameter ranges).</p>",
        _table(cov_head, [[html.escape(c) for c in r] for r in cov_rows]),
        f"<h2>Failures ({len(fails)})</h2>",
        _table(fail_head, fails) if fails else "<p class='pass'>No failures.</p>",
        "<h2>Datasheets</h2>",
    ]
    for key, _, data in sheets:
        enc = base64.b64encode(data).decode()
        body.append(f'<h3>{key}</h3><img alt="{key}" src="data:image/png;base64,{enc}">')
    pages = read_pages(structures)
    body += section_html(pages)
    body += ["<h2>Run configuration</h2>", _table(["", ""], conf_rows)]
    page = (f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>hiyari safety argument"
            f"</title><style>{STYLE}</style></head><body>{''.join(body)}</body></html>")  # fmt: skip
    write_text_atomic(out / "report.html", page)
    md = [
        "# Safety argument: JAMA traffic-disturbance catalogue", "",
        _md_table(["", ""], summary), "", "## Catalogue matrix", "", "![matrix](matrix.png)", "",
        "## Coverage", "", _md_table(cov_head, cov_rows), "",
        f"## Failures ({len(fails)})", "",
        _md_table(fail_head, [[*f[:4], html.unescape(f[4]), f"recordings/{f[0]}.mcap"]
                              for f in fails]) if fails else "No failures.", "",
        "## Datasheets", "", *[f"![{k}]({n})" for k, n, _ in sheets], "",
        *section_markdown(pages, structures, out),
        "## Run configuration", "", _md_table(["", ""], [[k, str(v)] for k, v in config.items()]),
    ]  # fmt: skip
    write_text_atomic(out / "report.md", "\n".join(md) + "\n")
    return out / "report.html"
