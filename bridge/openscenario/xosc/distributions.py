"""OpenSCENARIO ParameterValueDistribution files -> a list of concrete parameter sets.

Deterministic: every ParameterValueSet of a ValueSetDistribution, and for each single-parameter
distribution its DistributionSet elements or its DistributionRange (lower to upper limit in
steps of stepWidth, both limits included); the distributions combine as a Cartesian product
in file order. Stochastic: ``numberOfTestRuns`` draws with a seeded generator (the file's
randomSeed, else the caller's seed): UniformDistribution, NormalDistribution and
LogNormalDistribution (truncated to their Range by redrawing), PoissonDistribution,
Histogram (a bin by weight, then uniform in it) and ProbabilityDistributionSet (an element by
weight). The same file and seed give the same runs, bit for bit.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from lxml import etree

from hiyari.bridge.openscenario.xosc import document
from hiyari.bridge.openscenario.xosc.context import Ctx, Scope
from hiyari.errors import HiyariError

#: Redraws allowed when truncating a distribution to its range.
MAX_REDRAWS = 10_000


@dataclass(frozen=True)
class Distribution:
    """The scenario file a distribution applies to and its parameter sets (name -> text)."""

    scenario: Path
    runs: tuple[dict[str, str], ...]


def read_distribution(path: str | Path, seed: int | None = None) -> Distribution:
    """Expand the ParameterValueDistribution in ``path`` into concrete parameter sets."""
    path = Path(path).resolve()
    root = document.load(path, "parameter distribution file")
    ctx = Ctx(path, Scope()).enter(root)
    pvd = root.find("ParameterValueDistribution")
    if pvd is None:
        raise HiyariError(f"{path}: no <ParameterValueDistribution> in this file")
    sf = ctx.text(ctx.child(pvd, "ScenarioFile"), "filepath")
    scenario = Path(sf) if Path(sf).is_absolute() else (path.parent / sf).resolve()
    if not scenario.is_file():
        raise HiyariError(f"{ctx.where(pvd)}: scenario file {scenario} not found")
    det, sto = pvd.find("Deterministic"), pvd.find("Stochastic")
    runs = _deterministic(ctx, det) if det is not None else _stochastic(ctx, sto, seed)
    return Distribution(scenario, tuple(runs))


def _fmt(x: float) -> str:
    return repr(float(x))


def _deterministic(ctx: Ctx, det: etree._Element) -> list[dict[str, str]]:
    axes: list[list[dict[str, str]]] = []
    for d in det:
        if d.tag == "DeterministicMultiParameterDistribution":
            vs = ctx.one(d)
            if vs.tag != "ValueSetDistribution":
                raise ctx.unsupported(vs)
            sets = []
            for pset in vs.findall("ParameterValueSet"):
                sets.append(
                    {
                        ctx.text(a, "parameterRef"): ctx.text(a, "value")
                        for a in pset.findall("ParameterAssignment")
                    }
                )
            axes.append(sets)
        elif d.tag == "DeterministicSingleParameterDistribution":
            name = ctx.text(d, "parameterName")
            axes.append([{name: v} for v in _single(ctx, ctx.one(d))])
        else:
            raise ctx.unsupported(d)
    runs = []
    for combo in itertools.product(*axes):
        run: dict[str, str] = {}
        for part in combo:
            run.update(part)
        runs.append(run)
    return runs


def _single(ctx: Ctx, el: etree._Element) -> list[str]:
    if el.tag == "DistributionSet":
        return [ctx.text(e, "value") for e in el.findall("Element")]
    if el.tag == "DistributionRange":
        step = ctx.num(el, "stepWidth")
        lo, hi = _range(ctx, ctx.child(el, "Range"))
        if step <= 0 or hi < lo:
            raise HiyariError(
                f"{ctx.where(el)}: range {lo:g} .. {hi:g} with step {step:g} is empty"
            )
        n = int(math.floor((hi - lo) / step + 1e-9)) + 1
        return [_fmt(lo + k * step) for k in range(n)]
    raise ctx.unsupported(el)


def _range(ctx: Ctx, el: etree._Element) -> tuple[float, float]:
    return ctx.num(el, "lowerLimit"), ctx.num(el, "upperLimit")


def _stochastic(ctx: Ctx, sto: etree._Element, seed: int | None) -> list[dict[str, str]]:
    n = ctx.int(sto, "numberOfTestRuns")
    file_seed = ctx.opt_num(sto, "randomSeed")
    if file_seed is None and seed is None:
        raise HiyariError(
            f"{ctx.where(sto)}: stochastic distribution without randomSeed: give a seed"
        )
    rng = np.random.default_rng(int(file_seed) if file_seed is not None else seed)
    dists = [
        (ctx.text(d, "parameterName"), ctx.one(d)) for d in sto.findall("StochasticDistribution")
    ]
    runs = []
    for _ in range(n):
        runs.append({name: _draw(ctx, el, rng) for name, el in dists})
    return runs


def _truncated(ctx: Ctx, el: etree._Element, draw: object, rng: np.random.Generator) -> float:
    r = el.find("Range")
    lo, hi = _range(ctx, r) if r is not None else (-math.inf, math.inf)
    for _ in range(MAX_REDRAWS):
        x = float(draw())
        if lo <= x <= hi:
            return x
    raise HiyariError(f"{ctx.where(el)}: no draw fell into the range {lo:g} .. {hi:g}")


def _draw(ctx: Ctx, el: etree._Element, rng: np.random.Generator) -> str:
    tag = el.tag
    if tag == "UniformDistribution":
        lo, hi = _range(ctx, ctx.child(el, "Range"))
        return _fmt(rng.uniform(lo, hi))
    if tag == "NormalDistribution":
        mu, sd = ctx.num(el, "expectedValue"), math.sqrt(ctx.num(el, "variance"))
        return _fmt(_truncated(ctx, el, lambda: rng.normal(mu, sd), rng))
    if tag == "LogNormalDistribution":
        mu, sd = ctx.num(el, "expectedValue"), math.sqrt(ctx.num(el, "variance"))
        return _fmt(_truncated(ctx, el, lambda: rng.lognormal(mu, sd), rng))
    if tag == "PoissonDistribution":
        lam = ctx.num(el, "expectedValue")
        return _fmt(_truncated(ctx, el, lambda: rng.poisson(lam), rng))
    if tag == "Histogram":
        bins = el.findall("Bin")  # HistogramBin elements, named Bin
        w = np.array([ctx.num(b, "weight") for b in bins])
        k = int(rng.choice(len(bins), p=w / w.sum()))
        lo, hi = _range(ctx, ctx.child(bins[k], "Range"))
        return _fmt(rng.uniform(lo, hi))
    if tag == "ProbabilityDistributionSet":
        elems = el.findall("Element")
        w = np.array([ctx.num(e, "weight") for e in elems])
        return ctx.text(elems[int(rng.choice(len(elems), p=w / w.sum()))], "value")
    raise ctx.unsupported(el)
