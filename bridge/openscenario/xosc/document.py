"""Load an OpenSCENARIO XML file and validate it against the ASAM OpenSCENARIO 1.3 schema.

Files declaring revision 1.0 - 1.3 are read. All are validated against the standard (not the
"strict") 1.3 schema shipped in ``schema/``: it keeps the artifacts deprecated since 1.0, so
older files validate wherever 1.3 is compatible with them, and a file that is not gets a one-line
error naming the file, the line and the schema's complaint. Known deviations other tools write
(``repairs``) are repaired in the parsed tree first, one warning line each.
"""

from __future__ import annotations

import logging
from functools import cache
from pathlib import Path

from lxml import etree

from hiyari.bridge.openscenario.xosc.repairs import repair
from hiyari.errors import HiyariError

_log = logging.getLogger(__name__)
#: Repairs already said, by file (resolved) and repair: a file is loaded several times by one
#: command (plan, constraints, read; as given and resolved), its repairs are said once.
_said: set[tuple[Path, str]] = set()

SCHEMA = Path(__file__).resolve().parent / "schema" / "OpenSCENARIO_1_3.xsd"
#: The OpenSCENARIO revisions this reader accepts (major, minor).
SUPPORTED = ((1, 0), (1, 1), (1, 2), (1, 3))


@cache
def _schema() -> etree.XMLSchema:
    return etree.XMLSchema(etree.parse(str(SCHEMA)))


def load(path: str | Path, what: str = "OpenSCENARIO file") -> etree._Element:
    """Parse, repair (``repairs``: one logging warning per repair, once per process) and
    validate ``path``; return its root element. HiyariError (one line) for a missing,
    malformed, schema-invalid or unsupported-revision file."""
    path = Path(path)
    if not path.is_file():
        raise HiyariError(f"{path}: {what} not found")
    try:
        tree = etree.parse(str(path), etree.XMLParser(remove_comments=True, huge_tree=True))
    except etree.XMLSyntaxError as exc:
        raise HiyariError(f"{path}: not well-formed XML: {exc.msg}") from None
    root = tree.getroot()
    if root.tag != "OpenSCENARIO":
        raise HiyariError(f"{path}: not an OpenSCENARIO file (root element <{root.tag}>)")
    for r in repair(root):
        key = (path.resolve(), r.message(""))
        if key not in _said:
            _said.add(key)
            _log.warning(r.message(path))
    header = root.find("FileHeader")
    if header is not None:
        try:
            rev = (int(header.get("revMajor", "1")), int(header.get("revMinor", "0")))
        except ValueError:
            rev = (-1, -1)
        if rev not in SUPPORTED:
            raise HiyariError(
                f"{path}:{header.sourceline}: OpenSCENARIO revision "
                f"{header.get('revMajor')}.{header.get('revMinor')} is not supported (1.0 - 1.3)"
            )
    schema = _schema()
    if not schema.validate(tree):
        err = schema.error_log[0]
        msg = err.message.replace("{http://www.w3.org/2001/XMLSchema}", "xsd:")
        raise HiyariError(f"{path}:{err.line}: not valid OpenSCENARIO 1.3: {msg}")
    return root
