"""The host as measured (Appendices A and B of the seed paper): what a user with a rig on the bench brings in, and
what it becomes for the simulator.

* `records`: hammer-test time records and measured FRFs, CSV with units in the header or UFF 58 (pyuff).
* `hammer`: hits cut out of a continuous record, double hits and clipping, force and exponential windows, the H_1,
  H_2 and H_v estimators with the coherence, displacement per force (Appendix A).
* `identification`: LSCF with a stabilization diagram in sub-bands, the stable poles chosen automatically, LSFD.
* `update`: a host model updated to measured modes (stiffness scale, E), the errors per mode (Table A.1), damping.
* `linearity`: stepped sines at several levels, half-power damping, a single nonlinear mode, the damping interval
  of D_1 over a response range (Appendix B, Table 2).
* `synthetic`: a measurement set of the rig made from the workbench's own linear model (and friction at the clamp).
* `figures`: Fig. A.1's and Fig. B.2's layouts and the stabilization diagram; `cli`: `ies identify`, `ies update`,
  `ies linearity`, `ies synthetic-tests`.

It writes the host description every other command reads: a modal-model file (`sim.hosts.modal_file`) with its
`[host]` damping interval. No other part of `sim` imports it (tests/test_architecture.py).
"""
