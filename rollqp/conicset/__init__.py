r"""Rolling contact as a test set for conic and friction-contact solvers (docs/conic-test-set.md).

The 3D steps of rollqp (docs/theory3d.md §5) exported with certified solutions:

* :mod:`~rollqp.conicset.forms` — the step's conic program as plain arrays (:class:`ProgramData`)
  and rollqp's residual (eq. 3D.29) of any answer, computed from those arrays alone;
* :mod:`~rollqp.conicset.cbf` — the programs in the Conic Benchmark Format (CBF, version 3),
  the QP's objective through a rotated-cone epigraph;
* :mod:`~rollqp.conicset.fclib` — the coupled static steps as FCLib local problems (HDF5, h5py);
* :mod:`~rollqp.conicset.generate` — the steps of the built-in scenes marched by rollqp's Newton
  method and certified by rollqp's residual;
* :mod:`~rollqp.conicset.run` — every installed conic solver on the set, scored against the
  certified solutions.

Nothing here is imported by ``import rollqp``; h5py and the solvers are optional (the extra
``conicbench``).
"""
