"""OpenSCENARIO ``${...}`` expressions, evaluated by a small parser (never Python's eval).

The grammar of OpenSCENARIO 1.2 / 1.3 (section 9.2 "Expressions"): numbers, ``$name``
parameter references, ``true`` / ``false``, parentheses, unary ``-`` and ``not``, ``* / %``,
``+ -``, comparisons ``== != < <= > >=``, ``and``, ``or`` (lowest), the functions ``round``,
``floor``, ``ceil``, ``sqrt``, ``sin``, ``cos``, ``tan``, ``asin``, ``acos``, ``atan``,
``sign``, ``abs`` (one argument), ``pow``, ``max``, ``min`` (two), and the constant ``pi``
(which the Euro NCAP files of ../shared use; radians throughout). ``round`` rounds halves away
from zero; ``sign`` of 0 is 0; ``%`` is the remainder with the sign of the dividend (as in C's
fmod). Booleans count as 1 / 0 in arithmetic. Results are floats (or bools from comparisons
and logic).
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable

from hiyari.errors import HiyariError

_TOKEN = re.compile(
    r"\s*(?:(?P<num>\d+\.?\d*(?:[eE][+-]?\d+)?|\.\d+(?:[eE][+-]?\d+)?)"
    r"|(?P<par>\$[A-Za-z_][A-Za-z0-9_]*)"
    r"|(?P<name>[A-Za-z_][A-Za-z0-9_]*)"
    r"|(?P<op>==|!=|<=|>=|[-+*/%()<>,]))"
)


def _round(x: float) -> float:
    return math.floor(x + 0.5) if x >= 0 else -math.floor(-x + 0.5)


def _sqrt(x: float) -> float:
    if x < 0:
        raise ValueError(f"sqrt of a negative number ({x:g})")
    return math.sqrt(x)


def _inverse(name: str, fn: Callable[[float], float]) -> Callable[[float], float]:
    def call(x: float) -> float:
        if not -1.0 <= x <= 1.0:
            raise ValueError(f"{name} of {x:g}, outside [-1, 1]")
        return fn(x)

    return call


def _sign(x: float) -> float:
    return 1.0 if x > 0 else (-1.0 if x < 0 else 0.0)


_FUNCTIONS: dict[str, tuple[int, Callable[..., float]]] = {
    "round": (1, _round),
    "floor": (1, lambda x: float(math.floor(x))),
    "ceil": (1, lambda x: float(math.ceil(x))),
    "sqrt": (1, _sqrt),
    "sin": (1, math.sin),
    "cos": (1, math.cos),
    "tan": (1, math.tan),
    "asin": (1, _inverse("asin", math.asin)),
    "acos": (1, _inverse("acos", math.acos)),
    "atan": (1, math.atan),
    "sign": (1, _sign),
    "abs": (1, abs),
    "pow": (2, lambda x, y: float(math.pow(x, y))),
    "max": (2, max),
    "min": (2, min),
}
_CONSTANTS = {"pi": math.pi}

_COMPARE: dict[str, Callable[[float, float], bool]] = {
    "==": lambda a, b: a == b,
    "!=": lambda a, b: a != b,
    "<": lambda a, b: a < b,
    "<=": lambda a, b: a <= b,
    ">": lambda a, b: a > b,
    ">=": lambda a, b: a >= b,
}

Value = float | bool
Lookup = Callable[[str], object]


def evaluate(text: str, lookup: Lookup) -> Value:
    """Evaluate the expression ``text`` (without ``${`` ``}``); ``lookup(name)`` gives a
    parameter's value (KeyError when unknown). Raises ValueError with the reason."""
    return _Parser(text, lookup).parse()


