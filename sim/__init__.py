"""Modal simulator of a beam with an Impact Energy Scatterer (seed paper, Sects. 3 and 5)."""
from sim.errors import SimulationDiverged, SimulationInputError
from sim.system import Impactor, ModalModel, Nominal, a_base_star, a_noabs_star

__all__ = ["Impactor", "ModalModel", "Nominal", "SimulationDiverged", "SimulationInputError", "a_base_star", "a_noabs_star"]
