r"""Three dimensions: Kalker's rolling contact problem, every step posed as a convex program
(QP, SOCP) on external solvers and as nonsmooth equations for rollqp's generalized Newton method
(docs/theory3d.md, docs/validation3d.md).

The package is layered like the 2D one; each layer imports only from the ones above it:

* base: :mod:`.grid` (the uniform grid of the potential contact area);
* physics: :mod:`.materials` (combined constants ``G, ν, K``), :mod:`.influence` (Boussinesq–Cerruti
  coefficients of rectangles), :mod:`.geometry` (radii, curvatures, the undeformed distance),
  :mod:`.hertz` and :mod:`.closedforms` (Hertz, Cattaneo–Mindlin, Kalker's creep coefficients);
* operators: :mod:`.operator` (block-Toeplitz products by FFT, dense blocks), :mod:`.operators`
  (the influence operators of one contact, shifted and steady ones);
* problems: :mod:`.problem` (step problems, solutions, rollqp's residuals), :mod:`.forms` (their
  QP and SOCP forms), :mod:`.contact` (one contact, built once; it makes the step problems);
* methods: :mod:`.gnm` (generalized Newton), :mod:`.socp` (Clarabel, OSQP, cvxpy);
* problems in time: :mod:`.march` (static shift, steady rolling, transient, N–T alternation);
* post-processing: :mod:`.post` (errors against Hertz and Cattaneo, creep coefficients).

Nothing here is imported by ``import rollqp``.
"""
