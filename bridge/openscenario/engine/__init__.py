"""The scenario engine: executes a scenario model's storyboard on a running SUMO simulation,
one update per step (see ``executor``)."""

from hiyari.bridge.openscenario.engine.executor import ScenarioEngine, StepReport

__all__ = ["ScenarioEngine", "StepReport"]
