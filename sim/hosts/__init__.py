"""Host-structure models that produce a `sim.model.system.ModalModel` (Eq. 7): the built-in Timoshenko rig, the 3D
solid model, CalculiX results, modal files from any FE tool, and the fidelity variants of the rig.

`ies modes` takes its model from the table `sim.hosts.sources.HOST_SOURCES`: a new source is one row there."""
