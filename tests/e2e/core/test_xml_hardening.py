"""The OpenSCENARIO and OpenDRIVE readers refuse external entities (XXE) and entity-expansion
bombs: one line naming the file, exit 1, nothing read from outside the file, no blow-up.

Both are refused today by lxml's defaults (external entities are not resolved; libxml2 caps
the entity amplification); these tests keep it so if a parser option or the lxml version
changes."""

from __future__ import annotations

import resource
import time
from pathlib import Path

import pytest

from hiyari.bridge.cli.main import main
from hiyari.bridge.openscenario.xosc.document import load
from hiyari.errors import HiyariError
from hiyari.net.sumo.opendrive import check_opendrive

SECRET = "HIYARI-SECRET-7f3a"

# an entity the reader would have to fetch from the local disk
XXE = """<?xml version="1.0"?>
<!DOCTYPE {root} [ <!ENTITY xxe SYSTEM "file://{secret}"> ]>
<{root}><FileHeader revMajor="1" revMinor="3" date="2024-01-01T00:00:00"
 description="x" author="x"/><leak>&xxe;</leak></{root}>
"""

# "billion laughs": 60 characters x 20^7 = 76.8 GB once expanded, from a 1.6 kB file
_LEVELS = "abcdefgh"
BOMB = (
    '<?xml version="1.0"?>\n<!DOCTYPE {root} [\n'
    + f' <!ENTITY a "{"x" * 60}">\n'
    + "".join(
        f' <!ENTITY {name} "{f"&{prev};" * 20}">\n'
        for prev, name in zip(_LEVELS, _LEVELS[1:], strict=False)
    )
    + ']>\n<{root}><FileHeader revMajor="1" revMinor="3" date="2024-01-01T00:00:00"'
    + ' description="&h;" author="x"/></{root}>\n'
)

READERS = {
    # (root element, file suffix, the command that reads it)
    "openscenario": ("OpenSCENARIO", "xosc", ["run", "{file}", "-o", "{out}/run.mcap"]),
    "opendrive": ("OpenDRIVE", "xodr", ["net", "import", "{file}", "-o", "{out}/x.net.xml"]),
}

PARSE = {"openscenario": load, "opendrive": check_opendrive}


def _refused(tmp_path: Path, capsys, reader: str, text: str) -> str:
    """Run the command that reads the file; assert the one-line refusal; return it."""
    root, suffix, argv = READERS[reader]
    src = tmp_path / f"hostile.{suffix}"
    src.write_text(text.format(root=root, secret=tmp_path / "secret.txt"))
    out = tmp_path / "out"
    status = main([a.format(file=src, out=out) for a in argv])
    err = capsys.readouterr().err
    assert status == 1, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"hiyari: error: {src}"), err
    assert SECRET not in err
    # the reader again, its imports done: nothing expanded, the peak RSS grew by less than
    # 20 MB (ru_maxrss is in kB on Linux) and it took well under a second
    rss0 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    t0 = time.perf_counter()
    with pytest.raises(HiyariError, match=f"^{src}: not well-formed XML: "):
        PARSE[reader](src)
    assert time.perf_counter() - t0 < 0.5
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - rss0 < 20_000
    assert not out.exists() or not any(out.iterdir())
    return lines[0]


@pytest.mark.parametrize("reader", READERS)
def test_external_entity_refused(tmp_path, capsys, reader):
    (tmp_path / "secret.txt").write_text(SECRET)
    line = _refused(tmp_path, capsys, reader, XXE)
    assert "Entity 'xxe' not defined" in line


@pytest.mark.parametrize("reader", READERS)
def test_entity_expansion_bomb_refused(tmp_path, capsys, reader):
    line = _refused(tmp_path, capsys, reader, BOMB)
    assert "entity amplification" in line
