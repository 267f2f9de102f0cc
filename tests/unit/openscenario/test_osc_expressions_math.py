"""OpenSCENARIO 1.3 expression functions (section 9.2): trigonometry, sign, abs, min, max and
the constant pi, against hand-computed values (the Euro NCAP files use them all)."""

from __future__ import annotations

import math

import pytest

from hiyari.bridge.openscenario.xosc.expressions import evaluate

P = {"Overlap": "-50", "w": "1.712", "ego": "1.815", "deg": "65"}.__getitem__


def test_trigonometry_in_radians_and_pi() -> None:
    assert evaluate("$deg * pi / 180", P) == pytest.approx(65 * math.pi / 180)
    assert evaluate("sin(pi / 6) + cos(pi / 3) + tan(pi / 4)", P) == pytest.approx(2.0)
    assert evaluate("asin(1) * 2 - pi", P) == pytest.approx(0.0, abs=1e-12)
    assert evaluate("acos(0) + atan(1) * 2", P) == pytest.approx(math.pi)
    with pytest.raises(ValueError, match="outside"):
        evaluate("acos(1.5)", P)


def test_sign_abs_min_max() -> None:
    assert evaluate("sign(-3) + sign(0) + sign(2.5)", P) == 0.0
    assert evaluate("abs(-2.5) + max(1, 3) + min(-1, 2)", P) == 4.5
    # the CCR file's GVT offset: -50 % overlap of a 1.815 m ego on a 1.712 m target
    off = evaluate(
        "sign($Overlap)*min(1.0,100.0-$Overlap)*($w/2-$ego*((abs($Overlap)-50.0)/100.0))", P
    )
    assert off == pytest.approx(-0.856)
    with pytest.raises(ValueError, match="takes 2"):
        evaluate("max(1)", P)


def test_text_pasted_together_is_refused_with_the_reason() -> None:
    # esmini's cut-in.xosc names a condition ${BrakeCondition_HWT + _ + $HeadwayTime_Brake}
    with pytest.raises(ValueError, match=r"'BrakeCondition_HWT' is neither a parameter "):
        evaluate("BrakeCondition_HWT + _ + $deg", P)
    with pytest.raises(ValueError, match="compute numbers and booleans, not text"):
        evaluate("$deg + _", P)
