//! Tests of the STL, PLY and Medit readers through `read_plc` and the command, and of
//! the `-k` (VTK) and `-g` (Medit) writers. The models are in `data/formats/`.

use assert_cmd::Command;
use std::fs;
use std::path::{Path, PathBuf};
use tetcdt::io::read_plc;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("data")
        .join(name)
}

fn tetcdt() -> Command {
    Command::cargo_bin("tetcdt").unwrap()
}

/// The lines of a file without `#` comments and blank lines, split into tokens.
fn records(path: &Path) -> Vec<Vec<String>> {
    fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .lines()
        .map(|l| l.split('#').next().unwrap_or(""))
        .filter(|l| !l.trim().is_empty())
        .map(|l| l.split_whitespace().map(str::to_string).collect())
        .collect()
}

fn num(s: &str) -> f64 {
    s.parse().unwrap_or_else(|_| panic!("not a number: {s}"))
}

fn int(s: &str) -> i64 {
    s.parse().unwrap_or_else(|_| panic!("not an integer: {s}"))
}

/// Every model of `data/formats/`, its equivalent, and the first index it numbers from.
const MODELS: &[(&str, &str, usize)] = &[
    ("formats/cube.stl", "formats/cube_tri.off", 1),
    ("formats/cube.bin.stl", "formats/cube_tri.off", 1),
    ("formats/cube.ply", "examples/cube.off", 0),
    ("formats/cube_le.ply", "examples/cube.off", 0),
    ("formats/cube_be.ply", "examples/cube.off", 0),
    ("formats/cube.mesh", "examples/cube.poly", 1),
];

#[test]
fn each_format_reads_to_the_plc_of_its_equivalent() {
    for &(model, equivalent, first) in MODELS {
        let a = read_plc(&data(model)).unwrap_or_else(|e| panic!("{model}: {e}"));
        let b = read_plc(&data(equivalent)).unwrap();
        assert_eq!(a.points, b.points, "{model}");
        assert_eq!(a.facets.len(), b.facets.len(), "{model}");
        for (fa, fb) in a.facets.iter().zip(&b.facets) {
            assert_eq!(fa.polygons, fb.polygons, "{model}");
            assert_eq!(fa.marker, fb.marker, "{model}");
            assert!(fa.holes.is_empty());
        }
        assert_eq!(a.first_index, first, "{model}");
        assert!(a.holes.is_empty() && a.regions.is_empty(), "{model}");
        assert_eq!(a.source, data(model));
    }
}

/// Meshes `input` with `switches` into `dir/name`; returns the output prefix.
fn mesh(dir: &Path, name: &str, input: &Path, switches: &str) -> PathBuf {
    let prefix = dir.join(name);
    tetcdt()
        .arg(switches)
        .arg("--check")
        .arg("-o")
        .arg(&prefix)
        .arg(input)
        .assert()
        .success();
    prefix
}

fn with_ext(prefix: &Path, ext: &str) -> PathBuf {
    PathBuf::from(format!("{}.{ext}", prefix.display()))
}

#[test]
fn each_format_meshes_as_its_equivalent_and_passes_check() {
    let dir = tempfile::tempdir().unwrap();
    for (k, &(model, equivalent, _)) in MODELS.iter().enumerate() {
        let a = mesh(dir.path(), &format!("a{k}"), &data(model), "-pQz");
        let b = mesh(dir.path(), &format!("b{k}"), &data(equivalent), "-pQz");
        for ext in ["node", "ele", "face", "edge"] {
            assert_eq!(
                records(&with_ext(&a, ext)),
                records(&with_ext(&b, ext)),
                "{model}: .{ext} differs from that of {equivalent}"
            );
        }
    }
}

/// Runs tetcdt on `input` in `dir` (where output would go) and returns the stderr,
/// asserting exit code 3 and that no file was written beside the input.
fn refused(dir: &Path, input: &Path) -> String {
    let before = fs::read_dir(dir).unwrap().count();
    let out = tetcdt()
        .current_dir(dir)
        .arg("-pQ")
        .arg(input)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(3), "{}: {err}", input.display());
    assert_eq!(fs::read_dir(dir).unwrap().count(), before, "partial output");
    err
}

