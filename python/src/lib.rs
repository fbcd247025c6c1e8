//! The native half of the `tetcdt` Python package: builds a [`tetcdt::Plc`] from numpy
//! arrays (or reads one from a file), meshes it with the GIL released, and hands the
//! mesh back as numpy arrays that own the library's buffers. The Python half
//! (`tetcdt/__init__.py`) turns the friendlier input forms into the flat arrays taken
//! here and wraps the results in `Mesh` and `PLC` classes.

use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::create_exception;
use pyo3::exceptions::{PyFileNotFoundError, PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::path::PathBuf;
use tetcdt::error::{EXIT_INVALID_INPUT, EXIT_IO, EXIT_MESH_FAILED};
use tetcdt::io::write::{self as writer, WriteOptions};
use tetcdt::plc::{Facet, Region};
use tetcdt::stats::StatValue;
use tetcdt::{Error, InputError, MeshOut, Options, Plc};

create_exception!(
    tetcdt,
    InvalidInputError,
    PyValueError,
    "The input is not a valid PLC (the command line's exit code 3)."
);
create_exception!(
    tetcdt,
    MeshingError,
    PyRuntimeError,
    "Meshing failed on a valid input (the command line's exit code 1)."
);

/// The name arrays given to `tetrahedralize` take in messages, where a file's name goes.
const ARRAYS_SOURCE: &str = "<arrays>";

/// The Python exception of a library error, with the command line's message.
fn py_error(e: Error) -> PyErr {
    let msg = e.to_string();
    match e.exit_code() {
        EXIT_INVALID_INPUT => InvalidInputError::new_err(msg),
        EXIT_MESH_FAILED => MeshingError::new_err(msg),
        EXIT_IO => match &e {
            Error::Input(InputError::Io { source, .. }) | Error::Output { source, .. }
                if source.kind() == std::io::ErrorKind::NotFound =>
            {
                PyFileNotFoundError::new_err(msg)
            }
            _ => PyOSError::new_err(msg),
        },
        _ => PyRuntimeError::new_err(msg),
    }
}

/// Switches as the command line takes them (`"pq1.414"`, `"-pq1.414 -A"`), for meshing.
fn parse_switches(switches: &str) -> PyResult<Options> {
    let opts = Options::from_switches(switches.split_whitespace())
        .map_err(|e| PyValueError::new_err(format!("switches {switches:?}: {e}")))?;
    if opts.detect_intersections {
        return Err(PyValueError::new_err(
            "switch -d (report intersecting facets and write them) is for the command line; \
             tetrahedralize raises InvalidInputError naming them instead",
        ));
    }
    Ok(opts)
}

/// Rows of an (n, k) float array as points, refusing any other width.
fn rows3(name: &str, a: &PyReadonlyArray2<'_, f64>) -> PyResult<Vec<[f64; 3]>> {
    let a = a.as_array();
    if a.ncols() != 3 {
        return Err(PyValueError::new_err(format!(
            "{name} must have shape (n, 3), not {:?}",
            a.shape()
        )));
    }
    Ok(a.rows().into_iter().map(|r| [r[0], r[1], r[2]]).collect())
}

/// Offsets (`ends`, from 0, one more than the items) checked against the length of what
/// they cut.
fn check_offsets(name: &str, ends: &[i64], len: usize) -> PyResult<()> {
    let ok = ends.first() == Some(&0)
        && ends.windows(2).all(|w| w[0] <= w[1])
        && ends.last().copied() == Some(len as i64);
    if ok {
        Ok(())
    } else {
        Err(PyValueError::new_err(format!(
            "{name} must rise from 0 to {len}"
        )))
    }
}

/// Builds the PLC of flat arrays: the polygons are `indices` cut at `polygon_ends`, the
/// facets those polygons cut at `facet_ends` (both start with 0).
#[allow(clippy::too_many_arguments)]
fn plc_of_arrays(
    points: &PyReadonlyArray2<'_, f64>,
    indices: &[i64],
    polygon_ends: &[i64],
    facet_ends: &[i64],
    facet_markers: Option<&[i64]>,
    holes: Option<&PyReadonlyArray2<'_, f64>>,
    regions: Option<&PyReadonlyArray2<'_, f64>>,
) -> PyResult<Plc> {
    let mut plc = Plc::from_points(rows3("points", points)?, 0);
    plc.source = PathBuf::from(ARRAYS_SOURCE);
    check_offsets("polygon offsets", polygon_ends, indices.len())?;
    let polygons = polygon_ends.len() - 1;
    check_offsets("facet offsets", facet_ends, polygons)?;
    let facets = facet_ends.len() - 1;
    if let Some(m) = facet_markers {
        if m.len() != facets {
            return Err(PyValueError::new_err(format!(
                "facet_markers has {} entries for {facets} facets",
                m.len()
            )));
        }
    }
    let n = plc.points.len();
    let invalid = |msg: String| -> PyErr {
        py_error(
            InputError::Invalid {
                file: plc.source.clone(),
                msg,
            }
            .into(),
        )
    };
    let mut polygon = |p: usize| -> PyResult<Vec<u32>> {
        let (a, b) = (polygon_ends[p] as usize, polygon_ends[p + 1] as usize);
        indices[a..b]
            .iter()
            .map(|&i| match u32::try_from(i) {
                Ok(v) if (v as usize) < n => Ok(v),
                _ => Err(invalid(format!(
                    "polygon {p} refers to point {i}, but the points are numbered 0 to {}",
                    n as i64 - 1
                ))),
            })
            .collect()
    };
    plc.facets = (0..facets)
        .map(|f| {
            let polygons = (facet_ends[f] as usize..facet_ends[f + 1] as usize)
                .map(&mut polygon)
                .collect::<PyResult<Vec<_>>>()?;
            let marker = match facet_markers {
                None => 0,
                Some(m) => i32::try_from(m[f]).map_err(|_| {
                    invalid(format!("facet {f}: marker {} does not fit 32 bits", m[f]))
                })?,
            };
            Ok(Facet {
                polygons,
                marker,
                ..Default::default()
            })
        })
        .collect::<PyResult<Vec<_>>>()?;
    if let Some(h) = holes {
        plc.holes = rows3("holes", h)?;
    }
    if let Some(r) = regions {
        let r = r.as_array();
        if !(r.ncols() == 4 || r.ncols() == 5) {
            return Err(PyValueError::new_err(format!(
                "regions must have shape (n, 4) or (n, 5) (x, y, z, attribute[, max volume]), \
                 not {:?}",
                r.shape()
            )));
        }
        plc.regions = r
            .rows()
            .into_iter()
            .map(|row| Region {
                point: [row[0], row[1], row[2]],
                attribute: row[3],
                max_volume: if row.len() == 5 { row[4] } else { -1.0 },
            })
            .collect();
    }
    // As the surface readers do: a polygon whose corners weld to fewer than three points
    // adds nothing to the surface (a warning says so).
    plc.drop_degenerate_polygons();
    Ok(plc)
}

/// What the Python `Mesh` wraps beyond its arrays: the rest of the library's mesh (its
/// points and tets live in the arrays) and the switches, for writing TetGen's files.
#[pyclass(frozen, module = "tetcdt._tetcdt")]
struct MeshFiles {
    rest: MeshOut,
    write: WriteOptions,
    switches: String,
}

#[pymethods]
impl MeshFiles {
    /// Writes TetGen's files of the mesh under `prefix` (the files the switches ask for)
    /// and returns their paths; `points` and `tets` are the mesh's own arrays.
    fn write(
        &self,
        py: Python<'_>,
        prefix: PathBuf,
        points: PyReadonlyArray2<'_, f64>,
        tets: PyReadonlyArray2<'_, i32>,
    ) -> PyResult<Vec<PathBuf>> {
        let mut mesh = self.rest.clone();
        mesh.points = rows3("points", &points)?;
        mesh.tets = tets
            .as_array()
            .rows()
            .into_iter()
            .map(|r| [r[0] as u32, r[1] as u32, r[2] as u32, r[3] as u32])
            .collect();
        let mut w = self.write.clone();
        w.comment = Some(format!("tetcdt {} (Python)", self.switches));
        py.detach(|| {
            writer::check_output_dir(&prefix)?;
            writer::write_files(&mesh, &prefix, &w, &mut |_| {})
        })
        .map_err(py_error)
    }
}

/// A figure of the run as a Python value.
fn stat_value<'py>(py: Python<'py>, v: &StatValue) -> PyResult<Bound<'py, PyAny>> {
    Ok(match v {
        StatValue::Count(n) => n.into_pyobject(py)?.into_any(),
        StatValue::Number(x) => x.into_pyobject(py)?.into_any(),
        StatValue::Text(s) => s.into_pyobject(py)?.into_any(),
        StatValue::Flag(b) => b.into_pyobject(py)?.to_owned().into_any(),
        StatValue::Counts(c) => PyList::new(py, c)?.into_any(),
    })
}

