"""Discretizations of the potential contact area: the strip of nodes along x (two dimensions,
:mod:`rollqp.strip`) and the uniform grid of rectangular surface elements (three dimensions,
:mod:`rollqp.discretization.grid`)."""
