"""The record of one repair made to a parsed copy of a user's XML file (OpenDRIVE or
OpenSCENARIO), and how it names the element: both import pre-passes warn with it, one line
per repair, and never change the user's file."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from lxml import etree


@dataclass(frozen=True)
class Repair:
    """One change made to the copy: the element's source line, a short tag, what was done."""

    line: int
    element: str
    action: str

    def message(self, source: str | Path) -> str:
        """The one-line warning naming the user's file."""
        return f"{source}:{self.line}: {self.element}: {self.action}"


def tag(el: etree._Element, *attrs: str) -> str:
    """``<name a="1" b="2">`` with the given attributes, as written in the file."""
    shown = " ".join(f'{a}="{el.get(a)}"' for a in attrs if el.get(a) is not None)
    return f"<{etree.QName(el).localname}{' ' + shown if shown else ''}>"
