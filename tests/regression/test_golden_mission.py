"""Golden regression: a short version of the demo mission plans to the stored numbers.

The stored arrays were produced by ``regenerate.py``; a refactoring must reproduce them to
1e-9 (the pipeline is deterministic).
"""

from __future__ import annotations

import numpy as np
import pytest
from regenerate import HERE, golden_arrays


@pytest.mark.regression
def test_short_demo_mission_matches_golden() -> None:
    with np.load(HERE / "golden_mission.npz") as stored:
        golden = {key: stored[key] for key in stored.files}
    arrays = golden_arrays(HERE / "golden_mission.toml")
    assert int(arrays["n_iter"]) == int(golden["n_iter"])
    for key in ("desired", "states", "inputs", "energy", "cost"):
        np.testing.assert_allclose(arrays[key], golden[key], rtol=1e-9, atol=1e-9, err_msg=key)