/// Cells of `N` nodes with markers (subfaces, subsegments) as an (n, N) int32 array and
/// their markers.
fn constrained_cells<'py, const N: usize>(
    py: Python<'py>,
    cells: &[([u32; N], i32)],
) -> (Bound<'py, PyArray2<i32>>, Bound<'py, PyArray1<i32>>) {
    let nodes: Vec<i32> = cells
        .iter()
        .flat_map(|(c, _)| c.map(|v| v as i32))
        .collect();
    let markers: Vec<i32> = cells.iter().map(|&(_, m)| m).collect();
    (
        Array2::from_shape_vec((cells.len(), N), nodes)
            .expect("rows of N")
            .into_pyarray(py),
        Array1::from_vec(markers).into_pyarray(py),
    )
}

/// Meshes `plc` as `switches` ask, with the GIL released, and returns the mesh as a dict
/// of arrays (what the command line writes: without the points no tet uses, unless `J`).
fn mesh<'py>(py: Python<'py>, plc: &Plc, switches: &str) -> PyResult<Bound<'py, PyDict>> {
    let opts = parse_switches(switches)?;
    let meshed = py
        .detach(|| tetcdt::tetrahedralize(plc, &opts))
        .map_err(py_error)?;
    let tetcdt::Meshed {
        mesh,
        stats,
        warnings,
    } = meshed;
    let mut out = mesh.written(opts.keep_unused).unwrap_or(mesh);
    let d = PyDict::new(py);
    let points = std::mem::take(&mut out.points);
    let n = points.len();
    d.set_item(
        "points",
        Array2::from_shape_vec((n, 3), points.into_flattened())
            .expect("n rows of 3")
            .into_pyarray(py),
    )?;
    let tets = std::mem::take(&mut out.tets);
    let k = tets.len();
    // Node numbers are below 2^31 (the library numbers nodes with u32 and a mesh of
    // 2^31 nodes does not fit in memory at 24 bytes a point and 4 tets a point); i32
    // is what TetGen's own arrays hold. The map reuses the buffer.
    let tets: Vec<i32> = tets
        .into_flattened()
        .into_iter()
        .map(|v| v as i32)
        .collect();
    d.set_item(
        "tets",
        Array2::from_shape_vec((k, 4), tets)
            .expect("k rows of 4")
            .into_pyarray(py),
    )?;
    let (faces, face_markers) = constrained_cells(py, &out.subfaces);
    d.set_item("faces", faces)?;
    d.set_item("face_markers", face_markers)?;
    let (edges, edge_markers) = constrained_cells(py, &out.subsegments);
    d.set_item("edges", edges)?;
    d.set_item("edge_markers", edge_markers)?;
    if out.num_tet_attrs > 0 {
        // With -A each tet carries one attribute: its region's.
        let regions: Vec<f64> = out
            .tet_attrs
            .iter()
            .step_by(out.num_tet_attrs)
            .copied()
            .collect();
        d.set_item("tet_regions", PyArray1::from_vec(py, regions))?;
    } else {
        d.set_item("tet_regions", py.None())?;
    }
    let s = PyDict::new(py);
    s.set_item("mesh_points", n)?;
    for (name, v) in stats.fields() {
        s.set_item(name, stat_value(py, &v)?)?;
    }
    d.set_item("stats", s)?;
    let mut all_warnings = plc.warnings.clone();
    all_warnings.extend(warnings);
    d.set_item("warnings", all_warnings)?;
    out.neighbors.clear();
    d.set_item(
        "files",
        MeshFiles {
            rest: out,
            write: WriteOptions::from_options(&opts),
            switches: switches.to_string(),
        },
    )?;
    Ok(d)
}

