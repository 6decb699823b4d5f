"""Layered costmap construction (plugins form, pre-Hydro form), static and voxel layers."""

import logging

import numpy as np
import pytest

from fleetsim.errors import ParameterError
from fleetsim.nav.costmap import (
    FREE_SPACE,
    LETHAL_OBSTACLE,
    NO_INFORMATION,
    InflationLayer,
    LayeredCostmap,
    ObstacleLayer,
    StaticLayer,
    VoxelLayer,
)
from fleetsim.nav.costmap.layered_costmap import costs_from_published, occupancy_from_costs
from fleetsim.nav.costmap.static_layer import costs_from_occupancy
from fleetsim.nav.errors import CostmapError
from fleetsim.nav.map_io import OccupancyMap

SEED_COMMON = {  # the tutorial's costmap_common_params.yaml + global_costmap_params.yaml
    "max_obstacle_height": 0.60,
    "obstacle_range": 3.0,
    "raytrace_range": 3.0,
    "robot_radius": 0.15,
    "map_type": "voxel",
    "origin_z": 0.0,
    "z_resolution": 0.2,
    "z_voxels": 2,
    "publish_voxel_map": False,
    "observation_sources": "scan",
    "scan": {
        "data_type": "LaserScan",
        "topic": "scan",
        "marking": True,
        "clearing": True,
        "min_obstacle_height": 0.05,
        "max_obstacle_height": 0.6,
    },
    "global_frame": "map",
    "robot_base_frame": "base_link",
    "update_frequency": 1.0,
    "publish_frequency": 0.5,
    "static_map": True,
    "transform_tolerance": 1.0,
    "inflation_layer": {"inflation_radius": 1.0, "cost_scaling_factor": 20},
}


def test_pre_hydro_form_builds_static_voxel_inflation():
    lc = LayeredCostmap.from_params(dict(SEED_COMMON), "global_costmap")
    kinds = [(la.name, type(la)) for la in lc.layers]
    assert kinds == [
        ("static_layer", StaticLayer),
        ("obstacle_layer", VoxelLayer),
        ("inflation_layer", InflationLayer),
    ]
    ob = lc.layer("obstacle_layer")
    assert ob.params.z_voxels == 2 and ob.params.max_obstacle_height == 0.6
    assert ob.buffers["scan"].params.obstacle_range == 3.0
    assert lc.layer("inflation_layer").params.cost_scaling_factor == 20.0


def test_plugins_form_and_unknown_type():
    ns = {
        "plugins": [{"name": "obs", "type": "costmap_2d::ObstacleLayer"}],
        "obs": {"observation_sources": "", "combination_method": 0},
    }
    lc = LayeredCostmap.from_params(ns, "c")
    assert [type(la) for la in lc.layers] == [ObstacleLayer]
    ns["plugins"] = [{"name": "x", "type": "costmap_2d::InflatonLayer"}]
    with pytest.raises(CostmapError, match="did you mean 'costmap_2d::InflationLayer'"):
        LayeredCostmap.from_params(ns, "c")


def test_pre_hydro_keys_beside_plugins_are_said_once_and_typos_still_warned(caplog):
    """A common file loaded into a costmap with a plugins list (the manual's nav_stack.launch
    with a robots layer added): its pre-Hydro keys are unread, as in ROS, and said at INFO."""
    ns = {
        "plugins": [{"name": "obs", "type": "costmap_2d::ObstacleLayer"}],
        "obs": {"observation_sources": ""},
        "map_type": "voxel",
        "z_voxels": 2,
        "observation_sources": "scan",
        "scan": {"data_type": "LaserScan", "topic": "scan"},
        "obstacle_range": 3.0,
        "widht": 4.0,
    }
    with caplog.at_level(logging.INFO, logger="fleetsim"):
        LayeredCostmap.from_params(ns, "lc")
    warned = [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING]
    assert len(warned) == 1 and "'widht'" in warned[0]
    said = [r.getMessage() for r in caplog.records if "pre-Hydro keys" in r.getMessage()]
    assert said == [
        "'plugins' is set: the pre-Hydro keys map_type, observation_sources, scan, z_voxels "
        "are not read (each layer reads its own namespace)"
    ]


