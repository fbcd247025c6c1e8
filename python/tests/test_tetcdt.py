"""The Python package against the command line: same meshes, same errors, arrays of the
documented shapes and types. Run with ``python3 -m pytest python/tests`` after
``pip install ./python`` and ``cargo build --release`` (the command line binary is
``target/release/tetcdt``, or ``$TETCDT_BIN``)."""

from __future__ import annotations

import os
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import tetcdt

REPO = Path(__file__).resolve().parents[2]
BIN = Path(os.environ.get("TETCDT_BIN", REPO / "target" / "release" / "tetcdt"))
DATA = REPO / "data"


def cli(model: Path, switches: str, prefix: Path) -> subprocess.CompletedProcess:
    """Runs the command line on `model` with `switches`, writing under `prefix`."""
    assert BIN.exists(), f"{BIN} is missing: run cargo build --release first"
    args = [str(BIN), "-Q" + switches if switches else "-Q", str(model), "-o", str(prefix)]
    return subprocess.run(args, capture_output=True, text=True, check=False)


def table(path: Path) -> np.ndarray:
    """The rows of a TetGen file after its header line, comments left out."""
    rows = [
        line.split()
        for line in path.read_text().splitlines()
        if line.strip() and not line.lstrip().startswith("#")
    ]
    return np.array(rows[1:], dtype=float) if len(rows) > 1 else np.zeros((0, 1))


def cli_mesh(model: Path, switches: str, tmp: Path) -> dict:
    """The command line's mesh of `model`, numbered from 0."""
    run = cli(model, switches, tmp / "cli")
    assert run.returncode == 0, run.stderr
    node = table(tmp / "cli.node")
    ele = table(tmp / "cli.ele")
    first = int(node[0, 0]) if len(node) else 0
    out = {
        "points": node[:, 1:4],
        "tets": ele[:, 1:5].astype(np.int64) - first,
    }
    face_file = tmp / "cli.face"
    face = table(face_file) if face_file.exists() else np.zeros((0, 1))
    if face.shape[1] == 5:  # a PLC's faces on facets, with markers
        out["faces"] = face[:, 1:4].astype(np.int64) - first
        out["face_markers"] = face[:, 4].astype(np.int64)
    if ele.shape[1] > 5:
        out["tet_regions"] = ele[:, 5]
    return out


def same_faces(a: np.ndarray, am: np.ndarray, b: np.ndarray, bm: np.ndarray) -> bool:
    """The faces as sets of (sorted corners, marker)."""

    def key(f, m):
        return sorted((tuple(sorted(map(int, r))), int(k)) for r, k in zip(f, m))

    return key(a, am) == key(b, bm)


def assert_same_mesh(mesh: tetcdt.Mesh, ref: dict) -> None:
    np.testing.assert_array_equal(mesh.points, ref["points"])
    np.testing.assert_array_equal(mesh.tets, ref["tets"])
    if "faces" in ref:
        assert same_faces(mesh.faces, mesh.face_markers, ref["faces"], ref["face_markers"])
    if "tet_regions" in ref:
        np.testing.assert_array_equal(mesh.tet_regions, ref["tet_regions"])


CASES = [
    ("examples/box_with_hole.poly", "p"),
    ("examples/box_with_hole.poly", "pF"),
    ("examples/box_with_hole.poly", "pA"),
    ("examples/box_with_hole.poly", "pq1.414a0.01"),
    ("examples/points8.node", ""),
    ("plc/eight.off", "p"),
    ("plc/eight.off", "pq1.2/10"),
    ("plc/box_internal_facet.poly", "pq"),
    ("plc/slit-1.smesh", "pF"),
    ("plc/mpi.off", "p"),
    ("csg/flange_7.off", "p"),
    ("plc/eight.off", "pc"),
    ("formats/cube.stl", "pq1.414"),
    ("formats/cube.ply", "p"),
    ("formats/cube.mesh", "pa0.05"),
]


