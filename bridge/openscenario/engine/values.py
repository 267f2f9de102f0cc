"""The run-time values of a scenario: its variables (OpenSCENARIO 1.2+ VariableDeclarations),
its monitors (1.3 MonitorDeclarations: booleans the storyboard sets for whoever evaluates the
run) and its top-level parameters (which the deprecated ParameterSetAction / ParameterModifyAction
may still change). Values are kept as canonical text of their declared type, as the reader
resolves parameters; conditions compare them numerically when both sides are numbers, else as
text (equalTo / notEqualTo only)."""

from __future__ import annotations

from dataclasses import dataclass

from hiyari.bridge.openscenario.engine.kernels.measures import holds
from hiyari.bridge.openscenario.model.conditions import Rule
from hiyari.bridge.openscenario.xosc.context import canonical
from hiyari.errors import HiyariError

_RULES = list(Rule)
_NUMERIC = ("double", "int", "integer", "unsignedInt", "unsignedShort")


@dataclass
class Value:
    """One named value: its declared type and current canonical text."""

    type: str
    text: str


class ValueStore:
    """Variables and parameters by kind ("variable" / "parameter") and name."""

    def __init__(
        self,
        variables: dict[str, tuple[str, str]],
        parameters: dict[str, object],
        parameter_types: dict[str, str],
        monitors: dict[str, bool] | None = None,
    ) -> None:
        self._values = {
            "variable": {n: Value(t, v) for n, (t, v) in variables.items()},
            "parameter": {
                n: Value(parameter_types.get(n, "string"), str(v)) for n, v in parameters.items()
            },
            "monitor": {
                n: Value("boolean", "true" if v else "false") for n, v in (monitors or {}).items()
            },
        }
        #: Bumped by every change: conditions on values are re-read when it moves.
        self.version = 0

    def get(self, kind: str, name: str, where: str) -> Value:
        """The value ``name`` of ``kind``; HiyariError naming ``where`` when undeclared."""
        try:
            return self._values[kind][name]
        except KeyError:
            known = ", ".join(self._values[kind]) or "none"
            raise HiyariError(
                f"{where}: no {kind} {name!r} is declared (declared: {known})"
            ) from None

    def set(self, kind: str, name: str, text: str, where: str) -> None:
        """Set ``name`` to ``text`` converted to its declared type."""
        v = self.get(kind, name, where)
        v.text = canonical(text, v.type, where, name)
        self.version += 1

    def modify(self, kind: str, name: str, op: str, x: float, where: str) -> None:
        """Add ``x`` to a numeric ``name`` (``op`` "add") or multiply it by ``x``."""
        v = self.get(kind, name, where)
        if v.type not in _NUMERIC:
            raise HiyariError(f"{where}: {kind} {name!r} is a {v.type}, not a number to modify")
        now = float(v.text)
        self.set(kind, name, repr(now + x if op == "add" else now * x), where)

    def holds(self, kind: str, name: str, rule: Rule, value: str, where: str) -> bool:
        """Whether ``name`` compared by ``rule`` with ``value`` holds now."""
        have = self.get(kind, name, where).text
        try:
            a, b = float(have), float(value)
        except ValueError:
            if rule == Rule.EQUAL_TO:
                return have == value
            if rule == Rule.NOT_EQUAL_TO:
                return have != value
            raise HiyariError(f"{where}: {kind} condition {rule} needs numbers") from None
        return bool(holds(a, b, _RULES.index(rule)))
