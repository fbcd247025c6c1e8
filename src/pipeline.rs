//! The meshing pipeline: read model → Delaunay → (segments → facets → carve) → output.
//! [`mesh_plc`] is the `-p` part: [`crate::constrained`] builds the CDT, [`crate::carve`]
//! keeps its domain.

use crate::constrained::{construct, Constructed, PlcOptions, PlcStats};
use crate::delaunay::Delaunay;
use crate::error::{Error, MeshError};
use crate::live::RefineParameters;
use crate::options::Options;
use crate::output::MeshOut;
use crate::plc::prepare::PreparedPlc;
use crate::plc::Plc;
use crate::progress::{Progress, Stage};
use crate::stats::Stats;
use crate::Meshed;
use std::time::Instant;

/// Runs the pipeline on `plc` as `opts` asks, telling `progress` when each stage begins.
/// A model without volume (all points coplanar) is an invalid input, named by its file.
pub fn run(plc: &Plc, opts: &Options, progress: Progress<'_>) -> Result<Meshed, Error> {
    let r = if opts.plc {
        run_plc(plc, opts, progress)
    } else {
        run_points(plc, opts, progress)
    };
    r.map_err(|e| match e {
        Error::Mesh(MeshError::Degenerate(msg)) if !plc.source.as_os_str().is_empty() => {
            crate::error::InputError::Invalid {
                file: plc.source.clone(),
                msg,
            }
            .into()
        }
        e => e,
    })
}

/// The Delaunay tetrahedralization of a point set.
fn run_points(plc: &Plc, opts: &Options, progress: Progress<'_>) -> Result<Meshed, Error> {
    crate::precheck::check_coordinates(plc)?;
    progress(Stage::Delaunay);
    let start = Instant::now();
    let mut stats = Stats {
        input_points: plc.points.len(),
        ..Default::default()
    };
    let built = Delaunay::build(&plc.points)?;
    stats.delaunay_secs = start.elapsed().as_secs_f64();
    let mut warnings = Vec::new();
    let base = plc.first_index;
    for &(dup, kept) in &built.duplicates {
        warnings.push(format!(
            "point {} is a duplicate of point {} and was skipped",
            dup as usize + base,
            kept as usize + base
        ));
    }
    stats.duplicate_points = built.duplicates.len();
    // The neighbour table costs 32 bytes a tet and a pass over the arena; only the
    // .neigh, all-faces and edge writers need it.
    let need_neighbors = opts.write_neighbors || opts.all_faces || opts.write_edges;
    let out = built.dt.export_with(need_neighbors);
    stats.output_tets = out.tets.len();
    stats.hull_faces = out.hull_faces.len();
    let mesh = MeshOut {
        points: plc.points.clone(),
        num_point_attrs: plc.num_point_attrs,
        point_attrs: plc.point_attrs.clone(),
        point_markers: plc.point_markers.clone(),
        tets: out.tets,
        neighbors: out.neighbors,
        hull_faces: out.hull_faces,
        first_index: plc.first_index,
        ..Default::default()
    };
    stats.total_secs = start.elapsed().as_secs_f64();
    Ok(Meshed {
        mesh,
        stats,
        warnings,
    })
}

/// The `-p` pipeline: the constrained Delaunay tetrahedralization of the PLC, carved.
fn run_plc(plc: &Plc, opts: &Options, progress: Progress<'_>) -> Result<Meshed, Error> {
    let start = Instant::now();
    let popts = crate::constrained::PlcOptions {
        merge: opts.merges_facets(),
        keep_hull: opts.keep_hull,
        region_attributes: opts.region_attributes,
        // Without -S, a generous bound still guarantees that every run ends.
        max_steiner: opts
            .max_steiner
            .unwrap_or((20 * plc.points.len()).max(1_000_000)),
        inserter: match opts.facet_algo {
            crate::options::FacetAlgo::Cavity => crate::constrained::FacetInserter::Cavity,
            crate::options::FacetAlgo::Flip => crate::constrained::FacetInserter::Flip,
        },
        cancel: None,
        wake_when_prepared: None,
    };
    // The checks of single elements come first: meshing relies on them. The surface
    // checks (intersecting facets) run on a second core alongside meshing, and stop it
    // if they find the input invalid; their error then wins.
    let rep = crate::precheck::check_elements(plc)?;
    let cancel = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let (checked, done) = std::thread::scope(|s| {
        let checker = s.spawn(|| {
            // They start once the PLC is prepared (or meshing is over): the PLC's
            // preparation already shares the two cores with the Delaunay stage, and a
            // third thread there slowed that stage, the critical path, by a third.
            std::thread::park();
            let r = crate::precheck::check_surface(plc, &rep);
            if r.is_err() {
                cancel.store(true, std::sync::atomic::Ordering::Relaxed);
            }
            (r, start.elapsed().as_secs_f64())
        });
        let popts = crate::constrained::PlcOptions {
            cancel: Some(cancel.clone()),
            wake_when_prepared: Some(checker.thread().clone()),
            ..popts
        };
        let refine = RefineParameters {
            max_ratio: opts.quality.map(|q| q.max_ratio),
            min_dihedral: opts.quality.map(|q| q.min_dihedral),
            max_volume: opts.max_volume,
            region_volumes: opts.region_volumes,
            keep_boundary: opts.keep_boundary,
        };
        let done = mesh_plc_with_progress(plc, &popts, (&refine, opts.max_steiner), progress);
        checker.thread().unpark();
        let checked = checker
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
        (checked, done)
    });
    let (checked, precheck_secs) = checked;
    let mut warnings = checked?;
    let done = done?;
    if opts.keep_boundary {
        boundary_kept(plc, &done.mesh)?;
    }
    // Exit 0 means a valid CDT: the mesh is certified from its nodes and tets alone
    // before anyone gets it.
    let t_certify = Instant::now();
    let view = crate::check::MeshView {
        points: &done.mesh.points,
        tets: &done.mesh.tets,
        first_index: done.mesh.first_index,
    };
    let copts = crate::check::CertifyOptions::of(opts);
    crate::check::certify_prepared(plc, Some(&done.prepared), view, &copts)
        .map_err(MeshError::NotCertified)?;
    let certify_secs = t_certify.elapsed().as_secs_f64();
    warnings.extend(done.warnings);
    let ps = done.stats;
    let wants_quality = opts.verbose > 0
        || opts.stats_json.is_some()
        || opts.quality.is_some()
        || opts.max_volume.is_some()
        || opts.region_volumes;
    let quality =
        wants_quality.then(|| crate::stats::QualityFigures::of(&done.mesh.points, &done.mesh.tets));
    let stats = Stats {
        input_points: plc.points.len(),
        duplicate_points: ps.duplicate_points,
        output_tets: ps.output_tets,
        delaunay_secs: ps.delaunay_secs,
        precheck_secs,
        certify_secs,
        total_secs: start.elapsed().as_secs_f64(),
        plc: Some(ps),
        quality,
        ..Default::default()
    };
    Ok(Meshed {
        mesh: done.mesh,
        stats,
        warnings,
    })
}

