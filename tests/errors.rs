//! One test per kind of error: the exit code, and the message naming the file, the
//! elements (numbered as in the file) and, where it helps, coordinates. The broken
//! models are hand-made, in `data/broken/`. Every failed run must leave no output.
//!
//! Exit codes: 0 success, 1 meshing failed, 2 usage error, 3 invalid input, 4 I/O error.

use assert_cmd::Command;
use std::fs;
use std::path::{Path, PathBuf};

fn broken(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("data")
        .join("broken")
        .join(name)
}

/// The files in `dir`, sorted.
fn listing(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// Copies `data/broken/<name>` into a fresh directory and runs `tetcdt <args> <name>`
/// there. Returns (exit code, stdout, stderr, directory listing after the run).
fn run(name: &str, args: &[&str]) -> (i32, String, String, Vec<String>) {
    let dir = tempfile::tempdir().unwrap();
    fs::copy(broken(name), dir.path().join(name)).unwrap();
    let out = Command::cargo_bin("tetcdt")
        .unwrap()
        .current_dir(dir.path())
        .args(args)
        .arg(name)
        .timeout(std::time::Duration::from_secs(120))
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
        listing(dir.path()),
    )
}

/// A run that must fail with `code`, print every one of `wants`, and write nothing.
fn refused(name: &str, args: &[&str], code: i32, wants: &[&str]) {
    let (got, _, stderr, files) = run(name, args);
    assert_eq!(got, code, "{name}: {stderr}");
    assert!(stderr.starts_with("tetcdt: "), "{name}: {stderr}");
    for w in wants {
        assert!(stderr.contains(w), "{name}: {stderr:?} lacks {w:?}");
    }
    assert!(!stderr.contains("panicked") && !stderr.contains("internal error"));
    assert_eq!(files, [name], "{name}: a failed run must write nothing");
}

#[test]
fn malformed_files_exit_3_naming_file_and_line() {
    refused(
        "nan_coordinate.node",
        &["-Q"],
        3,
        &["nan_coordinate.node:5:", "point 3", "not a finite number"],
    );
    refused(
        "missing_points.smesh",
        &["-pQ"],
        3,
        &[
            "missing_points.smesh:5:",
            "unexpected end of file",
            "8 announced",
        ],
    );
    refused(
        "short_polygon.off",
        &["-pQ"],
        3,
        &["short_polygon.off:11:", "corner 3 of face 3"],
    );
    // A header count is never trusted for allocation: 4 billion vertices announced.
    refused(
        "huge_count.off",
        &["-pQ"],
        3,
        &["huge_count.off:5:", "4000000000 announced"],
    );
}

#[test]
fn out_of_range_index_exits_3() {
    refused(
        "index_out_of_range.poly",
        &["-pQ"],
        3,
        &[
            "index_out_of_range.poly:",
            "facet 3",
            "corner 9",
            "only 8 points",
        ],
    );
}

#[test]
fn coordinates_beyond_the_predicates_range_exit_3() {
    for args in [&["-pQ"][..], &["-Q"][..]] {
        refused(
            "huge_coordinate.off",
            args,
            3,
            &[
                "huge_coordinate.off: point 1 ",
                "out of the supported range",
                "1e300",
            ],
        );
    }
}

#[test]
fn repeated_vertex_exits_3() {
    refused(
        "repeated_vertex.poly",
        &["-pQ"],
        3,
        &[
            "repeated_vertex.poly: facet 4 (line 18), polygon 1",
            "vertex 3 is repeated (positions 2 and 4 of 5)",
        ],
    );
}

#[test]
fn collinear_polygon_exits_3_with_coordinates() {
    refused(
        "collinear_polygon.poly",
        &["-pQ"],
        3,
        &[
            "collinear_polygon.poly: facet 7 (line 25), polygon 1",
            "collinear",
            "9 (0.5, 0.5, 0.5)",
        ],
    );
}

#[test]
fn polygon_far_from_flat_exits_3() {
    refused(
        "twisted_facet.poly",
        &["-pQ"],
        3,
        &[
            "twisted_facet.poly: facet 2 (line 14), polygon 1 is not flat",
            "vertex 5 (0, 0, 1) is 1.179e-1 off the polygon's plane",
            "(at most 1% is accepted)",
        ],
    );
}

