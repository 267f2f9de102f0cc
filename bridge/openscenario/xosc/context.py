"""Parameter scopes and the reading context: every attribute goes through ``Ctx`` so that
``$name`` references and ``${expression}`` values are resolved in the scope where they appear,
and every error names the file and line."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

from lxml import etree

from hiyari.bridge.openscenario.xosc.expressions import evaluate_or_raise
from hiyari.errors import HiyariError

INT_TYPES = ("int", "integer", "unsignedInt", "unsignedShort")


@dataclass
class Scope:
    """Parameter values (canonical text) declared at one level, with the enclosing scope."""

    values: dict[str, str] = field(default_factory=dict)
    parent: Scope | None = None
    types: dict[str, str] = field(default_factory=dict)

    def get(self, name: str) -> str:
        """The value of ``name`` here or in an enclosing scope; KeyError when undeclared."""
        scope: Scope | None = self
        while scope is not None:
            if name in scope.values:
                return scope.values[name]
            scope = scope.parent
        raise KeyError(name)


@dataclass(frozen=True)
class Violation:
    """A parameter value that fits none of its ConstraintGroups: ``broken`` lists, per group,
    the constraints it breaks with their bounds evaluated (e.g. 'greaterThan -1.75')."""

    where: str
    name: str
    value: str
    broken: tuple[tuple[str, ...], ...]

    def detail(self) -> str:
        """'Offset = -1.75 breaks greaterThan -1.75' (one group), or every group's broken
        constraints in brackets when there are several (the value fits none of them)."""
        if len(self.broken) == 1:
            return f"{self.name} = {self.value} breaks {' and '.join(self.broken[0])}"
        groups = " ".join(f"[{' and '.join(g)}]" for g in self.broken)
        return f"{self.name} = {self.value} breaks every constraint group: {groups}"


class ConstraintViolation(HiyariError):
    """Parameter values that break their declarations' ConstraintGroups. A distribution's
    run whose set raises this is skipped, not executed (OpenSCENARIO: such a parameter set is
    not valid); every other reading error stays an error of the file."""

    def __init__(self, violations: list[Violation]) -> None:
        first = violations[0]
        super().__init__(
            f"{first.where}: parameter {first.name} = {first.value} violates its constraint "
            f"groups ({'; '.join(v.detail() for v in violations)})"
        )
        self.violations = tuple(violations)

    def detail(self) -> str:
        """The broken constraints of every parameter, without the file position."""
        return "; ".join(v.detail() for v in self.violations)


def canonical(value: object, ptype: str, where: str, name: str) -> str:
    """A parameter's or variable's value as text in the form its declared type takes (one-line
    HiyariError naming ``where`` when it is not of that type)."""
    text = _to_text(value)
    try:
        if ptype in INT_TYPES:
            x = float(text)
            r = math.floor(x + 0.5) if x >= 0 else -math.floor(-x + 0.5)
            if ptype != "int" and ptype != "integer" and r < 0:
                raise ValueError
            return str(int(r))
        if ptype == "double":
            return repr(float(text))
        if ptype == "boolean":
            if text not in ("true", "false"):
                raise ValueError
            return text
    except ValueError:
        raise HiyariError(f"{where}: parameter {name} = {text!r} is not a {ptype}") from None
    return text


def _to_text(value: object) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value)
    return str(value)


class Ctx:
    """Where an element is read: its file, its parameter scope, and the catalogs."""

    def __init__(self, file: Path, scope: Scope, catalogs: object = None) -> None:
        self.file = file
        self.scope = scope
        self.catalogs = catalogs
        #: The element whose scope this context is (entering it again keeps this scope: a
        #: catalog entry is entered with its reference's assignments when resolved).
        self.entered: etree._Element | None = None

    def where(self, el: etree._Element) -> str:
        """'file:line' of ``el``."""
        return f"{self.file}:{el.sourceline}"

    def unsupported(self, el: etree._Element, detail: str = "") -> HiyariError:
        """The error for an element the engine cannot execute; without ``detail``, the
        element table's reason (coverage.REFUSED / NOT_YET) when it has one."""
        from hiyari.bridge.openscenario.coverage import NOT_YET, REFUSED

        if not detail:
            detail = REFUSED.get(el.tag) or (
                f"not yet: {NOT_YET[el.tag]}" if el.tag in NOT_YET else ""
            )
        extra = f" ({detail})" if detail else ""
        return HiyariError(f"{self.where(el)}: <{el.tag}> is not supported by hiyari{extra}")

    # ------------------------------------------------------------------ attributes
    def resolve(self, text: str, el: etree._Element) -> str:
        """Resolve one attribute value: ``$name`` or ``${expression}`` or literal text."""
        if not text.startswith("$"):
            return text
        if text.startswith("${") and text.endswith("}"):
            return _to_text(evaluate_or_raise(text[2:-1], self.scope.get, self.where(el)))
        try:
            return self.scope.get(text[1:])
        except KeyError:
            raise HiyariError(f"{self.where(el)}: unknown parameter {text}") from None

    def text(self, el: etree._Element, name: str, default: str | None = None) -> str:
        """Attribute ``name`` resolved; ``default`` when absent (required when None)."""
        raw = el.get(name)
        if raw is None:
            if default is None:
                raise HiyariError(f"{self.where(el)}: <{el.tag}> lacks attribute {name!r}")
            return default
        return self.resolve(raw, el)

    def opt(self, el: etree._Element, name: str) -> str | None:
        """Attribute ``name`` resolved, or None when absent."""
        raw = el.get(name)
        return None if raw is None else self.resolve(raw, el)

    def num(self, el: etree._Element, name: str, default: float | None = None) -> float:
        """Attribute ``name`` as a float."""
        text = self.text(el, name, None if default is None else repr(default))
        try:
            return float(text)
        except ValueError:
            raise HiyariError(
                f"{self.where(el)}: <{el.tag}> {name} = {text!r} is not a number"
            ) from None

    def opt_num(self, el: etree._Element, name: str) -> float | None:
        """Attribute ``name`` as a float, or None when absent."""
        return None if el.get(name) is None else self.num(el, name)

    def int(self, el: etree._Element, name: str, default: int | None = None) -> int:
        """Attribute ``name`` as an int (an integral float is accepted) within xsd:int's
        32-bit range."""
        x = self.num(el, name, None if default is None else float(default))
        if not -(2**31) <= x <= 2**31 - 1:
            raise HiyariError(
                f"{self.where(el)}: <{el.tag}> {name} = {x:g} is outside the 32-bit integer range"
            )
        if x != int(x):
            raise HiyariError(f"{self.where(el)}: <{el.tag}> {name} = {x:g} is not an integer")
        return int(x)

    def flag(self, el: etree._Element, name: str, default: bool | None = None) -> bool:
        """Attribute ``name`` as a boolean."""
        text = self.text(el, name, None if default is None else str(default).lower())
        if text not in ("true", "false", "1", "0"):
            raise HiyariError(f"{self.where(el)}: <{el.tag}> {name} = {text!r} is not a boolean")
        return text in ("true", "1")

    def opt_flag(self, el: etree._Element, name: str) -> bool | None:
        """Attribute ``name`` as a boolean, or None when absent."""
        return None if el.get(name) is None else self.flag(el, name)

    # ------------------------------------------------------------------ scopes
    def enter(self, el: etree._Element, overrides: Mapping[str, str] | None = None) -> Ctx:
        """The context inside ``el``: its ParameterDeclarations (if any) declared in a new
        scope, ``overrides`` replacing declared values; constraints checked. Entering the
        element this context already is keeps it."""
        if self.entered is el and not overrides:
            return self
        decls = el.find("ParameterDeclarations")
        if decls is None and not overrides:
            return self
        scope = Scope(parent=self.scope)
        inner = Ctx(self.file, scope, self.catalogs)
        declared = []
        for d in [] if decls is None else decls.findall("ParameterDeclaration"):
            name = inner.text(d, "name")
            ptype = inner.text(d, "parameterType", "string")
            if overrides is not None and name in overrides:
                value: object = overrides[name]
            else:
                value = inner.text(d, "value", "")
            scope.values[name] = canonical(value, ptype, inner.where(d), name)
            scope.types[name] = ptype
            declared.append((name, ptype, d))
        unknown = set(overrides or ()) - {n for n, _, _ in declared}
        if unknown:
            raise HiyariError(
                f"{self.where(el)}: no parameter {', '.join(sorted(unknown))} is declared here "
                f"(declared: {', '.join(n for n, _, _ in declared) or 'none'})"
            )
        # every parameter is checked, so that a skipped run names all the values it breaks
        broken = [v for name, ptype, d in declared if (v := inner._violation(name, ptype, d))]
        if broken:
            raise ConstraintViolation(broken)
        inner.entered = el
        return inner

    def _violation(self, name: str, ptype: str, decl: etree._Element) -> Violation | None:
        """None when the value fits one of the declaration's ConstraintGroups (or it has
        none: OpenSCENARIO ORs the groups and ANDs the constraints inside a group)."""
        groups = decl.findall("ConstraintGroup")
        if not groups:
            return None
        value = self.scope.values[name]
        broken = []
        for g in groups:
            failed = tuple(
                b for c in g.findall("ValueConstraint") if (b := self._broken(value, ptype, c))
            )
            if not failed:
                return None
            broken.append(failed)
        return Violation(self.where(decl), name, value, tuple(broken))

    def _broken(self, value: str, ptype: str, c: etree._Element) -> str | None:
        """'rule bound' (the bound evaluated: it may be a parameter or an expression) when
        ``value`` breaks the constraint ``c``, else None."""
        if self._holds(value, ptype, c):
            return None
        return f"{self.text(c, 'rule')} {self.text(c, 'value')}"

    def _holds(self, value: str, ptype: str, c: etree._Element) -> bool:
        rule, bound = self.text(c, "rule"), self.text(c, "value")
        numeric = ptype in (*INT_TYPES, "double")
        if not numeric:
            try:
                a, b = float(value), float(bound)
            except ValueError:
                a, b = value, bound  # type: ignore[assignment]
        else:
            a, b = float(value), float(bound)
        ops = {
            "equalTo": lambda: a == b,
            "notEqualTo": lambda: a != b,
            "greaterThan": lambda: a > b,
            "lessThan": lambda: a < b,
            "greaterOrEqual": lambda: a >= b,
            "lessOrEqual": lambda: a <= b,
        }
        if rule not in ops:
            raise self.unsupported(c, f"rule {rule!r}")
        try:
            return bool(ops[rule]())
        except TypeError:
            raise HiyariError(
                f"{self.where(c)}: constraint {rule} {bound!r} cannot compare text values"
            ) from None

    def one(self, el: etree._Element) -> etree._Element:
        """The single element child of a choice element (comments are stripped on load)."""
        kids = [k for k in el if isinstance(k.tag, str)]
        if len(kids) != 1:
            raise HiyariError(f"{self.where(el)}: <{el.tag}> should hold exactly one element")
        return kids[0]

    def child(self, el: etree._Element, tag: str) -> etree._Element:
        """The child ``tag`` of ``el`` (the schema guarantees required ones)."""
        found = el.find(tag)
        if found is None:
            raise HiyariError(f"{self.where(el)}: <{el.tag}> lacks <{tag}>")
        return found
