"""The coupled system of the seed paper (Sect. 3.1, Eqs. 3-7): the modal model of the host, the sphere and its
contact laws at the cavity walls (Eqs. 4, 10), and dry friction at the floor (Appendix C).

The parameters a study may vary or a command may set are the table `sim.model.parameters.PARAMETERS` (a new
parameter is one row there); `sim.model.system.build_system` is the one impactor builder that feeds them."""