def test_bad_parameter_is_named(caplog):
    with pytest.raises(ParameterError, match="'width' must be float"):
        LayeredCostmap.from_params({"width": "wide"}, "local_costmap")
    with caplog.at_level(logging.WARNING):
        LayeredCostmap.from_params({"rolling_windw": True, "observation_sources": ""}, "lc")
    assert "did you mean 'rolling_window'" in caplog.text


def test_misspelled_pre_hydro_layer_key_is_offered_the_layer_key(caplog):
    # the lesson's costmap_common_params.yaml form: inflation_radius at the costmap's level,
    # read by the implicit inflation layer; a typo there had no suggestion
    with caplog.at_level(logging.WARNING):
        c = LayeredCostmap.from_params(
            {"inflation_raduis": 0.7, "observation_sources": ""}, "global_costmap"
        )
    warned = [r.getMessage() for r in caplog.records if "inflation_raduis" in r.getMessage()]
    assert warned == [
        "global_costmap: unknown parameter 'inflation_raduis' (did you mean 'inflation_radius'?)"
    ]
    assert c.layer("inflation_layer").params.inflation_radius != 0.7  # not read, as in ROS
    # a key the chosen stack does not read (z_voxels without map_type voxel) is not offered
    # itself (found in review)
    caplog.clear()
    with caplog.at_level(logging.WARNING):
        LayeredCostmap.from_params({"z_voxels": 10, "observation_sources": ""}, "local_costmap")
    assert "unknown parameter 'z_voxels'" in caplog.text
    assert "did you mean 'z_voxels'" not in caplog.text


def test_static_layer_values_and_map_resize():
    data = np.array([[0, 100, -1], [50, 99, 0]], dtype=np.int8)
    assert costs_from_occupancy(data).tolist() == [[0, 254, 255], [0, 0, 0]]
    assert costs_from_occupancy(data, track_unknown_space=False)[0, 2] == FREE_SPACE
    scaled = costs_from_occupancy(data, trinary_costmap=False)
    assert scaled[1, 0] == int(50 / 100 * 254)
    lc = LayeredCostmap.from_params({"observation_sources": "", "track_unknown_space": True}, "g")
    lc.set_map(OccupancyMap(data, 0.5, (1.0, 2.0, 0.0)))
    lc.update_map(1.2, 2.2, 0.0)
    assert (lc.costmap.size_x, lc.costmap.size_y, lc.costmap.origin) == (3, 2, (1.0, 2.0))
    assert lc.costmap.costs[0, 1] == LETHAL_OBSTACLE
    assert lc.costmap.costs[0, 2] == NO_INFORMATION


def test_voxel_flattening_rule():
    ns = dict(
        SEED_COMMON,
        static_map=False,
        track_unknown_space=True,
        width=4.0,
        height=4.0,
        rolling_window=True,
        mark_threshold=1,
    )
    lc = LayeredCostmap.from_params(ns, "local_costmap")
    vox = lc.layer("obstacle_layer")
    # one marked voxel is not enough with mark_threshold 1; two are (z 0.1 and 0.3)
    lc.add_observation("scan", [0.0, 0.0, 0.3], [[1.0, 0.0, 0.1], [1.0, 1.0, 0.1]])
    lc.update_map(0.0, 0.0, 0.0)
    c = vox.grid.world_to_map(1.0, 1.0)
    assert vox.grid.costs[c[1], c[0]] != LETHAL_OBSTACLE
    lc.add_observation("scan", [0.0, 0.0, 0.3], [[1.0, 1.0, 0.1], [1.0, 1.0, 0.3]])
    lc.update_map(0.0, 0.0, 0.0)
    assert vox.grid.costs[c[1], c[0]] == LETHAL_OBSTACLE
    # a laser above the column (z 1.0) is clamped into the top voxel and still clears
    lc.add_observation("scan", [0.0, 0.0, 1.0], [[2.0, 0.0, 0.5]])
    lc.update_map(0.0, 0.0, 0.0)
    mid = vox.grid.world_to_map(1.0, 0.0)
    assert vox.grid.costs[mid[1], mid[0]] == FREE_SPACE


