r"""Three dimensions: what of Kalker's rolling contact problem is not yet written once for both
dimensions (docs/theory3d.md, docs/validation3d.md).

The grid, its step problems, operators and methods live beside their 2D siblings:
:mod:`rollqp.discretization.grid` (the grid), :mod:`rollqp.materials` (combined constants),
:mod:`rollqp.influence.cerruti` and :mod:`rollqp.influence.grid` (Boussinesq–Cerruti on rectangles,
block-Toeplitz operators of :mod:`rollqp.influence.blocktoeplitz`), :mod:`rollqp.profiles.surface`
(radii and curvatures), :mod:`rollqp.problem.grid` and :mod:`rollqp.problem.conic` (step problems and
their conic forms), :mod:`rollqp.operators.grid` (one contact, built once), :mod:`rollqp.methods.newton.disc`,
:mod:`rollqp.methods.socp`, :mod:`rollqp.methods.refine`, :mod:`rollqp.methods.chord` (the methods) and
:mod:`rollqp.scene.grid` (the scene), the closed forms (:mod:`rollqp.closedforms.hertz_ellipse`,
:mod:`rollqp.closedforms.kalker`, :mod:`rollqp.closedforms.cattaneo3d`), the load paths (:mod:`rollqp.loads`,
:mod:`rollqp.loadpath`) and the computed contact patch (:mod:`rollqp.patch`). Here remain the march and run
(:mod:`.march`, :mod:`.run`), the summary, advice,
cross-check and post-processing beside their 2D siblings (:mod:`rollqp.report.grid`, :mod:`rollqp.advice.grid`,
:mod:`rollqp.crossval.grid`).

Nothing here is imported by ``import rollqp``.
"""
