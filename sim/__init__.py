"""The simulation stage: the modal model of a beam with an Impact Energy Scatterer, its time integrators and
the stepped-sine protocol with its measures (seed paper Sects. 3 and 5).

Pipeline: rig geometry / modal file -> sim.hosts.rig / sim.hosts.modal_file -> modal model -> **sim** (stepped sine,
per-period amplitudes) -> uq. sim stands alone: it imports no other stage, which is why `sim.common.files`, the
one way every stage writes a file, lives here, with what every stage's command line shares: option types
(`sim.common.options`, quantities with units from `sim.common.units`) and the redrawing of result folders (`sim.plots.redraw`). Its
commands, `sim.cli.COMMANDS`: `ies modes`, `ies sweep`, `ies overview`, `ies trace`, `ies cache` (the compiled
kernels' per-user cache, `sim.common.kernel_cache`; `sim.cli`), `ies orbits` (`sim.orbits.cli`: periodic orbits,
their stability and bifurcations), `ies impacts`, `ies modal-fit` (`sim.analysis.cli`) and `ies identify`, `ies update`,
`ies linearity`, `ies synthetic-tests` (`sim.measured.cli`: the host as measured, Appendices A and B); independent references for
tests in `sim.integration.references`.

Public names, each imported from its module on first use, so that `import sim.common.errors` (done by the `ies`
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

from sim.common.errors import SimulationDiverged, SimulationInputError

_MODULE_OF = {
    "ModalModel": "model.system", "Impactor": "model.system", "Nominal": "model.system", "a_base_star": "model.system",
    "a_noabs_star": "model.system",
    "seed_rig_model": "hosts.rig",
    "load_modal_model": "hosts.modal_file", "save_modal_model": "hosts.modal_file",
    "ContactLaw": "model.contact_law", "JenkinsElement": "model.friction",
    "SteppedSine": "stepped_sine.protocol", "SweepResult": "stepped_sine.protocol", "run_sweep": "stepped_sine.protocol", "sweep": "stepped_sine.protocol",
    "Signal": "analysis.signals", "read_signal": "analysis.signals", "simulated_signal": "analysis.signals",
    "detect_impacts": "analysis.impacts", "ImpactDetection": "analysis.impacts",
    "fit_modes": "analysis.modal_fit", "ModalFit": "analysis.modal_fit", "plot_modal_fit": "analysis.modal_fit",
    "overview_data": "stepped_sine.tables",
}
__all__ = ["SimulationDiverged", "SimulationInputError", *_MODULE_OF]


def __getattr__(name: str) -> Any:
    if name not in _MODULE_OF:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(f"{__name__}.{_MODULE_OF[name]}"), name)