def test_costs_from_published_inverts_the_costmap_publisher():
    costs = np.arange(256, dtype=np.uint8)
    published = occupancy_from_costs(costs)
    assert np.array_equal(occupancy_from_costs(costs_from_published(published)), published)
    assert costs_from_published(np.array([-1, 0, 99, 100], np.int8)).tolist() == [255, 0, 253, 254]
    every = np.arange(-128, 128, dtype=np.int8).reshape(16, 16)  # any byte, in a grid's shape
    back = costs_from_published(every)
    assert back.shape == (16, 16) and back.dtype == np.uint8
    assert (back[every < 0] == 255).all() and (back[every > 100] == 254).all()
    valid = (every >= 0) & (every <= 100)  # each published by some cost: read back as one
    np.testing.assert_array_equal(occupancy_from_costs(back)[valid], every[valid])


def test_max_combination_in_place_matches_combined_max():
    """`combine_max_into` (compiled, in place on a window of the master) leaves what
    `combined_max` returns: unknown layer cells keep the master's, known ones win over an
    unknown or lower master cell; cells outside the window untouched."""
    from fleetsim.nav.costmap.costmap_2d import NO_INFORMATION
    from fleetsim.nav.costmap.layer import combine_max_into, combined_max

    rng = np.random.default_rng(9)
    for _ in range(50):
        master = rng.choice([0, 1, 100, 252, 253, 254, 255], (30, 40)).astype(np.uint8)
        layer = rng.choice([0, 7, 128, 253, 254, 255], (30, 40)).astype(np.uint8)
        y0, x0 = rng.integers(0, 15, 2)
        y1, x1 = y0 + rng.integers(0, 15), x0 + rng.integers(0, 25)
        want = master.copy()
        want[y0:y1, x0:x1] = combined_max(master[y0:y1, x0:x1], layer[y0:y1, x0:x1])
        combine_max_into(master[y0:y1, x0:x1], layer[y0:y1, x0:x1], NO_INFORMATION)
        assert np.array_equal(master, want)


#: global costmaps of a map alone: its static layer, with and without inflation
STATIC = {
    "plugins": [{"name": "static_layer", "type": "costmap_2d::StaticLayer"}],
    "track_unknown_space": True,
}
STATIC_INFLATION = {
    **STATIC,
    "plugins": [
        *STATIC["plugins"],
        {"name": "inflation_layer", "type": "costmap_2d::InflationLayer"},
    ],
    "robot_radius": 0.2,
    "inflation_layer": {"inflation_radius": 0.5},
}


def _office_like(rng: np.random.Generator, size: int = 120) -> np.ndarray:
    """An int8 occupancy map: unknown, with a known room of free cells and walls."""
    data = np.full((size, size), -1, dtype=np.int8)
    data[20:100, 20:100] = 0
    data[20, 20:100] = data[99, 20:100] = 100
    data[rng.integers(25, 95, 40), rng.integers(25, 95, 40)] = 100
    return data


def _fresh(params: dict, data: np.ndarray) -> np.ndarray:
    lc = LayeredCostmap.from_params(params, "g")
    lc.set_map(OccupancyMap(data, 0.05, (-3.0, -3.0, 0.0)))
    lc.update_map(0.0, 0.0, 0.0)
    return lc.costmap.costs.copy()


