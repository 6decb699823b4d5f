"""State queries: which contacts are reported (vectorised rule against the per-contact one)."""

import mujoco
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from fleetsim.sim import Engine
from fleetsim.sim.queries import contacts_kept

PLANE, BOX = int(mujoco.mjtGeom.mjGEOM_PLANE), int(mujoco.mjtGeom.mjGEOM_BOX)


def kept_reference(g1, g2, geom_type, geom_model, robot):
    """The rule contact by contact, as ``contacts`` applied it in a Python loop."""
    if geom_type[g1] == PLANE or geom_type[g2] == PLANE:
        return False
    i1, i2 = geom_model[g1], geom_model[g2]
    if i1 == i2:
        return False
    return bool((i1 >= 0 and robot[i1]) or (i2 >= 0 and robot[i2]))


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 10_000), n_geoms=st.integers(2, 12), n_models=st.integers(1, 4))
def test_contact_filter_matches_the_per_contact_rule(seed, n_geoms, n_models):
    rng = np.random.default_rng(seed)
    geom_type = rng.choice([PLANE, BOX], n_geoms, p=[0.2, 0.8])
    geom_model = rng.integers(-1, n_models, n_geoms)
    robot = rng.random(n_models) < 0.5
    geom = rng.integers(0, n_geoms, (15, 2))
    want = [kept_reference(a, b, geom_type, geom_model, robot) for a, b in geom]
    assert contacts_kept(geom, geom_type, geom_model, robot).tolist() == want


def test_robots_touching_each_other_are_reported(diffbot):
    e = Engine(None)
    e.spawn_robot("a", diffbot, (0, 0, 0, 0, 0, 0))
    e.spawn_robot("b", diffbot, (0.5, 0, 0, 0, 0, np.pi))
    for _ in range(20):
        for name in "ab":
            e.entry(name).plugins[0].command(0.3, 0.0, e.time)
        e.advance(0.05)
    pairs = {(c.model1, c.link1, c.model2, c.link2) for c in e.contacts()}
    assert ("a", "base_link", "b", "base_link") in pairs
    assert all(c.depth > -0.01 for c in e.contacts())
    assert not any("ground_plane" in (c.model1, c.model2) for c in e.contacts())