/// Runs `tetcdt ARGS` on a copy of `data/MODEL` whose first `from` becomes `to` (one of
/// the fuzzer's mutations); returns the exit code and stderr.
fn mutated(model: &str, from: &str, to: &str, args: &[&str]) -> (Option<i32>, String) {
    mutated_traced(model, from, to, args, false)
}

/// Asserts that a run (exit `code`, `stderr`) either gave a certified mesh (exit 0) or
/// refused to give one because the mesh it made failed the certifier (exit 1): such
/// far-flung models leave flat tets on their facets, and exit 0 would be a lie.
fn certified_or_refused(code: Option<i32>, stderr: &str, what: &str) {
    if code == Some(0) {
        return;
    }
    assert_eq!(code, Some(1), "{what}: {stderr}");
    assert!(
        stderr.contains("is not a valid CDT of the PLC, so none is written"),
        "{what}: {stderr}"
    );
    assert!(!stderr.contains("internal error"), "{what}: {stderr}");
}

/// [`mutated`], with the mesher's trace (`TETCDT_DEBUG`) on stderr if `trace`.
fn mutated_traced(
    model: &str,
    from: &str,
    to: &str,
    args: &[&str],
    trace: bool,
) -> (Option<i32>, String) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("data")
        .join(model);
    let text = fs::read_to_string(&path).unwrap();
    assert!(text.contains(from), "{model} has no {from:?}");
    let name = path.file_name().unwrap();
    let dir = tempfile::tempdir().unwrap();
    fs::write(dir.path().join(name), text.replacen(from, to, 1)).unwrap();
    let mut cmd = Command::cargo_bin("tetcdt").unwrap();
    if trace {
        cmd.env("TETCDT_DEBUG", "1");
    } else {
        cmd.env_remove("TETCDT_DEBUG");
    }
    let out = cmd
        .current_dir(dir.path())
        .args(args)
        .arg(name)
        // A hang guard, far above any of these runs (killed: no exit code).
        .timeout(std::time::Duration::from_secs(30))
        .output()
        .unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Found by `tests/fuzz.rs`: a corner of `fig4_split.poly` moved 30 units away twists
/// three quadrilaterals, which made cavity insertion fail with an internal error.
#[test]
fn fuzz_regression_twisted_quads_are_refused() {
    let (code, stderr) = mutated(
        "plc/fig4_split.poly",
        "\n5 1 -1 -1e-05\n",
        "\n5 1 -31 -1e-05\n",
        &["-pQ"],
    );
    assert_eq!(code, Some(3), "{stderr}");
    assert!(stderr.contains("is not flat"), "{stderr}");
}

/// Found by `tests/fuzz.rs`: `mpi.off` with one vertex moved 2.5 units off the three
/// polygons through it (of a model 20 units wide). Around such a polygon, far from flat,
/// the cavity code told the sides of a widened cavity apart wrongly, and a side's faces
/// did not close it: an internal error. That side now asks for a Steiner point, like the
/// cavity code's other failures on polygons that are not flat; here they never settle,
/// which is a meshing failure with its reason (TetGen's mesh of it leaves 10 boundary
/// faces on no polygon).
#[test]
fn fuzz_regression_a_cavity_side_left_open_asks_for_a_point() {
    for switches in [["-pQ"], ["-pQF"]] {
        let (code, stderr) = mutated(
            "plc/mpi.off",
            "\n-6.02406 -10.012 4.01604\n",
            "\n-6.02406 -10.012 1.5\n",
            &switches,
        );
        assert_eq!(code, Some(1), "{stderr}");
        assert!(stderr.contains("not flat still conflict"), "{stderr}");
        assert!(!stderr.contains("internal error"), "{stderr}");
    }
}

/// Found by `tests/fuzz.rs`: `cube.ply` with an element of no properties announced
/// 24,294,967,296 times; the reader counted through its empty records for minutes.
#[test]
fn fuzz_regression_empty_ply_elements_are_not_counted_through() {
    let (code, stderr) = mutated(
        "formats/cube.ply",
        "element edge 2\n",
        "element edge 24294967296\nelement edge 2\n",
        &["-pQ", "--check"],
    );
    assert_eq!(code, Some(0), "{stderr}");
}

