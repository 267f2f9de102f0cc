"""One TOML concrete scenario run in this process, its road in a temporary folder (the tests'
shorthand for compiling with TomlRun and executing the spec)."""

from __future__ import annotations

from hiyari.bridge.loop.closed_loop import OnStep
from hiyari.bridge.loop.execute import RunOptions, execute
from hiyari.bridge.loop.result import RunResult
from hiyari.bridge.loop.toml_runs import TomlRun
from hiyari.bridge.openscenario.presets.scenarios import World
from hiyari.bridge.openscenario.presets.toml_file import ConcreteScenario


def run_preset(
    cs: ConcreteScenario,
    options: RunOptions | None = None,
    on_step: OnStep | None = None,
    world: World | None = None,
) -> RunResult:
    """Run ``cs`` (on ``world`` for a city run) with ``options``."""
    with TomlRun(cs, world).spec() as spec:
        return execute(spec, options, on_step)
