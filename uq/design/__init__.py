"""Design of an IES for a user's structure under uncertainty (`ies design`): which clearance g and which
sphere (radius R, material) keep the resonant tip amplitude lowest over an operating range of base excitation, in
the worst case over the uncertain D_1, clearance tolerance and k_H factor (Table 2's intervals by default).

Method, in two stages:

1. **Screening** by the slow flow (`sim.reduced.slow_flow.screen`): the one-mode slow flow predicts, in
   milliseconds, the resonant tip amplitude (m) and the regime of every (g, m_a, a_base) on the grid. Its inputs are
   the host's resonant mode and the modal restitution r (Eq. D.1; default the simulator's value for the seed rig,
   0.86). With rigid walls the slow flow depends on g and a_base only through a_base/g, which is the similarity law
   of Eqs. 2-7 (g -> s g, a_base -> s a_base, k_H -> s^-1/2 k_H; `tests/sim/integration/test_similarity.py`): k_H does not enter
   the screening. The worst case of a screened design is taken over the two ends of the D interval and of the
   clearance tolerance (the response is assumed monotone in each, as the paper does for Fig. 8).
2. **Verification** of the best screened designs that fit the cavity, their clearance neighbours on the grid and
   the user's baseline, by full stepped-sine simulation through the study runner (cached, resumable, joblib or
   Dask): at every operating level, every corner of the uncertainty box (D, g + tolerance, k_H factor: 8 corners)
   and the nominal point as the monotonicity check, each with the study's repetitions. The recommendation is always
   a verified design: the one with the lowest verified worst case.

The objective of a design is the worst case over the operating levels and the uncertainty corners of the resonant
tip amplitude in m (the mean over a period's amplitudes at the resonant frequency, Sect. 5.3; `--objective max`
takes the maximum amplitude instead), averaged over the repetitions.

Geometry: the cavity is 2R + 2g wide; a design whose cavity leaves walls thinner than `min_wall` (the rig's 5.5 mm
each across its 28 mm block) is refused or, on a grid, left out. The host's modes are taken as they are: the change
of the host's mass by a different cavity is neglected (said in the output). Dry friction (mu m_a g_grav) would break
the similarity law; the design runs without it.
"""
