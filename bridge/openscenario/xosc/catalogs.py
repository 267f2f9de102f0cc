"""Catalogs: the directories a scenario's CatalogLocations name, and CatalogReference
resolution with ParameterAssignments (each entry is read in its own parameter scope)."""

from __future__ import annotations

from pathlib import Path

from lxml import etree

from hiyari.bridge.openscenario.xosc import document
from hiyari.bridge.openscenario.xosc.context import Ctx, Scope
from hiyari.errors import HiyariError


class Catalogs:
    """The catalog directories of one scenario file; catalog files are loaded on first use."""

    def __init__(self, directories: list[Path]) -> None:
        self.directories = directories
        self._catalogs: dict[str, tuple[Path, etree._Element]] | None = None

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

    def _index(self) -> dict[str, tuple[Path, etree._Element]]:
        if self._catalogs is None:
            self._catalogs = {}
            for d in dict.fromkeys(self.directories):
                if not d.is_dir():
                    continue
                for f in sorted(d.glob("*.xosc")):
                    cat = document.load(f, "catalog file").find("Catalog")
                    if cat is not None:
                        self._catalogs.setdefault(cat.get("name", ""), (f, cat))
        return self._catalogs

    def resolve(self, ctx: Ctx, ref: etree._Element) -> tuple[etree._Element, Ctx]:
        """The catalog entry a CatalogReference names, and the context to read it in: the
        catalog file, a scope of the entry's own parameters with the reference's
        ParameterAssignments (evaluated where the reference stands)."""
        cat_name, entry_name = ctx.text(ref, "catalogName"), ctx.text(ref, "entryName")
        found = self._index().get(cat_name)
        if found is None:
            missing = [str(d) for d in self.directories if not d.is_dir()]
            hint = f"; missing directories: {', '.join(missing)}" if missing else ""
            raise HiyariError(
                f"{ctx.where(ref)}: catalog {cat_name!r} not found in the scenario's catalog "
                f"locations ({', '.join(str(d) for d in self.directories) or 'none'}{hint})"
            )
        file, cat = found
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