class _Parser:
    def __init__(self, text: str, lookup: Lookup) -> None:
        self.text = text
        self.lookup = lookup
        self.tokens = self._tokenize(text)
        self.i = 0

    @staticmethod
    def _tokenize(text: str) -> list[tuple[str, str]]:
        out, pos = [], 0
        text = text.rstrip()
        while pos < len(text):
            m = _TOKEN.match(text, pos)
            if m is None or m.end() == pos:
                raise ValueError(f"unexpected character {text[pos:].strip()[:1]!r}")
            kind = m.lastgroup or ""
            out.append((kind, m.group(kind)))
            pos = m.end()
        return out

    def parse(self) -> Value:
        if not self.tokens:
            raise ValueError("empty expression")
        value = self._or()
        if self.i != len(self.tokens):
            raise ValueError(f"unexpected {self.tokens[self.i][1]!r}")
        return value

    def _peek(self) -> str | None:
        return self.tokens[self.i][1] if self.i < len(self.tokens) else None

    def _take(self, expected: str | None = None) -> tuple[str, str]:
        if self.i >= len(self.tokens):
            raise ValueError("expression ends too early")
        tok = self.tokens[self.i]
        if expected is not None and tok[1] != expected:
            raise ValueError(f"expected {expected!r}, found {tok[1]!r}")
        self.i += 1
        return tok

    def _or(self) -> Value:
        value = self._and()
        while self._peek() == "or":
            self._take()
            rhs = self._and()
            value = bool(value) or bool(rhs)
        return value

    def _and(self) -> Value:
        value = self._compare()
        while self._peek() == "and":
            self._take()
            rhs = self._compare()
            value = bool(value) and bool(rhs)
        return value

    def _compare(self) -> Value:
        value = self._sum()
        while self._peek() in _COMPARE:
            op = self._take()[1]
            value = _COMPARE[op](_num(value), _num(self._sum()))
        return value

    def _sum(self) -> Value:
        value = self._product()
        while self._peek() in ("+", "-"):
            op = self._take()[1]
            rhs = _num(self._product())
            value = _num(value) + rhs if op == "+" else _num(value) - rhs
        return value

    def _product(self) -> Value:
        value = self._unary()
        while self._peek() in ("*", "/", "%"):
            op = self._take()[1]
            a, b = _num(value), _num(self._unary())
            if op == "*":
                value = a * b
            elif b == 0:
                raise ValueError("division by zero")
            else:
                value = a / b if op == "/" else math.fmod(a, b)
        return value

    def _unary(self) -> Value:
        if self._peek() == "-":
            self._take()
            return -_num(self._unary())
        if self._peek() == "not":
            self._take()
            return not bool(self._unary())
        return self._atom()

    def _atom(self) -> Value:
        kind, text = self._take()
        if kind == "num":
            return float(text)
        if kind == "par":
            try:
                return _as_value(self.lookup(text[1:]), text)
            except KeyError:
                raise ValueError(f"unknown parameter {text}") from None
        if text == "(":
            value = self._or()
            self._take(")")
            return value
        if kind == "name" and text in ("true", "false"):
            return text == "true"
        if kind == "name" and text in _CONSTANTS:
            return _CONSTANTS[text]
        if kind == "name" and text in _FUNCTIONS:
            n_args, fn = _FUNCTIONS[text]
            self._take("(")
            args = [_num(self._or())]
            while self._peek() == ",":
                self._take()
                args.append(_num(self._or()))
            self._take(")")
            if len(args) != n_args:
                raise ValueError(f"{text}() takes {n_args} argument(s), got {len(args)}")
            return fn(*args)
        if kind == "name":  # text pasted together, as some tools allow: not an expression
            raise ValueError(
                f"{text!r} is neither a parameter (${text}) nor a function or constant: "
                "OpenSCENARIO 1.3 expressions compute numbers and booleans, not text"
            )
        raise ValueError(f"unexpected {text!r}")


def _num(v: Value) -> float:
    return float(v)


def _as_value(v: object, name: str) -> Value:
    if isinstance(v, bool | int | float):
        return float(v) if not isinstance(v, bool) else v
    text = str(v).strip()
    if text in ("true", "false"):
        return text == "true"
    try:
        return float(text)
    except ValueError:
        raise ValueError(f"parameter {name} = {text!r} is not a number") from None


def evaluate_or_raise(text: str, lookup: Lookup, where: str) -> Value:
    """``evaluate`` with a HiyariError naming ``where`` (file:line) and the expression."""
    try:
        return evaluate(text, lookup)
    except (ValueError, OverflowError) as exc:
        raise HiyariError(f"{where}: cannot evaluate ${{{text}}}: {exc}") from None
