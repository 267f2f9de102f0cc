"""Catalogs: the directories a scenario's CatalogLocations name, and CatalogReference
resolution with ParameterAssignments (each entry is read in its own parameter scope)."""

from __future__ import annotations

from pathlib import Path

from lxml import etree

from hiyari.bridge.openscenario.xosc import document
from hiyari.bridge.openscenario.xosc.context import Ctx, Scope
from hiyari.errors import HiyariError


class Catalogs:
    """The catalog directories of one scenario file; a catalog file is read and validated when
    an entry of it is first referenced."""

    def __init__(self, directories: list[Path]) -> None:
        self.directories = directories
        self._files: dict[str, Path] | None = None  # catalog name -> the file declaring it
        self._unreadable: list[str] = []  # files whose catalog name could not be read
        self._loaded: dict[Path, etree._Element] = {}

    @staticmethod
    def from_locations(ctx: Ctx, locations: etree._Element | None) -> Catalogs:
        """The directories listed under ``locations`` (relative to the scenario file)."""
        dirs: list[Path] = []
        if locations is not None:
            for kind in locations:
                for d in kind.findall("Directory"):
                    p = Path(ctx.text(d, "path"))
                    dirs.append(p if p.is_absolute() else (ctx.file.parent / p).resolve())
        return Catalogs(dirs)

    def _index(self) -> dict[str, Path]:
        """Catalog name -> file, from each file's ``<Catalog name>`` only: a file is validated
        when an entry of it is referenced, so a bad file nobody uses blocks nothing."""
        if self._files is None:
            self._files = {}
            for d in dict.fromkeys(self.directories):
                if not d.is_dir():
                    continue
                for f in sorted(d.glob("*.xosc")):
                    name = _catalog_name(f)
                    if name is None:
                        self._unreadable.append(f.name)
                    else:
                        self._files.setdefault(name, f)
        return self._files

    def _catalog(self, file: Path) -> etree._Element:
        if file not in self._loaded:
            cat = document.load(file, "catalog file").find("Catalog")
            if cat is None:
                raise HiyariError(f"{file}: catalog file holds no <Catalog>")
            self._loaded[file] = cat
        return self._loaded[file]

    def resolve(self, ctx: Ctx, ref: etree._Element) -> tuple[etree._Element, Ctx]:
        """The catalog entry a CatalogReference names, and the context to read it in: the
        catalog file, a scope of the entry's own parameters with the reference's
        ParameterAssignments (evaluated where the reference stands)."""
        cat_name, entry_name = ctx.text(ref, "catalogName"), ctx.text(ref, "entryName")
        found = self._index().get(cat_name)
        if found is None:
            missing = [str(d) for d in self.directories if not d.is_dir()]
            hint = f"; missing directories: {', '.join(missing)}" if missing else ""
            if self._unreadable:
                hint += f"; not readable as catalogs: {', '.join(self._unreadable)}"
            raise HiyariError(
                f"{ctx.where(ref)}: catalog {cat_name!r} not found in the scenario's catalog "
                f"locations ({', '.join(str(d) for d in self.directories) or 'none'}{hint})"
            )
        file = found
        cat = self._catalog(file)
        entry = next((e for e in cat if e.get("name") == entry_name), None)
        if entry is None:
            raise HiyariError(
                f"{ctx.where(ref)}: catalog {cat_name!r} ({file}) has no entry {entry_name!r}"
            )
        assigned = {}
        pa = ref.find("ParameterAssignments")
        for a in [] if pa is None else pa.findall("ParameterAssignment"):
            assigned[ctx.text(a, "parameterRef")] = ctx.text(a, "value")
        entry_ctx = Ctx(file, Scope(), self).enter(entry, assigned)
        return entry, entry_ctx


def _catalog_name(file: Path) -> str | None:
    """The name of the ``<Catalog>`` in ``file`` (None: no catalog, or not well-formed before
    it), read without loading the rest of the file."""
    try:
        for _, el in etree.iterparse(str(file), events=("start",)):
            if el.tag == "Catalog":
                return el.get("name", "")
            if el.tag not in ("OpenSCENARIO", "FileHeader", "License", "Properties", "Property"):
                return None
    except etree.XMLSyntaxError:
        return None
    return None