#[test]
fn bad_inputs_exit_3_naming_file_and_place() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let put = |name: &str, bytes: &[u8]| {
        let p = d.join(name);
        fs::write(&p, bytes).unwrap();
        p
    };

    // A binary STL cut short in its last triangle.
    let mut stl = fs::read(data("formats/cube.bin.stl")).unwrap();
    stl.truncate(stl.len() - 7);
    let err = refused(d, &put("cut.stl", &stl));
    assert!(
        err.contains("cut.stl: binary STL truncated")
            && err.contains("triangle 11 (byte offset 634) is incomplete"),
        "{err}"
    );

    // A non-finite coordinate in an ASCII STL and in a binary STL.
    let text = fs::read_to_string(data("formats/cube.stl")).unwrap();
    let bad = text.replacen(
        "vertex 1.000000e+00 1.000000e+00 0.000000e+00",
        "vertex 1 1e999 0",
        1,
    );
    let err = refused(d, &put("inf.stl", bad.as_bytes()));
    assert!(
        err.contains(
            "inf.stl:6: the y coordinate of corner 2 of triangle 0 is not a finite number: `1e999`"
        ),
        "{err}"
    );
    let mut stl = fs::read(data("formats/cube.bin.stl")).unwrap();
    // Triangle 1, corner 0, z coordinate.
    let at = 84 + 50 + 12 + 8;
    stl[at..at + 4].copy_from_slice(&f32::NAN.to_le_bytes());
    let err = refused(d, &put("nan.stl", &stl));
    assert!(
        err.contains("nan.stl: triangle 1 (byte offset 134): the z coordinate of corner 0 is not a finite number"),
        "{err}"
    );

    // PLY: a bad header, a count the file cannot hold, a vertex index out of range.
    let ply = fs::read_to_string(data("formats/cube.ply")).unwrap();
    let err = refused(
        d,
        &put(
            "hdr.ply",
            ply.replace("property float ny", "property flot ny")
                .as_bytes(),
        ),
    );
    assert!(
        err.contains("hdr.ply:9: unknown property type `flot`"),
        "{err}"
    );
    let err = refused(
        d,
        &put("idx.ply", ply.replace("4 4 5 6 7", "4 4 5 6 8").as_bytes()),
    );
    assert!(
        err.contains(
            "idx.ply:26: face 1 has corner 8, but there are only 8 vertices (numbered from 0)"
        ),
        "{err}"
    );
    let le = fs::read(data("formats/cube_le.ply")).unwrap();
    let end = le.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
    let head = String::from_utf8(le[..end].to_vec()).unwrap();
    let mut long = head
        .replace("element face 6", "element face 600000")
        .into_bytes();
    long.extend(&le[end..]);
    let err = refused(d, &put("count.ply", &long));
    assert!(
        err.contains("count.ply: the header announces 600000 `face` elements"),
        "{err}"
    );
    let err = refused(
        d,
        &put(
            "nan.ply",
            ply.replacen("0 0 0 0 0 1", "0 nan 0 0 0 1", 1).as_bytes(),
        ),
    );
    assert!(
        err.contains("nan.ply:17: the y coordinate of vertex 0 is not a finite number: `nan`"),
        "{err}"
    );

    // Medit: a corner out of range, a non-finite coordinate, binary .meshb.
    let mesh = fs::read_to_string(data("formats/cube.mesh")).unwrap();
    let err = refused(
        d,
        &put(
            "idx.mesh",
            mesh.replace("2 3 7 6  4", "2 3 9 6  4").as_bytes(),
        ),
    );
    assert!(
        err.contains("idx.mesh:32: quadrilateral 4 has corner 9, but there are only 8 vertices (numbered from 1)"),
        "{err}"
    );
    let err = refused(
        d,
        &put(
            "inf.mesh",
            mesh.replace("1 1 1  0", "1 inf 1  0").as_bytes(),
        ),
    );
    assert!(
        err.contains("inf.mesh:15: the y coordinate of vertex 7 (7 of 8 announced on line 8) is not a finite number: `inf`"),
        "{err}"
    );
    let err = refused(d, &put("cube.meshb", b"\x01\x00\x00\x00"));
    assert!(
        err.contains("cube.meshb: binary Medit files (.meshb) are not supported"),
        "{err}"
    );
}

/// The nodes, tets (0-based) and `.face` records of a run's output.
struct Out {
    nodes: Vec<[f64; 3]>,
    tets: Vec<[i64; 4]>,
    attrs: Vec<f64>,
    faces: Vec<([i64; 3], i64)>,
}

fn read_out(prefix: &Path) -> Out {
    let node = records(&with_ext(prefix, "node"));
    let base = int(&node[1][0]);
    let nodes = node[1..]
        .iter()
        .map(|r| [num(&r[1]), num(&r[2]), num(&r[3])])
        .collect();
    let ele = records(&with_ext(prefix, "ele"));
    let tets = ele[1..]
        .iter()
        .map(|r| [1, 2, 3, 4].map(|k| int(&r[k]) - base))
        .collect();
    let attrs = ele[1..]
        .iter()
        .filter(|r| r.len() > 5)
        .map(|r| num(&r[5]))
        .collect();
    let face = records(&with_ext(prefix, "face"));
    let faces = face[1..]
        .iter()
        .map(|r| {
            (
                [1, 2, 3].map(|k| int(&r[k]) - base),
                r.get(4).map_or(0, |m| int(m)),
            )
        })
        .collect();
    Out {
        nodes,
        tets,
        attrs,
        faces,
    }
}

