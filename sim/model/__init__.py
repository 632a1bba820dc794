"""The coupled system of the seed paper (Sect. 3.1, Eqs. 3-7): the modal model of the host, the sphere and its
contact laws at the cavity walls (Eqs. 4, 10), and dry friction at the floor (Appendix C)."""