@pytest.mark.parametrize("model,switches", CASES)
def test_same_mesh_as_command_line(model: str, switches: str, tmp_path: Path) -> None:
    path = DATA / model
    ref = cli_mesh(path, switches, tmp_path)
    plc = tetcdt.read(path)
    assert_same_mesh(plc.tetrahedralize(switches), ref)
    if any(plc.facet_holes):
        return  # facet holes have no array form; PLC.tetrahedralize covers them
    from_arrays = tetcdt.tetrahedralize(
        plc.points,
        plc.faces if len(plc.facets) else None,
        switches,
        holes=plc.holes,
        regions=plc.regions,
        facet_markers=plc.facet_markers,
    )
    assert_same_mesh(from_arrays, ref)


def test_written_files_are_the_command_lines(tmp_path: Path) -> None:
    path = DATA / "examples/box_with_hole.poly"
    cli(path, "pAen", tmp_path / "cli")
    written = tetcdt.read(path).tetrahedralize("pAen").write(tmp_path / "py")
    assert [Path(p).suffix for p in written] == [".node", ".ele", ".face", ".edge", ".neigh"]

    def body(p: Path) -> list[str]:
        return [line for line in p.read_text().splitlines() if not line.startswith("#")]

    for p in written:
        suffix = Path(p).suffix
        assert body(Path(p)) == body(tmp_path / ("cli" + suffix)), suffix


CUBE = np.array(
    [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]],
    dtype=float,
)
QUADS = [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]]


def cube_triangles() -> np.ndarray:
    return np.array([t for q in QUADS for t in ([q[0], q[1], q[2]], [q[0], q[2], q[3]])])


def test_face_forms() -> None:
    # Quads as an array, as a list of polygons, and as a list of one-polygon facets.
    as_array = tetcdt.tetrahedralize(CUBE, np.array(QUADS), "p")
    as_polygons = tetcdt.tetrahedralize(CUBE, QUADS, "p")
    as_facets = tetcdt.tetrahedralize(CUBE, [[q] for q in QUADS], "p")
    for m in (as_polygons, as_facets):
        np.testing.assert_array_equal(m.tets, as_array.tets)
    # A facet of two triangles is one facet: its diagonal is no constraint (-M keeps
    # the triangles as separate facets, which still merge when coplanar, so compare
    # the facet count through the markers instead).
    tris = cube_triangles()
    paired = [[list(tris[2 * i]), list(tris[2 * i + 1])] for i in range(6)]
    m = tetcdt.tetrahedralize(CUBE, paired, "p", facet_markers=np.arange(6) + 10)
    assert sorted(set(m.face_markers.tolist())) == list(range(10, 16))
    # Mixed polygon sizes in one list.
    mixed = [QUADS[0], QUADS[1]] + [list(t) for t in tris[4:]]
    assert len(tetcdt.tetrahedralize(CUBE, mixed, "p").tets) == len(as_array.tets)