/// `-Y`: an error if `mesh` has Steiner points on the segments or facets (its first
/// nodes are the input points, in order; refinement under `-Y` adds none there, so any
/// come from recovering the segments and facets).
fn boundary_kept(plc: &Plc, mesh: &MeshOut) -> Result<(), MeshError> {
    let inputs = plc.points.len();
    let faces = mesh.subfaces.iter().flat_map(|(f, _)| *f);
    let edges = mesh.subsegments.iter().flat_map(|(e, _)| *e);
    let on: rustc_hash::FxHashSet<u32> = faces
        .chain(edges)
        .filter(|&v| v as usize >= inputs)
        .collect();
    match on.iter().min() {
        None => Ok(()),
        Some(&first) => Err(MeshError::BoundaryChanged {
            points: on.len(),
            first: mesh.points[first as usize],
        }),
    }
}

/// The finished PLC mesh, its figures, and warnings for the user.
pub struct PlcMesh {
    /// The mesh in output form.
    pub mesh: MeshOut,
    /// Figures.
    pub stats: PlcStats,
    /// Warnings.
    pub warnings: Vec<String>,
    /// The PLC as prepared for meshing (merged facets, segments), which the certifier
    /// judges the mesh against.
    pub prepared: PreparedPlc,
}

/// Meshes a PLC: its constrained Delaunay tetrahedralization, carved.
pub fn mesh_plc(plc: &Plc, opts: &PlcOptions) -> Result<PlcMesh, Error> {
    let no = RefineParameters::default();
    mesh_plc_with_progress(plc, opts, (&no, None), &crate::progress::no_progress)
}

/// Like [`mesh_plc`], refined to `refine.0` (with the Steiner point budget `refine.1`,
/// none if `None`), telling `progress` when each stage begins.
pub fn mesh_plc_with_progress(
    plc: &Plc,
    opts: &PlcOptions,
    refine: (&RefineParameters, Option<usize>),
    progress: Progress<'_>,
) -> Result<PlcMesh, Error> {
    let constructed = construct(plc, opts, progress)?;
    if refine.0.any() {
        return refined(plc, opts, constructed, refine, progress);
    }
    let Constructed {
        built,
        split,
        base,
        mut stats,
        warnings,
    } = constructed;
    let prep = split.as_ref().unwrap_or(&base);
    let mesh = crate::carve::carve(plc, prep, *built, opts, &mut stats, progress)?;
    Ok(PlcMesh {
        mesh,
        stats,
        warnings,
        prepared: base,
    })
}

/// The refinement stage: the finished CDT, live, refined in place, then carved.
fn refined(
    plc: &Plc,
    opts: &PlcOptions,
    constructed: Constructed,
    (params, budget): (&RefineParameters, Option<usize>),
    progress: Progress<'_>,
) -> Result<PlcMesh, Error> {
    progress(Stage::Refine);
    let t = Instant::now();
    let mut cdt = crate::live::Cdt::of_construction(plc, opts, constructed);
    // Refinement ends by its own argument (ARCHITECTURE.md): only `-S` bounds it.
    cdt.set_steiner_budget(budget.unwrap_or(usize::MAX));
    let r = cdt.refine(params);
    let secs = t.elapsed().as_secs_f64();
    let (mesh, prepared, mut stats, mut warnings) = cdt.into_mesh(progress)?;
    stats.refine_points = r.points;
    stats.refine_left = r.left;
    stats.refine_secs = secs;
    if r.budget_spent {
        warnings.push(format!(
            "the Steiner point budget (-S) ran out during refinement: {} tets are still over \
             the quality bounds",
            r.left
        ));
    }
    Ok(PlcMesh {
        mesh,
        stats,
        warnings,
        prepared,
    })
}
