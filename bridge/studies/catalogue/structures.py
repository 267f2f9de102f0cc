"""The perception and vehicle-motion structures of the safety argument (JAMA §4.2-4.3) as a
report section: the pages `hiyari perception coverage | sweep | blindspots | grip` wrote into
one folder (``<name>.md`` + ``<name>.png``), in the order a reader needs them. Pages that are
missing are listed as not evaluated, so the report never implies coverage it does not have."""

from __future__ import annotations

import base64
import html
import os
from dataclasses import dataclass
from pathlib import Path

import mistune

#: (file stem, title, the command that writes it) in report order.
PAGES = (
    ("coverage", "Perception: factor x principle coverage", "hiyari perception coverage"),
    ("sweep", "Perception: representative factors swept", "hiyari perception sweep"),
    ("blindspots", "Blind spots caused by surrounding vehicles", "hiyari perception blindspots"),
    ("grip", "Vehicle-motion disturbances: grip use", "hiyari perception grip"),
)


@dataclass(frozen=True)
class StructurePage:
    """One written page: its title, Markdown text and figure (PNG bytes, or None)."""

    stem: str
    title: str
    command: str
    markdown: str | None
    png: bytes | None


def ensure_coverage(folder: Path) -> Path:
    """Write the factor x principle coverage page (camera, radar, LiDAR) into ``folder``
    unless it is there: it takes seconds and is always part of the argument."""
    if not (folder / "coverage.md").is_file():
        from hiyari.bridge.studies.perception.coverage_run import parse_sensors, write_coverage

        write_coverage(parse_sensors("camera,radar,lidar"), folder)
    return folder


def read_pages(folder: Path | None) -> list[StructurePage]:
    """The four pages from ``folder`` (missing ones with ``markdown=None``)."""
    out = []
    for stem, title, command in PAGES:
        md = png = None
        if folder is not None and (folder / f"{stem}.md").is_file():
            md = (folder / f"{stem}.md").read_text(encoding="utf-8")
            fig = folder / f"{stem}.png"
            png = fig.read_bytes() if fig.is_file() else None
        out.append(StructurePage(stem, title, command, md, png))
    return out


def _body(md: str) -> str:
    # each page starts with its own level-1 title; the report gives the section title
    lines = md.splitlines()
    return "\n".join(lines[1:] if lines and lines[0].startswith("# ") else lines)


def section_html(pages: list[StructurePage]) -> list[str]:
    """HTML parts of the section (figures embedded)."""
    render = mistune.create_markdown(plugins=["table"])
    parts = ["<h2>Perception and vehicle-motion disturbances</h2>"]
    for p in pages:
        parts.append(f"<h3 id='{p.stem}'>{html.escape(p.title)}</h3>")
        if p.markdown is None:
            parts.append(f"<p class='fail'>Not evaluated in this report (<code>{p.command}"
                         f"</code> not run into the structures folder).</p>")  # fmt: skip
            continue
        if p.png is not None:
            enc = base64.b64encode(p.png).decode()
            parts.append(f'<img alt="{p.stem}" src="data:image/png;base64,{enc}">')
        parts.append(str(render(_body(p.markdown))))
    return parts


def section_markdown(pages: list[StructurePage], folder: Path | None, out: Path) -> list[str]:
    """Markdown lines of the section; figures linked relative to ``out``."""
    lines = ["## Perception and vehicle-motion disturbances", ""]
    for p in pages:
        lines += [f"### {p.title}", ""]
        if p.markdown is None:
            lines += [f"Not evaluated in this report (`{p.command}` not run).", ""]
            continue
        if p.png is not None and folder is not None:
            rel = os.path.relpath(folder / f"{p.stem}.png", out)
            lines += [f"![{p.stem}]({rel})", ""]
        lines += [_body(p.markdown).replace("\n## ", "\n#### "), ""]
    return lines
