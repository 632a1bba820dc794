"""The simulation stage: the modal model of a beam with an Impact Energy Scatterer, its time integrators and
the stepped-sine protocol with its measures (seed paper Sects. 3 and 5).

Pipeline: rig geometry / modal file -> sim.rig / sim.modal_file -> modal model -> **sim** (stepped sine,
per-period amplitudes) -> uq. sim stands alone: it imports no other stage, which is why `sim.files`, the
one way every stage writes a file, lives here, with what every stage's command line shares: option types
(`sim.options`, quantities with units from `sim.units`) and the redrawing of result folders (`sim.redraw`). Its
commands `ies modes`, `ies sweep`, `ies overview` live in `sim.cli`; independent references for tests in
`sim.references`.

Public names, each imported from its module on first use, so that `import sim.errors` (done by the `ies`
front door) stays light (importing all of them takes 0.6-0.8 s more):
  system:     ModalModel, Impactor, Nominal, a_base_star, a_noabs_star (Eqs. 3-7, Sect. 5)
  rig:        seed_rig_model (the built-in Timoshenko beam model of the rig, Appendix A)
  modal_file: load_modal_model, save_modal_model (modes from any FE tool)
  contact_law: ContactLaw (Eq. 4 or the damped Hertz law of Eq. 10)
  friction:   JenkinsElement (the elastic dry-friction element of Appendix C)
  protocol:   SteppedSine, SweepResult, run_sweep, sweep (Sects. 5.1-5.3)
  signals:    Signal, read_signal, simulated_signal (measured or simulated time signals)
  impacts:    detect_impacts, ImpactDetection (impact detection, Appendix D.1)
  modal_fit:  fit_modes, ModalFit, plot_modal_fit (modal energies between impacts, Eq. 9, Figs. 9b/10b)
  tables:     overview_data (the resonant levels per excitation level, Fig. 6)
"""
from __future__ import annotations

import importlib
from typing import Any

from sim.errors import SimulationDiverged, SimulationInputError

_MODULE_OF = {
    "ModalModel": "system", "Impactor": "system", "Nominal": "system", "a_base_star": "system",
    "a_noabs_star": "system",
    "seed_rig_model": "rig",
    "load_modal_model": "modal_file", "save_modal_model": "modal_file",
    "ContactLaw": "contact_law", "JenkinsElement": "friction",
    "SteppedSine": "protocol", "SweepResult": "protocol", "run_sweep": "protocol", "sweep": "protocol",
    "Signal": "signals", "read_signal": "signals", "simulated_signal": "signals",
    "detect_impacts": "impacts", "ImpactDetection": "impacts",
    "fit_modes": "modal_fit", "ModalFit": "modal_fit", "plot_modal_fit": "modal_fit",
    "overview_data": "tables",
}
__all__ = ["SimulationDiverged", "SimulationInputError", *_MODULE_OF]


def __getattr__(name: str) -> Any:
    if name not in _MODULE_OF:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(f"{__name__}.{_MODULE_OF[name]}"), name)