/// Found by `tests/fuzz.rs`: `star.off` with one vertex moved 4.3e9 units away needs
/// free points, and one was located in a hull tet, whose ghost vertex the orientation
/// check of its walled cavity read.
#[test]
fn fuzz_regression_free_point_outside_the_hull() {
    let (code, stderr) = mutated(
        "plc/star.off",
        "\n-0.125 -0.125 -0.125\n",
        "\n-4294967295 -0.125 -0.125\n",
        &["-pQ", "--check"],
    );
    certified_or_refused(code, &stderr, "");
}

/// Found by `tests/fuzz.rs`: `collinear_polygon.poly` with a vertex moved 4.3e9 units
/// away gives sliver polygons whose Steiner points never settle, and each restart cost
/// more exact predicates than the last (over a minute in all); the restarts' work is now
/// bounded.
#[test]
fn fuzz_regression_far_vertex_restarts_are_bounded() {
    let (code, stderr) = mutated(
        "broken/collinear_polygon.poly",
        "\n7 1 1 1\n",
        "\n7 4294967295 1 1\n",
        &["-pQ"],
    );
    assert_eq!(code, Some(1), "{stderr}");
    assert!(stderr.contains("not flat"), "{stderr}");
}

/// Found by `tests/fuzz.rs`: `star.off` with a vertex moved 1.8e19 units away made the
/// search for free points combine search directions without end until memory ran out.
/// It then failed at the -S bound; now that free points go into the CDT by flips
/// instead of restarting the construction, it meshes.
#[test]
fn fuzz_regression_free_point_search_is_bounded() {
    let (code, stderr) = mutated(
        "plc/star.off",
        "\n0.125 -0.125 0.125\n",
        "\n18446744073709551616 -0.125 0.125\n",
        &["-pQS20000", "--check"],
    );
    certified_or_refused(code, &stderr, "");
}

/// Found by `tests/fuzz.rs`: `star.off` with a vertex moved 1.8e19 units up made the
/// walk that locates a candidate free point cycle for ever in the (non-Delaunay) CDT;
/// the walk is now bounded, with a scan of every tet past the bound.
#[test]
fn fuzz_regression_point_location_in_the_cdt_ends() {
    let (code, stderr) = mutated(
        "plc/star.off",
        "\n0.125 -0.125 0.125\n",
        "\n0.125 -0.125 18446744073709551616\n",
        &["-pQ", "--check"],
    );
    certified_or_refused(code, &stderr, "");
}

/// Found by `tests/fuzz.rs`: a prism with one vertex moved 1e20 units down. Updates of
/// the CDT in place of restarts (subsegment splits) closed in on its Steiner points
/// without settling them, and the construction then gave up where restarts alone
/// succeed (and with unbounded updates, ran for over a minute). The updates are now
/// bounded, and a construction that fails after them is done again without them.
#[test]
fn fuzz_regression_updates_in_place_fall_back_to_restarts() {
    let (code, stderr) = mutated(
        "plc/prism_n8_d1e-5_s1000.poly",
        "\n0 1500 -500 -250.00675292370607\n",
        "\n0 1500 -500 -99999999999999999999\n",
        &["-pQ", "--check"],
    );
    certified_or_refused(code, &stderr, "");
}

/// Found by `tests/fuzz.rs` in CI: one corner of a 40-gon prism moved 1.8e19 away (the
/// other coordinates are within 0.5) makes every flip-time comparison of `-F` need exact
/// arithmetic on long expansions; the restarts that do not settle the polygons then ran
/// for over a minute, since only crossing tests counted as their work. Exact comparisons
/// now count too (and products are compressed), and the run ends within seconds.
#[test]
fn fuzz_regression_far_corner_ends_flip_insertion_in_bounded_work() {
    refused_at_the_restarts_bound(
        "plc/prism_n40_d1e-5_s1.poly",
        "\n6 0.29389262614623657 0.4045084971874737 -0.5000067566867479\n",
        "\n6 0.29389262614623657 0.4045084971874737 -18446744073709551616\n",
    );
}

/// Asserts that both algorithms refuse the mutated model (see [`mutated`]) at the bound
/// on restarts, within the hang guard.
fn refused_at_the_restarts_bound(model: &str, from: &str, to: &str) {
    for algo in ["-pQF", "-pQ"] {
        let (code, stderr) = mutated(model, from, to, &[algo]);
        assert_eq!(code, Some(1), "{algo}: {stderr}");
        assert!(
            stderr.contains("polygons that are not flat still conflict after"),
            "{algo}: {stderr}"
        );
    }
}

