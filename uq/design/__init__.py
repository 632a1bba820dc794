"""Design of an IES for a user's structure under uncertainty (`ies design`): which clearance g and which sphere
(radius R, material) keep the objective (`uq.design.objectives`; by default the resonant tip amplitude) lowest over
an operating range of base excitation, in the worst case over the uncertain D_1, clearance tolerance and k_H factor,
while the switch from strongly modulated to almost periodic response stays a margin above the top of that range at
every corner of the box.

The host decides the box and the contact (`uq.design.problem.problem_of`): D_1's interval is the host's own
(`ModalModel.damping_box`: its [host] damping_interval, else Table 2's relative interval around its nominal D_1*,
said so in the output) unless `--damping`; every sphere's k_H* is Eq. 8 with both bodies' E and nu on the host's wall
material (`--wall-material` to override), through `sim.model.sphere`, so that `ies sweep --radius --material
--wall-material` simulates the same sphere; levels and a / a_noabs* are normalised by the host's D_1* and the
structure without IES is drawn at it.

Why the margin. An IES works best just below that switch (Sect. 5.3: the optimum at a_base/a_base* ~ 6.7 lies at the
switch): below it the response is strongly modulated and low, above it the amplitude jumps several-fold onto the
almost periodic branch (3.5x on the cantilever of the design benchmarks, 4.1x on the rig in the README's example).
A design whose worst corner switches within the range, or just above it, is one tolerance away from that jump;
`--margin` (default 20 %) is the distance a design must keep, and the recommendation says where its amplitude jumps
and by how much.

Method, in three stages (`uq.design.search`):

1. **Screening** by the slow flow (`sim.reduced.slow_flow.screen`, milliseconds for the whole grid): the onset of
   impacts, the trends with the sphere's mass and which spheres to predict first. Its switch (the fold of Eq. 9) is
   only a lower bound of the full model's (0.75-0.82 of it on the rig, its 3D solid model and a cantilever), so it
   does not decide.
2. **Prediction** by the similarity law of the full model (`sim.reduced.similarity`, `uq.design.prediction`): for a
   host and a sphere the normalised response at the own level a_base/a_base*(g) depends on g and k_H only through
   kappa = k_H g^(1/2), so a few references per sphere (kappa across the grid and the box, both ends of D_1),
   simulated on a grid of own levels with their switch bisected, predict every clearance's worst case and its switch
   at every corner of the box. Measured against the simulator on three hosts: tests/benchmarks/README.md.
3. **Verification** by full stepped-sine simulation through the study runner (cached, resumable, joblib or Dask):
   every corner of the box (D, g + tolerance, k_H factor: 8 corners) and its centre (the monotonicity check), at
   every operating level and at the margin level (the top times 1 + margin), each with the study's repetitions. The
   first batch is the `--candidates` best predicted designs (and the baseline); then the unverified neighbours of the
   best verified design on every axis (clearance, radius, material by density) are verified, round by round, until it
   has verified neighbours on both sides or the grid ends: the answer does not depend on the first batch's size.

A design is admissible when its margin at the box's worst corner (predicted, or lower where a verified run was almost
periodic) is at least `--margin` and no verified run of its box is almost periodic: never on the steep side of a
switch anywhere in the box. A level counts as almost periodic at a box point when any one of its runs is (not most
of them: the conservative rule, `uq.design.results.APR_RULE`), at or above the point's first impacts. The
recommendation is the admissible verified design with the lowest verified worst case, which comes with the 95 %
interval of a repeat of its verification (`uq.design.uncertainty`); where the runner-up's interval overlaps it, both
gain repetitions at the cells deciding them until the intervals part or 5x the repetitions are spent
(`uq.design.search.settle`), and the result says which. Refusals: where the similarity law predicts no design keeping
the margin, one line with the best predicted margins before any verification (exit 2); where no verified design is
admissible, design.csv and design.json hold every verified design marked not admissible (exit 3); both say how many
designs fit the block and which --block-width takes the grid.

The objective of a design is the worst case over the operating levels and the box's corners and centre of the
objective's value per run (the mean over a period's amplitudes at the resonant frequency, Sect. 5.3, for
`--objective mean`), averaged over the repetitions.

Geometry: the cavity is 2R + 2g wide; a design whose cavity leaves walls thinner than `min_wall` (the rig's 5.5 mm
each across its 28 mm block) is refused or, on a grid, left out. The host's modes are taken as they are: the change
of the host's mass by a different cavity is neglected (said in the output). Dry friction (mu m_a g_grav) would break
the similarity law; the design runs without it.
"""
