"""Host-structure models that produce a `sim.model.system.ModalModel` (Eq. 7): the built-in Timoshenko rig, the 3D
solid model, CalculiX results, modal files from any FE tool, and the fidelity variants of the rig.

Every command, study and design takes its model from the table `sim.hosts.sources.HOST_SOURCES` through one resolver
(`sim.hosts.sources.resolve_host`): a new source is one row there."""