/// Found by `tests/fuzz.rs`: `cosph_hull.poly` with a vertex moved 1.8e20 away. Every
/// orientation around it needs adaptive arithmetic, and after two restarts one
/// construction spent close to a minute (`-F`; 20 s with `-C`) on the crossing tests of
/// single regions, work that the bound on restarts saw only when the construction
/// ended. A construction now stops where that bound would end the restarts.
#[test]
fn fuzz_regression_one_construction_stops_at_the_restarts_bound() {
    refused_at_the_restarts_bound(
        "plc/cosph_hull.poly",
        "\n26 1 -1 -5\n",
        "\n26 1 -1 -184467440737095516165\n",
    );
}

/// Found by a search like the fuzzer's: a corner of the 40-gon prism moved 3.4e38 away.
/// The first construction updates the CDT in place, and those updates cost more than the
/// bound on restarts allows; they stop there (the trace says so), and the constructions
/// start over without updates (0.8 s in all; 2.8 s before).
#[test]
fn updates_in_place_of_the_first_construction_stop_at_the_restarts_bound() {
    let (code, stderr) = mutated_traced(
        "plc/prism_n40_d1e-5_s1.poly",
        "\n70 0 -0.49999 0.5000072385547387\n",
        "\n70 0 -0.49999 3.4e38\n",
        &["-pQF"],
        true,
    );
    assert_eq!(code, Some(1), "{stderr}");
    assert!(
        stderr.contains("restart 0 without updates in place: the construction passed its bound"),
        "{stderr}"
    );
    assert!(
        stderr.contains("polygons that are not flat still conflict after"),
        "{stderr}"
    );
}

/// Found by `tests/fuzz.rs`: a space inside a coordinate of `anchor.off` shifts every
/// later coordinate by one, so the model gets a vertex 135,538 units out of a shape of
/// size 1. The search for free points then walked to hundreds of thousands of candidate
/// places, thousands of steps each, for two minutes; it now stops past a bound on its
/// work, and the run ends in about a second.
#[test]
fn fuzz_regression_free_point_walks_are_bounded() {
    for algo in ["-p", "-pF"] {
        let (code, stderr) = mutated(
            "nonflat/anchor.off",
            "\n-0.345 0.135538 0.0217069\n",
            "\n-0.345 0. 135538 0.0217069\n",
            &[algo, "--check"],
        );
        certified_or_refused(code, &stderr, algo);
    }
}

#[test]
fn duplicate_facet_exits_3() {
    refused(
        "duplicate_facet.poly",
        &["-pQ"],
        3,
        &[
            "1 duplicate polygon(s)",
            "facet 2 (line 14), polygon 1 and facet 7 (line 24), polygon 1",
        ],
    );
}

#[test]
fn duplicate_triangle_exits_3() {
    // The last triangle repeats the second one, rotated and reversed.
    let (code, stderr) = mutated("examples/tet.obj", "f -4 -1 -2", "f 4 2 1", &["-pQ"]);
    assert_eq!(code, Some(3), "{stderr}");
    assert!(stderr.contains("1 duplicate polygon(s)"), "{stderr}");
    assert!(stderr.contains("polygon 1 and facet 4"), "{stderr}");
}

