"""Convex decomposition of static meshes: which rule each mesh takes, exactness of the prisms,
CoACD's quality warning, the disk cache."""

from __future__ import annotations

import itertools
import warnings

import numpy as np
import pytest
from scipy.spatial import ConvexHull

from fleetsim.errors import SimulationError
from fleetsim.sim import Engine, decompose
from fleetsim.sim.mesh_files import triangle_mesh
from fleetsim.sim.prisms import prisms_of_architecture
from fleetsim.sim.sdf import load_sdf_model
from fleetsim.sim.world import WorldDesc, ground_plane

from .fixtures.make_building import grid_mesh


@pytest.fixture(autouse=True)
def cache(monkeypatch, tmp_path):
    monkeypatch.setenv("FLEETSIM_CACHE_DIR", str(tmp_path / "cache"))


def box(lo, hi):
    """Vertices and outward triangles of an axis-aligned box."""
    x = np.array(
        [[a, b, c] for a in (lo[0], hi[0]) for b in (lo[1], hi[1]) for c in (lo[2], hi[2])]
    )
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    f = [(a, b, c) for a, b, c, d in quads] + [(a, c, d) for a, b, c, d in quads]
    return x.astype(float), np.array(f)


def torus(n=12, m=6):
    u = np.linspace(0, 2 * np.pi, n, endpoint=False)
    w = np.linspace(0, 2 * np.pi, m, endpoint=False)
    uu, ww = np.meshgrid(u, w, indexing="ij")
    rad = 1.0 + 0.3 * np.cos(ww)
    v = np.stack([rad * np.cos(uu), rad * np.sin(uu), 0.3 * np.sin(ww) + 0.3], -1).reshape(-1, 3)
    f = []
    for i in range(n):
        for j in range(m):
            a, b = i * m + j, ((i + 1) % n) * m + j
            c, d = ((i + 1) % n) * m + (j + 1) % m, i * m + (j + 1) % m
            f += [(a, b, c), (a, c, d)]
    return v, np.array(f)


def u_shape():
    """A U of three boxes welded into one closed mesh: the union's surface, by a grid."""
    cells = np.zeros((3, 2, 1), bool)
    cells[0, :, 0] = cells[2, :, 0] = cells[1, 0, 0] = True
    return grid_mesh(cells, [0, 1, 2, 3], [0, 1, 3], [0, 2])


def test_a_box_is_convex_and_kept_whole():
    v, f = box((0, 0, 0), (1, 2, 3))
    d = decompose.decompose(v, f)
    assert d.convex and d.methods == ["convex"] and len(d.parts) == 1


def test_double_sided_and_duplicated_vertices_are_welded():
    v, f = box((0, 0, 0), (1, 1, 1))
    split = v[f].reshape(-1, 3)  # every triangle with vertices of its own (as COLLADA writes)
    faces = np.arange(len(split)).reshape(-1, 3)
    both = np.vstack([faces, faces[:, ::-1]])  # and each triangle twice, once per winding
    wv, wf = decompose.weld(split, both)
    assert len(wv) == 8 and len(wf) == 12
    assert decompose.decompose(split, both).convex


def test_separate_boxes_are_components_each_convex():
    v1, f1 = box((0, 0, 0), (1, 1, 1))
    v2, f2 = box((3, 0, 0), (4, 1, 2))
    d = decompose.decompose(np.vstack([v1, v2]), np.vstack([f1, f2 + 8]))
    assert d.methods == ["convex", "convex"] and not d.convex
    assert sorted(ConvexHull(p).volume for p in d.parts) == pytest.approx([1.0, 2.0])


def test_u_shape_is_cut_into_prisms_with_its_exact_volume():
    v, f = u_shape()
    assert not decompose.is_convex(v, f, 0.005)
    parts = prisms_of_architecture(v, f, 0.01)
    assert parts is not None
    assert sum(ConvexHull(p).volume for p in parts) == pytest.approx(decompose.mesh_volume(v, f))
    # no part covers the gap of the U (x 1..2, y 1..3)
    for p in parts:
        lo, hi = p.min(axis=0), p.max(axis=0)
        assert not (lo[0] < 1.999 and hi[0] > 1.001 and hi[1] > 1.001)


def test_walls_leaning_more_than_the_drift_are_not_prisms():
    v, f = box((0, 0, 0), (1, 1, 1))
    leaning = v.copy()
    leaning[v[:, 2] > 0.5, 0] += 0.05  # 5 cm lean over 1 m
    assert prisms_of_architecture(leaning, f, 0.01) is None
    assert prisms_of_architecture(leaning, f, 0.06) is not None


def test_a_torus_goes_to_coacd_and_a_part_limit_is_reported():
    v, f = torus()
    d = decompose.decompose(v, f, decompose.DecompositionParams(max_hulls=2))
    assert d.methods == ["coacd"] and len(d.parts) <= 2
    assert "maximum of 2 parts" in d.problems[0] and "more volume than the mesh" in d.problems[0]


