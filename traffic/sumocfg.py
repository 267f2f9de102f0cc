"""A user's own SUMO scenario: what a ``.sumocfg`` names (net, route and additional files) and
its time window, read so that hiyari can run its ego inside the scenario as SUMO would run it.

SUMO configurations name their inputs relative to the configuration's folder, as
comma-separated lists (``<route-files value="a.rou.xml,b.rou.xml"/>``); options are either
child elements of a section (``<input><net-file value="..."/></input>``) or of the root.
SUMO itself loads the configuration (``-c``), so the scenario's own processing options
(teleports, lateral resolution, pedestrian model, devices ...) stay as its author set them;
hiyari only adds its collision checks and the step length its ego stack runs at.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from lxml import etree

from hiyari.errors import HiyariError

#: Option names (with SUMO's short aliases) read from a configuration.
_KEYS = {
    "net-file": "net", "n": "net", "route-files": "routes", "r": "routes",
    "additional-files": "additional", "a": "additional", "begin": "begin", "b": "begin",
    "end": "end", "e": "end", "step-length": "step_length", "seed": "seed",
}  # fmt: skip


@dataclass(frozen=True)
class SumoScenario:
    """What a ``.sumocfg`` runs. Paths are resolved against the configuration's folder;
    times in seconds (``end`` None: no end given); ``step_length`` None: SUMO's default."""

    config: Path
    net: Path
    routes: tuple[Path, ...] = ()
    additional: tuple[Path, ...] = ()
    begin: float = 0.0
    end: float | None = None
    step_length: float | None = None
    seed: int | None = None


def _options(root: etree._Element) -> dict[str, str]:
    """Option name -> value text of every ``<name value="..."/>`` in the file."""
    found: dict[str, str] = {}
    for el in root.iter():
        if not isinstance(el.tag, str):
            continue  # comments
        key = _KEYS.get(etree.QName(el).localname)
        if key is not None and el.get("value") is not None:
            found[key] = el.get("value", "")
    return found


def _time(path: Path, name: str, text: str) -> float:
    """A SUMO time value (seconds, or ``h:m:s``)."""
    try:
        parts = [float(p) for p in text.strip().split(":")]
    except ValueError:
        parts = []
    if not 1 <= len(parts) <= 4:
        raise HiyariError(f"{path}: {name} {text!r} is not a time in seconds")
    value = sum(p * f for p, f in zip(reversed(parts), (1, 60, 3600, 86400), strict=False))
    if not math.isfinite(value):
        raise HiyariError(f"{path}: {name} {text!r} is not a time in seconds")
    return value


def _files(path: Path, name: str, text: str) -> tuple[Path, ...]:
    """The comma- (or space-) separated files of an option, each of which must exist."""
    out = []
    for part in text.replace(",", " ").split():
        file = Path(part) if Path(part).is_absolute() else path.parent / part
        shown = part if len(part) <= 80 else part[:77] + "..."
        try:
            found = file.is_file()
        except OSError as exc:  # e.g. a name longer than the file system allows
            raise HiyariError(f"{path}: {name} names {shown}: {exc.strerror}") from None
        if not found:
            raise HiyariError(f"{path}: {name} names {shown}, which does not exist")
        out.append(file)
    return tuple(out)


def read_sumocfg(path: str | Path) -> SumoScenario:
    """Read a SUMO configuration; HiyariError (one line naming the file) when it is missing,
    not a SUMO configuration, names no net, names a file that does not exist, or gives a time
    window or step length that cannot run."""
    path = Path(path)
    if not path.is_file():
        raise HiyariError(f"{path}: SUMO configuration not found")
    try:
        root = etree.parse(str(path), etree.XMLParser(huge_tree=True)).getroot()
    except etree.XMLSyntaxError as exc:
        raise HiyariError(f"{path}: SUMO configuration is not well-formed XML: {exc.msg}") from None
    if root.tag not in ("configuration", "sumoConfiguration"):
        raise HiyariError(f"{path}: not a SUMO configuration (root element <{root.tag}>)")
    opts = _options(root)
    if "net" not in opts:
        raise HiyariError(f"{path}: the configuration names no net-file")
    (net,) = _files(path, "net-file", opts["net"])[:1] or (None,)
    if net is None:
        raise HiyariError(f"{path}: the configuration names no net-file")
    begin = _time(path, "begin", opts["begin"]) if "begin" in opts else 0.0
    end = _time(path, "end", opts["end"]) if "end" in opts else None
    if end is not None and end < 0:  # SUMO's -1: no end
        end = None
    if end is not None and end <= begin:
        raise HiyariError(f"{path}: end {end:g} s is not after begin {begin:g} s")
    step = _time(path, "step-length", opts["step_length"]) if "step_length" in opts else None
    if step is not None and not step > 0:
        raise HiyariError(f"{path}: step-length must be positive, got {opts['step_length']!r}")
    seed = None
    if "seed" in opts:
        try:
            seed = int(opts["seed"])
        except ValueError:
            raise HiyariError(f"{path}: seed {opts['seed']!r} is not an integer") from None
    return SumoScenario(
        path,
        net,
        _files(path, "route-files", opts.get("routes", "")),
        _files(path, "additional-files", opts.get("additional", "")),
        begin,
        end,
        step,
        seed,
    )