#[test]
fn coincident_points_are_merged_with_a_warning() {
    let (code, _, stderr, files) = run("coincident_points.poly", &["-p", "--check"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stderr.contains("Warning: point 9 coincides with point 5 at (0, 0, 1)"),
        "{stderr}"
    );
    assert!(files.contains(&"coincident_points.1.ele".to_string()));
}

#[test]
fn open_surface_exits_3_listing_boundary_edges() {
    refused(
        "open_box.poly",
        &["-pQ"],
        3,
        &[
            "open_box.poly: the meshed domain would be empty",
            "not closed: 4 boundary edge(s)",
            "5 (0, 0, 1) – 6 (1, 0, 1)",
        ],
    );
    // With -c the hull is kept, and the open box is a valid PLC.
    let (code, _, stderr, _) = run("open_box.poly", &["-pcQ", "--check"]);
    assert_eq!(code, 0, "{stderr}");
}

#[test]
fn open_facet_inside_a_closed_one_is_fine() {
    let (code, _, stderr, _) = run("dangling_facet_inside.poly", &["-pQ", "--check"]);
    assert_eq!(code, 0, "{stderr}");
}

#[test]
fn facet_dangling_outside_is_refused_naming_its_free_edges() {
    refused(
        "dangling_facet_outside.poly",
        &["-pQ"],
        3,
        &[
            "dangling_facet_outside.poly: 2 polygon edge(s) lie outside the meshed domain, \
             first (5, 9)",
            "the surface is not closed",
            "2 boundary edge(s)",
            "6 (1, 0, 1) – 9 (0.5, -0.5, 1.5) of facet 7 (line",
            "-c keeps the convex hull",
        ],
    );
    // With the hull kept, the fin is inside the domain and stays.
    let (code, _, stderr, _) = run("dangling_facet_outside.poly", &["-pcQ", "--check"]);
    assert_eq!(code, 0, "{stderr}");
}

#[test]
fn facet_in_a_hole_is_refused_naming_the_hole() {
    refused(
        "fin_in_hole.poly",
        &["-pQ"],
        3,
        &[
            "fin_in_hole.poly: 3 polygon edge(s) lie outside the meshed domain, first (17, 18)",
            "dangle outside the enclosed volume or in a hole",
            "17 (1.5, 1.5, 1.5) – 18 (2.5, 1.5, 1.5) of facet 13 (line",
            "the hole point; -c keeps the exterior, not the holes",
        ],
    );
    // -c keeps the exterior but still carves the hole.
    let (code, _, stderr, _) = run("fin_in_hole.poly", &["-pcQ"]);
    assert_eq!(code, 3, "{stderr}");
}

#[test]
fn intersecting_facets_exit_3_naming_the_pairs() {
    refused(
        "crossing_facets.poly",
        &["-pQ"],
        3,
        &[
            "1 pair(s) of facets intersect",
            "facet 2 (line 17) and facet 7 (line 27) (crossing)",
            "(9, 10, 11)",
        ],
    );
    refused(
        "touching_facets.poly",
        &["-pQ"],
        3,
        &["facet 2 (line 18) and facet 7 (line 28) (touching)"],
    );
    refused(
        "overlapping_facets.off",
        &["-pQ"],
        3,
        &[
            "2 pair(s) of facets intersect",
            "facet 0 (line 11) and facet 4 (line 15) (coplanar overlap)",
        ],
    );
}

/// Facets that cross only because two vertices differ by a rounding error (as in
/// gmsh's `object.stl`): the message names the two vertices.
#[test]
fn crossing_at_nearly_coincident_vertices_names_them() {
    refused(
        "near_coincident.off",
        &["-pQ"],
        3,
        &[
            "6 pair(s) of facets intersect",
            "they meet at nearly coincident vertices",
            "vertices 0 (0, 0, 0) and 4 (",
            "are only 1.73e-17 apart",
        ],
    );
    // Crossings with no such vertices say nothing of them.
    let (_, _, stderr, _) = run("crossing_facets.poly", &["-pQ"]);
    assert!(!stderr.contains("nearly coincident"), "{stderr}");
}

#[test]
fn segment_through_a_facet_exits_3() {
    refused(
        "crossing_segment.poly",
        &["-pQ"],
        3,
        &[
            "1 segment(s) meet a facet other than at a shared vertex",
            "segment (9, 10) of facet 7 (line 26) and facet 2 (line 16) (crossing)",
        ],
    );
}

#[test]
fn point_on_a_facet_that_does_not_list_it_exits_3() {
    refused(
        "stray_point.poly",
        &["-pQ"],
        3,
        &[
            "stray_point.poly: 1 point(s) lie on a facet without being among its vertices",
            "point 12 (0.5, 0.5, 1) lies on facet 2 (line 18)",
        ],
    );
}

#[test]
fn detect_switch_reports_and_writes_the_triangles() {
    let (code, stdout, stderr, files) = run("crossing_facets.poly", &["-d"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stdout.contains("facet 2 (line 17) and facet 7 (line 27) (crossing)"),
        "{stdout}"
    );
    assert!(
        stdout.contains("Found 1 pair(s) of intersecting facets."),
        "{stdout}"
    );
    assert_eq!(
        files,
        [
            "crossing_facets.1.face",
            "crossing_facets.1.node",
            "crossing_facets.poly"
        ]
    );
    // The .face file: the two triangles, numbered like the input (from 1), with markers.
    let dir = tempfile::tempdir().unwrap();
    fs::copy(broken("crossing_facets.poly"), dir.path().join("m.poly")).unwrap();
    Command::cargo_bin("tetcdt")
        .unwrap()
        .current_dir(dir.path())
        .args(["-dQ", "m.poly"])
        .assert()
        .success();
    let face = fs::read_to_string(dir.path().join("m.1.face")).unwrap();
    let rows: Vec<Vec<&str>> = face
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| l.split_whitespace().collect())
        .collect();
    assert_eq!(rows[0], ["2", "1"]);
    assert_eq!(rows[1][..4], ["1", "5", "6", "7"]);
    assert_eq!(rows[2][..4], ["2", "9", "10", "11"]);
    let node = fs::read_to_string(dir.path().join("m.1.node")).unwrap();
    assert!(node.starts_with("11  3  0  0"), "{node}");

    // No intersections: said so, nothing written, exit 0 (as TetGen does).
    let (code, stdout, stderr, files) = run("dangling_facet_inside.poly", &["-d"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains("No faces are intersecting."), "{stdout}");
    assert_eq!(files, ["dangling_facet_inside.poly"]);
}

#[test]
fn steiner_bound_exits_1_with_the_reason() {
    let model = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("data")
        .join("plc")
        .join("schonhardt.off");
    let dir = tempfile::tempdir().unwrap();
    fs::copy(&model, dir.path().join("s.off")).unwrap();
    let out = Command::cargo_bin("tetcdt")
        .unwrap()
        .current_dir(dir.path())
        .args(["-pQS1", "s.off"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("more than 1 Steiner points"), "{stderr}");
    assert!(stderr.contains("-S"), "{stderr}");
    assert_eq!(listing(dir.path()), ["s.off"]);
    // Steiner points on polygons that are not flat count against the same bound.
    fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("data/plc/prism_n40_d1e-8_s1.poly"),
        dir.path().join("p.poly"),
    )
    .unwrap();
    let out = Command::cargo_bin("tetcdt")
        .unwrap()
        .current_dir(dir.path())
        .args(["-pQS1", "p.poly"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("need more than 1 Steiner points (the -S limit)"),
        "{stderr}"
    );
    assert_eq!(listing(dir.path()), ["p.poly", "s.off"]);
    // With room for them, the same models mesh.
    Command::cargo_bin("tetcdt")
        .unwrap()
        .current_dir(dir.path())
        .args(["-pQS100", "p.poly"])
        .assert()
        .success();
    Command::cargo_bin("tetcdt")
        .unwrap()
        .current_dir(dir.path())
        .args(["-pQS100", "s.off"])
        .assert()
        .success();
}

#[test]
fn usage_and_io_errors() {
    refused("crossing_facets.poly", &["-pr"], 2, &["-r (reconstruct"]);
    refused(
        "crossing_facets.poly",
        &["-q"],
        2,
        &["-q (quality mesh generation) needs -p"],
    );
    refused(
        "crossing_facets.poly",
        &["-d", "--check"],
        2,
        &["-d only detects", "--check"],
    );
    let dir = tempfile::tempdir().unwrap();
    let out = Command::cargo_bin("tetcdt")
        .unwrap()
        .current_dir(dir.path())
        .args(["-pQ", "nothing.poly"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(4));
    assert!(String::from_utf8_lossy(&out.stderr).contains("nothing.poly"));
}

/// A failed run keeps the outputs of an earlier successful one intact and leaves no
/// temporary files: outputs are written under temporary names and renamed at the end,
/// and the input is checked before anything is written.
#[test]
fn failed_run_keeps_earlier_outputs() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fs::copy(broken("dangling_facet_inside.poly"), d.join("m.poly")).unwrap();
    let ok = Command::cargo_bin("tetcdt")
        .unwrap()
        .current_dir(d)
        .args(["-pQ", "m.poly"])
        .output()
        .unwrap();
    assert_eq!(ok.status.code(), Some(0));
    let before: Vec<(String, Vec<u8>)> = listing(d)
        .into_iter()
        .map(|f| (f.clone(), fs::read(d.join(&f)).unwrap()))
        .collect();
    assert_eq!(before.len(), 5, "{:?}", listing(d));
    for (bad, code) in [
        ("crossing_facets.poly", 3),
        ("open_box.poly", 3),
        ("repeated_vertex.poly", 3),
    ] {
        fs::copy(broken(bad), d.join("m.poly")).unwrap();
        let out = Command::cargo_bin("tetcdt")
            .unwrap()
            .current_dir(d)
            .args(["-pQ", "m.poly"])
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(code), "{bad}");
        for (f, bytes) in &before {
            if f != "m.poly" {
                assert_eq!(&fs::read(d.join(f)).unwrap(), bytes, "{bad} changed {f}");
            }
        }
        assert_eq!(listing(d).len(), 5, "{bad}: {:?}", listing(d));
    }
    // The Steiner bound is hit after meshing started: still nothing is touched.
    fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("data/plc/schonhardt.off"),
        d.join("m.off"),
    )
    .unwrap();
    let out = Command::cargo_bin("tetcdt")
        .unwrap()
        .current_dir(d)
        .args(["-pQS1", "-o", "m.1", "m.off"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    for (f, bytes) in &before {
        if f != "m.poly" {
            assert_eq!(&fs::read(d.join(f)).unwrap(), bytes, "-S1 changed {f}");
        }
    }
    assert_eq!(listing(d).len(), 6, "{:?}", listing(d));
}

/// Found by `tests/fuzz.rs`: a vertex of `prism_n40_d1e-5_s1.poly` moved 4.3e9 units out
/// makes two side quads into needles billions of times longer than wide, whose sides
/// rounding confuses: a cavity grew around its polygon, an internal error. Such a
/// region now asks for a Steiner point on the polygon, and the restarts' bound ends it
/// with a reason (TetGen aborts on it too).
#[test]
fn fuzz_regression_cavity_around_a_needle_polygon() {
    let (code, stderr) = mutated(
        "plc/prism_n40_d1e-5_s1.poly",
        "\n11 -0.0782172325201153 0.4938441702975689 ",
        "\n11 -0.0782172325201153 4294967295 ",
        &["-pQ"],
    );
    assert_eq!(code, Some(1), "{stderr}");
    assert!(stderr.contains("still conflict"), "{stderr}");
    assert!(!stderr.contains("internal error"), "{stderr}");
}

/// Found by fuzzing with `-F`: `mpi.off` with a vertex moved 1.2e21 units out. A
/// Steiner point's cavity in the CDT (which is not Delaunay near its constraints) was
/// pinched, two parts meeting along an edge only; filling it glued the new tets wrongly,
/// and a later facet failed with an internal error. Such a cavity is now refused like
/// one that wraps around a subface, and the run ends as with `-C`.
#[test]
fn fuzz_regression_pinched_cavity_is_refused() {
    let (code, stderr) = mutated(
        "nonflat/mpi.off",
        "\n-10 10 10\n",
        "\n-1184467440737095516160 10 10\n",
        &["-pQF"],
    );
    assert!(!stderr.contains("internal error"), "{stderr}");
    assert!(
        matches!(code, Some(0) | Some(1) | Some(3)),
        "{code:?}: {stderr}"
    );
}

/// A triangle with three distinct but collinear corners is a crack or a T-junction, not
/// a degenerate triangle to drop: the input is refused, naming it.
#[test]
fn collinear_triangle_in_an_stl_exits_3() {
    refused(
        "collinear_triangle.stl",
        &["-pQ"],
        3,
        &["facet 5 (line 30), polygon 1: its 3 vertices are collinear"],
    );
}

/// Dropping a triangle with a repeated corner never closes a surface: one that was open
/// without it is refused as open.
#[test]
fn surface_open_once_degenerate_triangles_are_dropped_exits_3() {
    let (code, _, stderr, files) = run("open_after_drop.off", &["-p"]);
    assert_eq!(code, 3, "{stderr}");
    assert!(
        stderr.contains("1 facet(s) with a repeated corner"),
        "{stderr}"
    );
    assert!(stderr.contains("not closed"), "{stderr}");
    assert_eq!(files, ["open_after_drop.off"]);
}