fn volume6(p: &[[f64; 3]], t: [i64; 4]) -> f64 {
    let [a, b, c, d] = t.map(|i| p[i as usize]);
    let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    let w = [d[0] - a[0], d[1] - a[1], d[2] - a[2]];
    u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
        + u[2] * (v[0] * w[1] - v[1] * w[0])
}

/// Checks the `.vtk` file against the `.node`/`.ele` files.
fn check_vtk(prefix: &Path, out: &Out) {
    let vtk = records(&with_ext(prefix, "vtk"));
    let text = fs::read_to_string(with_ext(prefix, "vtk")).unwrap();
    assert!(text.starts_with("# vtk DataFile Version 2.0\n"));
    assert_eq!(
        vtk[1..3],
        [vec!["ASCII"], vec!["DATASET", "UNSTRUCTURED_GRID"]]
    );
    let n = out.nodes.len();
    assert_eq!(vtk[3], ["POINTS", &n.to_string(), "double"]);
    let points: Vec<[f64; 3]> = vtk[4..4 + n]
        .iter()
        .map(|r| [num(&r[0]), num(&r[1]), num(&r[2])])
        .collect();
    assert_eq!(points, out.nodes);
    let m = out.tets.len();
    let at = 4 + n;
    assert_eq!(vtk[at], ["CELLS", &m.to_string(), &(5 * m).to_string()]);
    let cells: Vec<[i64; 4]> = vtk[at + 1..at + 1 + m]
        .iter()
        .map(|r| {
            assert_eq!(r[0], "4");
            [1, 2, 3, 4].map(|k| int(&r[k]))
        })
        .collect();
    assert_eq!(cells, out.tets);
    // VTK_TETRA: the fourth point lies on the side the first three face counterclockwise.
    assert!(cells.iter().all(|&c| volume6(&points, c) > 0.0));
    let at = at + 1 + m;
    assert_eq!(vtk[at], ["CELL_TYPES", &m.to_string()]);
    assert!(vtk[at + 1..at + 1 + m].iter().all(|r| r == &["10"]));
    let rest = &vtk[at + 1 + m..];
    if out.attrs.is_empty() {
        assert!(rest.is_empty(), "{rest:?}");
    } else {
        assert_eq!(rest[0], ["CELL_DATA", &m.to_string()]);
        assert_eq!(rest[1], ["SCALARS", "region", "double", "1"]);
        assert_eq!(rest[2], ["LOOKUP_TABLE", "default"]);
        let values: Vec<f64> = rest[3..].iter().map(|r| num(&r[0])).collect();
        assert_eq!(values, out.attrs);
    }
}

/// Checks the Medit `.mesh` file against the `.node`/`.ele`/`.face` files.
fn check_medit(prefix: &Path, out: &Out, plc: bool) {
    let mesh = records(&with_ext(prefix, "mesh"));
    assert_eq!(mesh[0], ["MeshVersionFormatted", "1"]);
    assert_eq!(mesh[1], ["Dimension", "3"]);
    assert_eq!(mesh[2], ["Vertices"]);
    let n = out.nodes.len();
    assert_eq!(int(&mesh[3][0]), n as i64);
    let points: Vec<[f64; 3]> = mesh[4..4 + n]
        .iter()
        .map(|r| [num(&r[0]), num(&r[1]), num(&r[2])])
        .collect();
    assert_eq!(points, out.nodes);
    let at = 4 + n;
    assert_eq!(mesh[at], ["Triangles"]);
    let k = int(&mesh[at + 1][0]) as usize;
    let tris: Vec<([i64; 3], i64)> = mesh[at + 2..at + 2 + k]
        .iter()
        .map(|r| ([0, 1, 2].map(|i| int(&r[i]) - 1), int(&r[3])))
        .collect();
    let sorted = |v: &[([i64; 3], i64)]| {
        let mut v: Vec<_> = v
            .iter()
            .map(|&(mut f, m)| {
                f.sort();
                (f, m)
            })
            .collect();
        v.sort();
        v
    };
    if plc {
        // The subfaces of the .face file, with their markers.
        assert_eq!(sorted(&tris), sorted(&out.faces));
    } else {
        let hull: Vec<_> = out.faces.iter().map(|&(f, _)| (f, 1)).collect();
        assert_eq!(sorted(&tris), sorted(&hull));
    }
    let at = at + 2 + k;
    assert_eq!(mesh[at], ["Tetrahedra"]);
    let m = out.tets.len();
    assert_eq!(int(&mesh[at + 1][0]), m as i64);
    let tets: Vec<[i64; 4]> = mesh[at + 2..at + 2 + m]
        .iter()
        .map(|r| [0, 1, 2, 3].map(|i| int(&r[i]) - 1))
        .collect();
    assert_eq!(tets, out.tets);
    let refs: Vec<f64> = mesh[at + 2..at + 2 + m]
        .iter()
        .map(|r| num(&r[4]))
        .collect();
    if out.attrs.is_empty() {
        assert!(refs.iter().all(|&r| r == 0.0));
    } else {
        assert_eq!(
            refs,
            out.attrs.iter().map(|a| a.trunc()).collect::<Vec<_>>()
        );
    }
    assert_eq!(mesh[at + 2 + m..], [vec!["End"]]);
    // Our own reader takes it back: the nodes, and the triangles as facets.
    let back = read_plc(&with_ext(prefix, "mesh")).unwrap();
    assert_eq!(back.points, out.nodes);
    let facets: Vec<([i64; 3], i64)> = back
        .facets
        .iter()
        .map(|f| {
            let p = &f.polygons[0];
            ([p[0], p[1], p[2]].map(i64::from), i64::from(f.marker))
        })
        .collect();
    assert_eq!(facets, tris);
}