def test_badly_decomposable_static_mesh_warns_naming_model_link_and_file(tmp_path, monkeypatch):
    v, f = torus()
    obj = tmp_path / "ring.obj"
    obj.write_text(
        "\n".join(
            [f"v {a} {b} {c}" for a, b, c in v] + [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in f]
        )
    )
    sdf = f"""<sdf version="1.6"><model name="ring_sculpture"><static>true</static>
      <link name="body"><collision name="shell"><geometry><mesh><uri>{obj}</uri></mesh>
      </geometry></collision></link></model></sdf>"""
    model = load_sdf_model(sdf, str(tmp_path / "ring.sdf"))
    monkeypatch.setattr(decompose, "DEFAULT_PARAMS", decompose.DecompositionParams(max_hulls=2))
    with pytest.warns(UserWarning, match=r"model 'ring_sculpture' link 'body' collision 'shell'"):
        e = Engine(WorldDesc("w", [ground_plane(), model]))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        Engine(WorldDesc("w", [ground_plane(), model]))  # cached: the warning comes again
    assert any("ring.obj" in str(w.message) for w in caught)
    assert sum(":cvx" in e.model.geom(i).name for i in range(e.model.ngeom)) == 2


def test_cache_location_follows_the_environment(monkeypatch, tmp_path):
    monkeypatch.delenv("FLEETSIM_CACHE_DIR")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert decompose.cache_dir() == tmp_path / "xdg" / "fleetsim"
    monkeypatch.setenv("FLEETSIM_CACHE_DIR", str(tmp_path / "mine"))
    v, f = box((0, 0, 0), (1, 1, 1))
    decompose.convex_decomposition(v, f)
    assert len(list((tmp_path / "mine" / "convex").glob("*.npz"))) == 1
    other = decompose.cache_file(v, f, decompose.DecompositionParams(prism_drift=0.02))
    assert other != decompose.cache_file(v, f, decompose.DEFAULT_PARAMS)


def test_stl_binary_ascii_and_obj_read_the_same_triangles(tmp_path):
    v, f = box((0, 0, 0), (1, 2, 3))
    tri = v[f].astype(np.float32)
    rec = np.zeros(len(f), [("n", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    rec["v"] = tri
    (tmp_path / "b.stl").write_bytes(b"\0" * 80 + np.uint32(len(f)).tobytes() + rec.tobytes())
    facets = "".join(
        "facet normal 0 0 0\nouter loop\n"
        + "".join(f"vertex {a} {b} {c}\n" for a, b, c in t)
        + "endloop\nendfacet\n"
        for t in tri
    )
    (tmp_path / "a.stl").write_text(f"solid x\n{facets}endsolid x\n")
    (tmp_path / "m.obj").write_text(
        "\n".join(
            [f"v {a} {b} {c}" for a, b, c in v] + [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in f]
        )
    )
    for name in ("b.stl", "a.stl", "m.obj"):
        vv, ff = triangle_mesh(tmp_path / name)
        np.testing.assert_allclose(vv[ff], tri, atol=1e-6)
    (tmp_path / "bad.obj").write_text("v 0 0 0\nf 1 2 3\n")
    with pytest.raises(SimulationError, match="bad.obj.*vertex that does not exist"):
        triangle_mesh(tmp_path / "bad.obj")


def test_an_open_mesh_of_single_faces_becomes_sheets():
    """Three walls of a room drawn as single faces (no thickness, not closed): each becomes a
    slab SHEET thick around its face, so robots are stopped by it as in Gazebo."""
    from fleetsim.sim.prisms import SHEET

    corners = [(0, 0), (4, 0), (4, 3), (0, 3)]
    v, f = [], []
    for (x0, y0), (x1, y1) in itertools.pairwise(corners):
        k = len(v)
        v += [(x0, y0, 0), (x1, y1, 0), (x1, y1, 2), (x0, y0, 2)]
        f += [(k, k + 1, k + 2), (k, k + 2, k + 3)]
    v, f = np.array(v, float), np.array(f)
    assert not decompose.is_closed(decompose.weld(v, f)[1])
    d = decompose.decompose(v, f)
    assert d.methods == ["prisms"]
    volume = sum(ConvexHull(p).volume for p in d.parts)
    assert volume == pytest.approx((4 + 3 + 4) * 2 * SHEET, rel=0.01)  # corners overlap a bit
    for x, y in [(2, 0), (4, 1.5), (2, 3)]:  # each wall's middle is inside a part
        assert any(
            np.all(p.min(axis=0) <= (x, y, 1)) and np.all(p.max(axis=0) >= (x, y, 1))
            for p in d.parts
        )
