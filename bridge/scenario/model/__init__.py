"""The scenario model: entities, positions, a storyboard of actions and conditions; typed,
frozen, SI units (m, s, m/s, m/s^2, rad). Readers (OpenSCENARIO XML, hiyari presets) produce
it; the engine (``hiyari.bridge.scenario.engine``) executes it on SUMO."""

from hiyari.bridge.scenario.model.actions import *  # noqa: F403
from hiyari.bridge.scenario.model.conditions import *  # noqa: F403
from hiyari.bridge.scenario.model.entities import *  # noqa: F403
from hiyari.bridge.scenario.model.positions import *  # noqa: F403
from hiyari.bridge.scenario.model.storyboard import *  # noqa: F403