#[test]
fn vtk_and_medit_outputs_match_node_and_ele() {
    let dir = tempfile::tempdir().unwrap();
    let cases: &[(&str, &str, bool)] = &[
        ("formats/cube.mesh", "-pQkg", true),
        ("formats/cube.bin.stl", "-pQkgz", true),
        ("examples/box_with_hole.poly", "-pQAkg", true),
        ("examples/points8.node", "-Qkg", false),
    ];
    for (k, &(model, switches, plc)) in cases.iter().enumerate() {
        let prefix = mesh(dir.path(), &format!("m{k}"), &data(model), switches);
        let out = read_out(&prefix);
        assert!(!out.tets.is_empty());
        assert_eq!(!out.attrs.is_empty(), switches.contains('A'), "{model}");
        check_vtk(&prefix, &out);
        check_medit(&prefix, &out, plc);
    }
}

#[test]
fn outputs_are_named_like_tetgen_and_spare_the_input() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("cube.mesh");
    fs::copy(data("formats/cube.mesh"), &input).unwrap();
    tetcdt()
        .current_dir(dir.path())
        .args(["-pQkg", "cube.mesh"])
        .assert()
        .success();
    for ext in ["node", "ele", "face", "edge", "vtk", "mesh"] {
        assert!(
            dir.path().join(format!("cube.1.{ext}")).is_file(),
            "cube.1.{ext}"
        );
    }
    // With -I the Medit output would be the input itself: refused before meshing.
    let before = fs::read(&input).unwrap();
    let out = tetcdt()
        .current_dir(dir.path())
        .args(["-pQgI", "cube.mesh"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("would overwrite the input file"));
    assert_eq!(fs::read(&input).unwrap(), before);
}

#[test]
fn help_documents_k_and_g() {
    let out = tetcdt().arg("--help").output().unwrap();
    let help = String::from_utf8_lossy(&out.stdout);
    assert!(
        help.contains("-k     Also write the mesh as legacy VTK"),
        "{help}"
    );
    assert!(
        help.contains("-g     Also write the mesh as Medit"),
        "{help}"
    );
    assert!(help.contains(".stl, .ply, .mesh"), "{help}");
}

/// Cut short at every length and with bytes changed at random (a fixed sequence), the
/// models give errors or models, never a panic.
#[test]
fn damaged_files_never_panic() {
    let mut state: u64 = 0x2545_f491_4f6c_dd1d;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    const JUNK: &[u8] = b"0123456789 -.e\n\0\xff\x80solidfacetvertexendloopnaninf#";
    for &(model, _, _) in MODELS {
        let path = data(model);
        let bytes = fs::read(&path).unwrap();
        let parse = |b: &[u8]| {
            let _ = match path.extension().and_then(|e| e.to_str()) {
                Some("stl") => tetcdt::io::stl::parse(b, &path),
                Some("ply") => tetcdt::io::ply::parse(b, &path),
                _ => tetcdt::io::medit::parse(&String::from_utf8_lossy(b), &path),
            };
        };
        for len in 0..bytes.len() {
            parse(&bytes[..len]);
        }
        for _ in 0..2000 {
            let mut b = bytes.clone();
            for _ in 0..1 + next() % 4 {
                let at = (next() % b.len() as u64) as usize;
                b[at] = JUNK[(next() % JUNK.len() as u64) as usize];
            }
            parse(&b);
        }
    }
}