@pytest.mark.parametrize("params", [STATIC, STATIC_INFLATION], ids=["static", "inflated"])
def test_a_new_map_updates_only_what_changed_and_gives_the_full_update(params):
    """A republished map of the same geometry (a SLAM map) updates the cells it changed (grown
    by the inflation radius), not the whole map, and the master comes out as a costmap built
    from that map alone; two maps taken before one update count both maps' changes."""
    rng = np.random.default_rng(4)
    a = _office_like(rng)
    lc = LayeredCostmap.from_params(params, "g")

    def take(data: np.ndarray) -> None:
        lc.set_map(OccupancyMap(data, 0.05, (-3.0, -3.0, 0.0)))

    take(a)
    assert lc.update_map(0.0, 0.0, 0.0) == (0, 0, 120, 120)  # the first map: all of it
    b = a.copy()
    b[50:54, 60:63] = 100  # an obstacle mapped
    b[100:104, 30:40] = 0  # unknown cells seen free
    take(b)
    x0, y0, xn, yn = lc.update_map(0.0, 0.0, 0.0)
    assert (x0, y0) > (0, 0) and (xn - x0) * (yn - y0) < 120 * 120 / 2, (x0, y0, xn, yn)
    if params is STATIC:  # the changed cells and, as costmap_2d converts bounds, one beyond
        assert (x0, y0, xn, yn) == (30, 50, 64, 105)
    np.testing.assert_array_equal(lc.costmap.costs, _fresh(params, b))
    assert lc.update_map(0.0, 0.0, 0.0) == (0, 0, 0, 0)  # nothing new
    c = b.copy()
    c[30:32, 90:92] = 100  # mapped in the first of two maps, kept in the second
    d = c.copy()
    d[80, 25] = 100
    take(c)
    take(d)
    lc.update_map(0.0, 0.0, 0.0)
    np.testing.assert_array_equal(lc.costmap.costs, _fresh(params, d))
    take(d)
    assert lc.update_map(0.0, 0.0, 0.0) == (0, 0, 0, 0)  # the same map again
    grown = np.pad(d, ((0, 20), (0, 0)), constant_values=-1)  # gmapping grew its map
    take(grown)
    assert lc.update_map(0.0, 0.0, 0.0) == (0, 0, 120, 140)
    np.testing.assert_array_equal(lc.costmap.costs, _fresh(params, grown))


def _interpret_value_reference(data, lethal, unknown_value, track_unknown, trinary):
    """StaticLayer::interpretValue over an array, as costs_from_occupancy first computed it."""
    v = np.asarray(data).astype(np.int16) & 0xFF
    unknown = v == (unknown_value & 0xFF)
    if trinary:
        out = np.full(v.shape, FREE_SPACE, dtype=np.uint8)
    else:
        out = np.clip(v.astype(np.float64) / max(lethal, 1) * LETHAL_OBSTACLE, 0, 255)
        out = out.astype(np.uint8)
    out[v >= lethal] = LETHAL_OBSTACLE
    out[unknown] = NO_INFORMATION if track_unknown else FREE_SPACE
    return out


@pytest.mark.parametrize(
    "kw",
    [
        {},
        {"trinary_costmap": False},
        {"track_unknown_space": False},
        {"lethal_cost_threshold": 65, "unknown_cost_value": 255, "trinary_costmap": False},
    ],
)
def test_map_translations_by_table_match_the_per_cell_rules(kw):
    """Both translations of a map (occupancy -> costs as StaticLayer reads it, costs ->
    occupancy as costmap_2d publishes it) looked up by byte agree with the rules cell by cell,
    for every byte value, in any shape (empty, one row, a non-contiguous window)."""
    every = np.arange(-128, 128, dtype=np.int8).reshape(16, 16)
    ref = _interpret_value_reference(
        every,
        kw.get("lethal_cost_threshold", 100),
        kw.get("unknown_cost_value", -1),
        kw.get("track_unknown_space", True),
        kw.get("trinary_costmap", True),
    )
    np.testing.assert_array_equal(costs_from_occupancy(every, **kw), ref)
    np.testing.assert_array_equal(costs_from_occupancy(every[1::2, 3:], **kw), ref[1::2, 3:])
    np.testing.assert_array_equal(costs_from_occupancy(every.ravel(), **kw), ref.ravel())
    assert costs_from_occupancy(np.zeros((0, 4), np.int8), **kw).shape == (0, 4)
    costs = np.arange(256, dtype=np.uint8).reshape(2, 8, 16)
    published = occupancy_from_costs(costs)
    assert published.shape == costs.shape and published.dtype == np.int8
    assert published.ravel()[[0, 1, 252, 253, 254, 255]].tolist() == [0, 1, 98, 99, 100, -1]
    assert (np.diff(published.ravel()[1:253].astype(int)) >= 0).all()