/// Meshes the PLC given as flat arrays (see `tetcdt/__init__.py` for the friendly forms).
#[pyfunction]
#[pyo3(signature = (points, indices, polygon_ends, facet_ends, facet_markers, holes, regions, switches))]
#[allow(clippy::too_many_arguments)]
fn tetrahedralize<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    indices: PyReadonlyArray1<'py, i64>,
    polygon_ends: PyReadonlyArray1<'py, i64>,
    facet_ends: PyReadonlyArray1<'py, i64>,
    facet_markers: Option<PyReadonlyArray1<'py, i64>>,
    holes: Option<PyReadonlyArray2<'py, f64>>,
    regions: Option<PyReadonlyArray2<'py, f64>>,
    switches: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let markers = facet_markers.as_ref().map(|m| m.as_slice()).transpose()?;
    let plc = plc_of_arrays(
        &points,
        indices.as_slice()?,
        polygon_ends.as_slice()?,
        facet_ends.as_slice()?,
        markers,
        holes.as_ref(),
        regions.as_ref(),
    )?;
    mesh(py, &plc, switches)
}

/// Points as an (n, 3) array (a copy: the PLC keeps its own).
fn points_array<'py>(py: Python<'py>, points: &[[f64; 3]]) -> Bound<'py, PyArray2<f64>> {
    let flat: Vec<f64> = points.iter().flatten().copied().collect();
    Array2::from_shape_vec((points.len(), 3), flat)
        .expect("rows of 3")
        .into_pyarray(py)
}

