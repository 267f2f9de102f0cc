"""SUMO runtime through libsumo: Simulation, WorldState, demand and collision detection."""

from hiyari.traffic.actor_class import ActorClass
from hiyari.traffic.collision import Collision, CollisionDetector
from hiyari.traffic.demand import DemandConfig, write_demand
from hiyari.traffic.read_scope import ReadScope
from hiyari.traffic.simulation import SimConfig, Simulation
from hiyari.traffic.world_state import WorldState

__all__ = [
    "ActorClass",
    "Collision",
    "CollisionDetector",
    "DemandConfig",
    "ReadScope",
    "SimConfig",
    "Simulation",
    "WorldState",
    "write_demand",
]
