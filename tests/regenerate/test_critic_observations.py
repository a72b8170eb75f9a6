"""The stored observations the critic's tests judge still come out of their recipes: rolled out again
under the locked versions, each case gives the oracle values it was stored with, the same verdict of
the image critic (accept and every check), and the same segmentation of its last top view.

A failure here means the rollouts moved (a new simulator, a changed skill or scene): the critic's
tests still judge the stored files, so look at what moved, then make the files again with
``.venv/bin/python tests/critics/recipes.py NAME`` in a commit that says why. ``scripts/check-latest.sh``
runs this check under the newest releases.
"""

from __future__ import annotations

import numpy as np
import pytest

from critics.recipes import CASES, observed
from vcage.critics.image import ImageCritic

CRITIC = ImageCritic()
pytestmark = pytest.mark.slow


@pytest.mark.parametrize("name", sorted(CASES))
def test_a_stored_observation_comes_out_of_its_recipe_again(name: str) -> None:
    stored = observed(name)
    fresh = CASES[name]()
    assert fresh.oracle == stored.oracle, "the oracle's values moved"
    assert fresh.extra["applied"] == stored.extra["applied"]
    then, now = CRITIC.judge(stored.obs), CRITIC.judge(fresh.obs)
    assert (now.accept, now.details.get("checks")) == (then.accept, then.details.get("checks")), \
        (now.reason, then.reason)
    a, b = stored.obs.after["top"].segmentation, fresh.obs.after["top"].segmentation
    assert a.shape == b.shape and float(np.mean(a == b)) >= 0.99, "the scene after the subtask moved"


def test_every_stored_observation_has_a_recipe() -> None:
    from critics.recipes import HERE

    assert sorted(p.stem for p in HERE.glob("*.npz")) == sorted(CASES)