/// Polygons as (indices, polygon ends, facet ends).
type FacetArrays<'py> = (
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<i64>>,
);

/// A PLC read from a file, as the command line reads it.
#[pyclass(frozen, name = "Plc", module = "tetcdt._tetcdt")]
struct PyPlc {
    plc: Plc,
}

#[pymethods]
impl PyPlc {
    /// Meshes the PLC exactly as the command line meshes its file.
    fn tetrahedralize<'py>(&self, py: Python<'py>, switches: &str) -> PyResult<Bound<'py, PyDict>> {
        mesh(py, &self.plc, switches)
    }

    /// The points, (n, 3).
    #[getter]
    fn points<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        points_array(py, &self.plc.points)
    }

    /// The facets' polygons as flat arrays: (indices, polygon ends, facet ends), the
    /// ends starting with 0.
    #[getter]
    fn facet_arrays<'py>(&self, py: Python<'py>) -> FacetArrays<'py> {
        let mut indices = Vec::new();
        let mut polygon_ends = vec![0i64];
        let mut facet_ends = vec![0i64];
        for f in &self.plc.facets {
            for p in &f.polygons {
                indices.extend(p.iter().map(|&v| v as i64));
                polygon_ends.push(indices.len() as i64);
            }
            facet_ends.push(polygon_ends.len() as i64 - 1);
        }
        (
            PyArray1::from_vec(py, indices),
            PyArray1::from_vec(py, polygon_ends),
            PyArray1::from_vec(py, facet_ends),
        )
    }

    /// The facets' boundary markers.
    #[getter]
    fn facet_markers<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        let m: Vec<i64> = self.plc.facets.iter().map(|f| f.marker as i64).collect();
        PyArray1::from_vec(py, m)
    }

    /// The hole points inside each facet (a `.poly` file's facet holes), per facet.
    #[getter]
    fn facet_holes(&self) -> Vec<Vec<[f64; 3]>> {
        self.plc.facets.iter().map(|f| f.holes.clone()).collect()
    }

    /// The volume hole points, (h, 3).
    #[getter]
    fn holes<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        points_array(py, &self.plc.holes)
    }

    /// The regions, (r, 5): a point inside, the attribute and the volume bound (negative
    /// when none).
    #[getter]
    fn regions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let flat: Vec<f64> = self
            .plc
            .regions
            .iter()
            .flat_map(|r| {
                [
                    r.point[0],
                    r.point[1],
                    r.point[2],
                    r.attribute,
                    r.max_volume,
                ]
            })
            .collect();
        Array2::from_shape_vec((self.plc.regions.len(), 5), flat)
            .expect("rows of 5")
            .into_pyarray(py)
    }

    /// The number of the file's first point (0 or 1); arrays always count from 0.
    #[getter]
    fn first_index(&self) -> usize {
        self.plc.first_index
    }

    /// The file read.
    #[getter]
    fn source(&self) -> PathBuf {
        self.plc.source.clone()
    }

    /// What reading found worth a warning (dropped degenerate polygons and the like).
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.plc.warnings.clone()
    }
}

/// Reads a model in any format the command line reads.
#[pyfunction]
fn read(py: Python<'_>, path: PathBuf) -> PyResult<PyPlc> {
    let plc = py
        .detach(|| tetcdt::io::read_plc(&path))
        .map_err(|e| py_error(e.into()))?;
    Ok(PyPlc { plc })
}

/// The native module.
#[pymodule]
fn _tetcdt(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("InvalidInputError", py.get_type::<InvalidInputError>())?;
    m.add("MeshingError", py.get_type::<MeshingError>())?;
    m.add_function(wrap_pyfunction!(tetrahedralize, m)?)?;
    m.add_function(wrap_pyfunction!(read, m)?)?;
    m.add_class::<PyPlc>()?;
    m.add_class::<MeshFiles>()?;
    Ok(())
}