def test_shapes_and_types() -> None:
    m = tetcdt.tetrahedralize(CUBE, cube_triangles(), "pq1.414a0.05A", regions=[[0.5] * 3 + [4]])
    n, k, f, e = len(m.points), len(m.tets), len(m.faces), len(m.edges)
    assert m.points.shape == (n, 3) and m.points.dtype == np.float64
    assert m.tets.shape == (k, 4) and m.tets.dtype == np.int32
    assert m.faces.shape == (f, 3) and m.faces.dtype == np.int32
    assert m.face_markers.shape == (f,) and m.face_markers.dtype == np.int32
    assert m.edges.shape == (e, 2) and m.edge_markers.shape == (e,)
    assert m.tet_regions.shape == (k,) and m.tet_regions.dtype == np.float64
    assert set(m.tet_regions.tolist()) == {4.0}
    assert m.tets.min() >= 0 and m.tets.max() == n - 1
    assert not m.points.flags.writeable and not m.tets.flags.writeable
    assert m.stats["mesh_points"] == n and m.stats["output_tets"] == k
    assert m.stats["max_radius_edge_ratio"] <= 1.414
    assert m.stats["max_volume"] <= 0.05
    assert len(m.stats["dihedral_histogram"]) == 18
    assert sum(m.stats["dihedral_histogram"]) == 6 * k
    assert m.stats["plc"] is True and m.stats["facet_algorithm"] == "cavity"
    assert tetcdt.tetrahedralize(CUBE, cube_triangles(), "p").tet_regions is None
    # Positive orientation, as TetGen writes tets.
    p = m.points[m.tets]
    vol = np.einsum("ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), p[:, 3] - p[:, 0])
    assert (vol > 0).all()


def test_points_alone() -> None:
    rng = np.random.default_rng(5)
    pts = rng.random((200, 3))
    m = tetcdt.tetrahedralize(pts, switches="")
    assert len(m.points) == 200 and len(m.tets) > 200
    with pytest.raises(tetcdt.InvalidInputError, match="empty"):
        tetcdt.tetrahedralize(pts)  # -p with no facets: nothing is inside


def command_line_message(model: Path, switches: str, tmp: Path) -> tuple[int, str]:
    run = cli(model, switches, tmp / "err")
    return run.returncode, run.stderr.strip().removeprefix("tetcdt: ")


def test_invalid_input_errors(tmp_path: Path) -> None:
    # Found while reading: the message names the file and the line.
    bad = DATA / "broken/index_out_of_range.poly"
    code, msg = command_line_message(bad, "p", tmp_path)
    with pytest.raises(tetcdt.InvalidInputError) as e:
        tetcdt.read(bad)
    assert code == 3 and str(e.value) == msg and ":17:" in msg
    assert isinstance(e.value, ValueError)
    # Found while meshing: intersecting facets.
    crossing = DATA / "broken/crossing_facets.poly"
    code, msg = command_line_message(crossing, "p", tmp_path)
    plc = tetcdt.read(crossing)
    with pytest.raises(tetcdt.InvalidInputError) as e:
        plc.tetrahedralize("p")
    assert code == 3 and str(e.value) == msg
    # Arrays: an index out of range, a negative one, two crossing triangles.
    with pytest.raises(tetcdt.InvalidInputError, match="refers to point 8"):
        tetcdt.tetrahedralize(CUBE, [[0, 1, 8]])
    with pytest.raises(tetcdt.InvalidInputError, match="refers to point -1"):
        tetcdt.tetrahedralize(CUBE, [[0, 1, -1]])
    crossing_pts = np.array(
        [[0, 0, 0], [2, 0, 0], [0, 2, 0], [0.5, 0.5, -1], [0.5, 0.5, 1], [3, 3, 0]], float
    )
    with pytest.raises(tetcdt.InvalidInputError, match="intersect"):
        tetcdt.tetrahedralize(crossing_pts, [[0, 1, 2], [3, 4, 5]])
    with pytest.raises(tetcdt.InvalidInputError, match="not finite|NaN|nan"):
        tetcdt.tetrahedralize(np.array([[np.nan, 0, 0]] + CUBE.tolist()[1:]), cube_triangles())
    # A malformed file and an unknown format.
    with pytest.raises(tetcdt.InvalidInputError, match=":"):
        tetcdt.read(DATA / "broken/huge_count.off")
    unknown = tmp_path / "model.xyz"
    unknown.write_text("0 0 0\n")
    with pytest.raises(tetcdt.InvalidInputError, match="unknown input format"):
        tetcdt.read(unknown)


def test_meshing_error(tmp_path: Path) -> None:
    model = DATA / "csg/flange_7.off"
    code, msg = command_line_message(model, "pS1", tmp_path)
    with pytest.raises(tetcdt.MeshingError) as e:
        tetcdt.read(model).tetrahedralize("pS1")
    assert code == 1 and str(e.value) == msg
    assert isinstance(e.value, RuntimeError)


def test_switch_and_argument_errors(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match=r"-r \(reconstruct"):
        tetcdt.tetrahedralize(CUBE, cube_triangles(), "pr")
    with pytest.raises(ValueError, match="q"):
        tetcdt.tetrahedralize(CUBE, cube_triangles(), "pq1.414/80")
    with pytest.raises(ValueError, match="-d"):
        tetcdt.tetrahedralize(CUBE, cube_triangles(), "pd")
    with pytest.raises(ValueError, match="shape"):
        tetcdt.tetrahedralize(CUBE[:, :2], cube_triangles())
    with pytest.raises(ValueError, match="integer"):
        tetcdt.tetrahedralize(CUBE, cube_triangles().astype(float))
    with pytest.raises(ValueError, match="facet_markers"):
        tetcdt.tetrahedralize(CUBE, cube_triangles(), facet_markers=[1, 2])
    with pytest.raises(ValueError, match="regions"):
        tetcdt.tetrahedralize(CUBE, cube_triangles(), "pA", regions=[[0.5, 0.5, 0.5]])
    with pytest.raises(FileNotFoundError):
        tetcdt.read(tmp_path / "missing.off")
    m = tetcdt.tetrahedralize(CUBE, cube_triangles(), "p")
    with pytest.raises(OSError):
        m.write(tmp_path / "no-such-dir" / "out")


def test_warnings_are_python_warnings() -> None:
    # Two faces whose corners weld to two points are dropped, with a warning.
    pts = np.vstack([CUBE, CUBE[:1]])
    faces = np.vstack([cube_triangles(), [[0, 8, 1]]])
    with pytest.warns(UserWarning) as caught:
        tetcdt.tetrahedralize(pts, faces, "p")
    messages = [str(w.message) for w in caught]
    assert any("point 8 coincides with point 0" in m for m in messages), messages
    assert any("repeated corner" in m for m in messages), messages


def big_sphere(subdivisions: int) -> tuple[np.ndarray, np.ndarray]:
    """A subdivided icosahedron projected onto the unit sphere."""
    t = (1 + 5**0.5) / 2
    v = [[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t],
         [0, -1, -t], [0, 1, -t], [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]]
    f = [[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4],
         [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8],
         [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]]
    pts = [np.array(p, float) / np.linalg.norm(p) for p in v]

    def middle(mid: dict[tuple[int, int], int], a: int, b: int) -> int:
        key = (min(a, b), max(a, b))
        if key not in mid:
            p = pts[a] + pts[b]
            pts.append(p / np.linalg.norm(p))
            mid[key] = len(pts) - 1
        return mid[key]

    for _ in range(subdivisions):
        mid: dict[tuple[int, int], int] = {}
        f = [
            g
            for a, b, c in f
            for ab, bc, ca in [(middle(mid, a, b), middle(mid, b, c), middle(mid, c, a))]
            for g in ([a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca])
        ]
    return np.array(pts), np.array(f)


def test_meshing_releases_the_gil() -> None:
    pts, faces = big_sphere(5)
    times: list[float] = []
    stop = threading.Event()

    def tick() -> None:
        while not stop.is_set():
            times.append(time.perf_counter())

    counter = threading.Thread(target=tick)
    counter.start()
    try:
        while not times:
            time.sleep(0.001)
        m = tetcdt.tetrahedralize(pts, faces, "p")
    finally:
        stop.set()
        counter.join()
    meshing = m.stats["total_secs"]
    assert meshing > 0.02, "the model is too small to tell"
    # Holding the GIL through the library's call would stop the other thread for all
    # of it; released, the thread ticks on while the mesh is made.
    longest_pause = max(np.diff(times))
    assert longest_pause < meshing / 2, (longest_pause, meshing)


def test_to_meshio() -> None:
    meshio = pytest.importorskip("meshio")
    m = tetcdt.tetrahedralize(CUBE, cube_triangles(), "pq1.414A", regions=[[0.5] * 3 + [2]])
    mm = m.to_meshio()
    assert isinstance(mm, meshio.Mesh)
    np.testing.assert_array_equal(mm.points, m.points)
    np.testing.assert_array_equal(mm.cells_dict["tetra"], m.tets)
    np.testing.assert_array_equal(mm.cells_dict["triangle"], m.faces)
    assert set(mm.cell_data_dict["region"]["tetra"].tolist()) == {2.0}


def test_to_pyvista() -> None:
    pyvista = pytest.importorskip("pyvista")
    m = tetcdt.tetrahedralize(CUBE, cube_triangles(), "pq1.414")
    grid = m.to_pyvista()
    assert isinstance(grid, pyvista.UnstructuredGrid)
    assert grid.n_cells == len(m.tets) and grid.n_points == len(m.points)
    assert abs(grid.volume - 1.0) < 1e-12


def test_missing_optional_packages(monkeypatch: pytest.MonkeyPatch) -> None:
    m = tetcdt.tetrahedralize(CUBE, cube_triangles(), "p")
    monkeypatch.setitem(sys.modules, "meshio", None)
    monkeypatch.setitem(sys.modules, "pyvista", None)
    with pytest.raises(ImportError, match="pip install meshio"):
        m.to_meshio()
    with pytest.raises(ImportError, match="pip install pyvista"):
        m.to_pyvista()
