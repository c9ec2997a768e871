"""The result key `mu` of a 3D scene (SPEC, "Three dimensions: beyond Hertz": the friction coefficient each
element had): for a patch or a table in the fixed or the material frame, rolling forward, back (load.rolled)
or the other way (load.direction = +1), every element that the result calls slipping carries |t| = μp with the
stored μ, and no element carries more (Coulomb's law read back from the result file alone)."""
from __future__ import annotations

import numpy as np
import pytest

import rollqp

PATCH = {"law": "patch", "mu": 0.3, "inside": 0.1, "start": -0.5, "end": 0.5, "y_start": 0.0}
TABLE = {"law": "table", "x": [-1.0, 0.0, 1.0], "y": [-1.0, 1.0], "values": [[0.2, 0.3, 0.2], [0.2, 0.3, 0.25]]}
PATHS = {"forward": {}, "reversal": {"load.rolled": {"kind": "table", "q": [0.0, 0.5, 1.0], "value": [0.0, 0.5, 0.0]}},
         "direction +1": {"load.direction": 1}}


@pytest.mark.parametrize("path", PATHS)
@pytest.mark.parametrize("frame", ["fixed", "material"])
@pytest.mark.parametrize("law", ["patch", "table"])
def test_the_stored_mu_is_the_bound_each_element_had(law, frame, path):
    """Measured |(|t| − μp)| <= 4e-11 p0 on the slipping elements (the solver's tolerance 1e-10 on μp0) and
    |t| − μp <= 4e-11 p0 everywhere; bounds 1e-9 p0."""
    friction = dict(PATCH if law == "patch" else TABLE, frame=frame)
    s = rollqp.load_scene("cattaneo-3d").replace(**{"discretization.elements": [12, 12], "discretization.distance": 1.0,
                                                    "contact.friction": friction, **PATHS[path]})
    a = rollqp.run(s).arrays()
    mu, p, t = a["mu"], a["pn"], np.hypot(a["px"], a["py"])
    assert mu.shape == a["pn"].shape and np.all(mu >= 0)
    slip = a["state"] == 2
    assert slip.sum() > 20
    p0 = float(a["p0"])
    assert np.abs(t[slip] - mu[slip] * p[slip]).max() < 1e-9 * p0
    assert (t - mu * p).max() < 1e-9 * p0
    assert mu.min() < mu.max()            # the law varies over the grid


def test_a_coulomb_scene_has_no_mu_key():
    a = rollqp.run(rollqp.load_scene("cattaneo-3d").replace(**{"discretization.elements": [12, 12],
                                                                "discretization.distance": 0.5})).arrays()
    assert "mu" not in a
