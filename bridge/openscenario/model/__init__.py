"""The scenario model: entities, positions, a storyboard of actions and conditions; typed,
frozen, SI units (m, s, m/s, m/s^2, rad). Readers (OpenSCENARIO XML, hiyari presets) produce
it; the engine (``hiyari.bridge.openscenario.engine``) executes it on SUMO."""

from hiyari.bridge.openscenario.model.actions import *  # noqa: F403
from hiyari.bridge.openscenario.model.conditions import *  # noqa: F403
from hiyari.bridge.openscenario.model.entities import *  # noqa: F403
from hiyari.bridge.openscenario.model.global_actions import *  # noqa: F403
from hiyari.bridge.openscenario.model.positions import *  # noqa: F403
from hiyari.bridge.openscenario.model.storyboard import *  # noqa: F403
from hiyari.bridge.openscenario.model.trajectories import *  # noqa: F403
