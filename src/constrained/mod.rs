//! Constrained Delaunay tetrahedralization of a PLC: preparation of the PLC, segment
//! recovery with Steiner points, and facet insertion, then carving.
//!
//! [`mesh_plc`] runs read PLC → Delaunay → segments → facets → carve. When a polygon
//! that is not flat needs a Steiner point on it (paper §3.1), the point goes into the
//! CDT by a walled cavity and flips (`free.rs`) and the polygon is triangulated again
//! with it; where that cannot be done, the point is added to the facet and the whole
//! construction starts again from the Delaunay tetrahedralization.

mod bistellar;
pub mod cavity;
pub mod cdt;
pub mod enclosure;
pub mod facet2d;
pub mod flip;
mod flip_queue;
mod free;
pub mod prepare;
pub mod segments;
mod slivers;

use crate::carve::{carve, Carved};
use crate::delaunay::Delaunay;
use crate::error::{Error, MeshError};
use crate::geom::Point;
use crate::mesh::VertexId;
use crate::output::MeshOut;
use crate::plc::Plc;
use crate::progress::{Progress, Stage};
use cavity::{insert_region, Outcome};
use cdt::{edge_key, face_key, Cdt};
use prepare::{prepare, PreparedPlc};
use rustc_hash::{FxHashMap, FxHashSet};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

/// What `-p` meshing needs to know beyond the PLC.
#[derive(Clone, Debug)]
pub struct PlcOptions {
    /// Merge edge-adjacent coplanar facets (TetGen's default; `-M` turns it off).
    pub merge: bool,
    /// Keep the convex hull instead of carving the exterior (`-c`).
    pub keep_hull: bool,
    /// Give each tet its region attribute (`-A`).
    pub region_attributes: bool,
    /// The most Steiner points to add (`-S`).
    pub max_steiner: usize,
    /// How missing regions are inserted (`-C` / `-F`).
    pub inserter: FacetInserter,
    /// Set by another thread to stop the run early (the checks before meshing, run
    /// alongside, found the input invalid): the run then fails with [`CANCELLED`].
    pub cancel: Option<Arc<AtomicBool>>,
    /// A thread to wake (`unpark`) once the PLC is prepared, the first stage that runs
    /// beside the Delaunay tetrahedralization: work that can wait (the checks before
    /// meshing) then takes the second core without a third thread competing for it.
    pub wake_when_prepared: Option<std::thread::Thread>,
}

/// The failure of a run stopped through [`PlcOptions::cancel`].
pub const CANCELLED: &str = "stopped: the input is invalid";

impl PlcOptions {
    /// Fails if the run has been told to stop.
    fn check_cancel(&self) -> Result<(), MeshError> {
        match &self.cancel {
            Some(c) if c.load(Ordering::Relaxed) => Err(MeshError::Failed(CANCELLED.into())),
            _ => Ok(()),
        }
    }

    /// The stop flag, or one never set.
    fn cancel_flag(&self) -> &AtomicBool {
        static NEVER: AtomicBool = AtomicBool::new(false);
        self.cancel.as_deref().unwrap_or(&NEVER)
    }
}

/// The facet insertion algorithm: both insert one missing region at a time, with the
/// same contract (see [`cavity::insert_region`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FacetInserter {
    /// Cavity retriangulation (paper §3.1, `-C`).
    #[default]
    Cavity,
    /// Bistellar flips with exact flip-time ordering (paper §3.2, `-F`).
    Flip,
}

impl FacetInserter {
    /// Inserts the region `tris` of facet `facet` (flips add their figures to `flips`).
    pub fn insert(
        self,
        cdt: &mut Cdt,
        tris: &[[VertexId; 3]],
        facet: u32,
        normal: [f64; 3],
        flips: &mut flip::FlipCounts,
    ) -> Result<Outcome, MeshError> {
        match self {
            FacetInserter::Cavity => insert_region(cdt, tris, facet, normal),
            FacetInserter::Flip => flip::insert_region(cdt, tris, facet, normal, flips),
        }
    }
}

impl Default for PlcOptions {
    fn default() -> Self {
        PlcOptions {
            merge: true,
            keep_hull: false,
            region_attributes: false,
            max_steiner: 10_000_000,
            inserter: FacetInserter::Cavity,
            cancel: None,
            wake_when_prepared: None,
        }
    }
}

/// Figures of a PLC meshing run: the rows of the paper's Table 1.
#[derive(Clone, Debug, Default)]
pub struct PlcStats {
    /// Input vertices.
    pub input_points: usize,
    /// Input polygons.
    pub input_polygons: usize,
    /// Input vertices merged with an earlier one at the same coordinates.
    pub duplicate_points: usize,
    /// Steiner points added, in total.
    pub steiner_points: usize,
    /// Of those, the ones on polygons (for polygons that are not flat).
    pub facet_steiner_points: usize,
    /// Of those, the free ones inside the domain (for flat tets at steps of facets).
    pub free_steiner_points: usize,
    /// Flat tets left with all four vertices on one facet (no free point removed them).
    pub flat_tets_left: usize,
    /// Constructions whose search for free points stopped at its bound on work (around
    /// vertices far out of the model's scale), leaving flat tets it did not get to.
    pub free_searches_cut: usize,
    /// Output tets.
    pub output_tets: usize,
    /// Output subpolygons (triangles on input polygons).
    pub output_subfaces: usize,
    /// Subpolygons that had to be recovered (missing from the Delaunay tetrahedralization).
    pub recovered_subfaces: usize,
    /// The most subpolygons recovered in one missing region.
    pub max_region_subfaces: usize,
    /// Missing regions inserted.
    pub regions: usize,
    /// Crossing tets deleted, in total.
    pub crossing_tets: usize,
    /// The most crossing tets of one missing region.
    pub max_region_crossing_tets: usize,
    /// Tets added to cavities by enlargement.
    pub enlarged_tets: usize,
    /// Restarts caused by Steiner points on polygons.
    pub restarts: usize,
    /// Updates of the CDT in place of a restart, for Steiner points on polygons that it
    /// refused: subsegments split in place, and points put in with facets taken out.
    pub in_place_splits: usize,
    /// Whether those updates were turned off: with them the construction did not
    /// converge, so it was done again without.
    pub in_place_off: bool,
    /// The work over all attempts ([`Cdt::work`]; bounds the restarts).
    pub work: u64,
    /// Seconds for the Delaunay tetrahedralization.
    pub delaunay_secs: f64,
    /// Seconds for segment recovery.
    pub segment_secs: f64,
    /// Seconds for triangulating the facets in their planes (TetGen's "surface mesh"),
    /// before facet recovery.
    pub surface_secs: f64,
    /// Seconds for facet recovery, without the facets' first triangulation (as TetGen
    /// counts it).
    pub facet_secs: f64,
    /// Seconds for carving.
    pub carve_secs: f64,
    /// The facet insertion algorithm used.
    pub inserter: FacetInserter,
    /// Flip insertion's figures (`-F`).
    pub flips: flip::FlipCounts,
    /// Facets whose regions fell back from flips to cavity retriangulation.
    pub flip_fallback_facets: Vec<u32>,
}

/// The finished PLC mesh, its figures, and warnings for the user.
pub struct PlcMesh {
    /// The mesh in output form.
    pub mesh: MeshOut,
    /// Figures.
    pub stats: PlcStats,
    /// Warnings.
    pub warnings: Vec<String>,
}

/// Whether to trace restarts, Steiner points, cavity widening and flip fallbacks on
/// stderr (`TETCDT_DEBUG=1`).
fn debug() -> bool {
    std::env::var_os("TETCDT_DEBUG").is_some()
}

/// The most Steiner points on polygons before giving up: far more than polygons that are
/// nearly flat need (the paper's worst case needed 103), so reaching it means the
/// polygons are not nearly flat and more points will not help.
fn max_facet_points(plc: &Plc) -> usize {
    (4 * plc.points.len()).max(1000)
}

/// The facet of a Steiner point that lies on none: it removes a flat tet from the domain
/// (see [`slivers`]).
const FREE_POINT: usize = usize::MAX;

/// Marks the failure to triangulate a merged group in one plane (then split).
const UNFLAT_GROUP: &str = "merged facets ";

/// At most this many tets left on facets are worth other constructions (fans of needle
/// triangles leave many, which no single point removes).
const MAX_RETRY_TETS: usize = 4;

/// The most restarts for Steiner points on polygons before giving up.
const MAX_RESTARTS: usize = 24;

/// Work ([`Cdt::work`]) that restarts may spend beyond eight times the first attempt's.
const RESTART_WORK: u64 = 20_000_000;

/// The work all restarts may do, by the first construction's `first` (see
/// [`RESTART_WORK`]).
fn restart_work_bound(first: u64) -> u64 {
    RESTART_WORK + 8 * first
}

/// Restarts after which flat tets no longer get free points (see [`slivers`]).
const MAX_FREE_ROUNDS: usize = 12;

/// Work ([`slivers::free_points`]) that the search for free points may do in one
/// construction, per tet slot of the mesh (the corpus takes at most 17 per slot, on
/// `112544.off`)...
const FREE_SEARCH_WORK_PER_SLOT: u64 = 64;
/// ... and beyond that, for small meshes.
const FREE_SEARCH_WORK: u64 = 1_000_000;

/// Restarts after which free points the CDT refuses and flat-tet splits no longer start
/// the construction again: each costs a whole construction, and past a few they do not
/// converge (on fans of needle triangles every restart finds new flat tets).
const MAX_FREE_RESTARTS: usize = 3;

/// The error of restarts that end over their bounds, after `points` Steiner points on
/// polygons.
fn still_conflicting(points: usize) -> Error {
    MeshError::Failed(format!(
        "polygons that are not flat still conflict after {points} Steiner points on them"
    ))
    .into()
}

/// The state to start the constructions over from, with updates in place turned off
/// (`stats0` as at the start): no points from earlier attempts, no work done.
fn without_updates(stats0: &PlcStats) -> (Vec<FacetPoint>, Vec<SegmentSplit>, u64, PlcStats) {
    let stats = PlcStats {
        in_place_off: true,
        ..stats0.clone()
    };
    (Vec::new(), Vec::new(), 0, stats)
}

/// Meshes a PLC: its constrained Delaunay tetrahedralization, carved.
pub fn mesh_plc(plc: &Plc, opts: &PlcOptions) -> Result<PlcMesh, Error> {
    mesh_plc_with_progress(plc, opts, &crate::progress::no_progress)
}

/// Like [`mesh_plc`], telling `progress` when each stage (of each attempt) begins.
pub fn mesh_plc_with_progress(
    plc: &Plc,
    opts: &PlcOptions,
    progress: Progress<'_>,
) -> Result<PlcMesh, Error> {
    // The PLC's preparation and the first attempt's Delaunay tetrahedralization do not
    // depend on each other: they run on two cores.
    // An open surface is found once prepared: the Delaunay stage then stops early.
    progress(Stage::Delaunay);
    let open = AtomicBool::new(false);
    let (prepared, first_dt) = std::thread::scope(|s| {
        let preparing = s.spawn(|| -> Result<_, Error> {
            let base = prepare(plc, opts.merge);
            if let Some(t) = &opts.wake_when_prepared {
                t.unpark();
            }
            let refused = match &base {
                Ok(b) => !opts.keep_hull && enclosure::open_boundary(plc, b).is_some(),
                Err(_) => true,
            };
            if refused {
                open.store(true, Ordering::Relaxed);
            }
            let base = base?;
            // Flat tets are judged on the facets as merged by default, whatever the
            // switches and the splitting of groups below did.
            let all_merged = if opts.merge {
                None
            } else {
                Some(prepare(plc, true)?)
            };
            Ok((base, all_merged))
        });
        let t0 = Instant::now();
        let dt =
            Delaunay::build_until(&plc.points, &open).map(|b| (b.dt, t0.elapsed().as_secs_f64()));
        let prepared = preparing
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
        (prepared, dt)
    });
    let (base, all_merged) = prepared?;
    let merged = all_merged.as_ref().unwrap_or(&base);
    // `base` with the groups that could not be triangulated in one plane kept apart.
    let mut split: Option<PreparedPlc> = None;
    let prep = &base;
    // The message lists the boundary edges in the input's own terms.
    if open.load(Ordering::Relaxed) {
        return Err(crate::error::InputError::Invalid {
            file: plc.source.clone(),
            msg: crate::precheck::empty_domain_message(plc),
        }
        .into());
    }
    let mut first_dt = Some(first_dt?);
    // Input facets kept out of merging because their merged group could not be
    // triangulated in one plane.
    let mut keep_apart: Vec<usize> = Vec::new();
    let mut warnings = Vec::new();
    for &(dup, kept) in &prep.duplicates {
        warnings.push(format!(
            "point {} coincides with point {} at ({}, {}, {}) and is merged with it",
            dup as usize + plc.first_index,
            kept as usize + plc.first_index,
            plc.points[kept as usize][0],
            plc.points[kept as usize][1],
            plc.points[kept as usize][2]
        ));
    }
    let mut stats = PlcStats {
        inserter: opts.inserter,
        input_points: plc.points.len(),
        input_polygons: plc.facets.iter().map(|f| f.polygons.len()).sum(),
        duplicate_points: prep.duplicates.len(),
        ..Default::default()
    };
    // Steiner points on polygons, found by earlier attempts: (merged facet, point); and
    // split points on segments: (segment, parameter).
    let mut facet_points: Vec<(usize, Point)> = Vec::new();
    let mut presplits: Vec<(usize, f64)> = Vec::new();
    let mut first_work = 0u64;
    // A construction that leaves a few thick tets on facets is followed by others, each
    // started with one point off such a tet's facet; the first that leaves none is
    // taken, else the first construction.
    let stats0 = stats.clone();
    let mut retry: Option<Retry> = None;
    // Set when a retry's construction fails or does no better: the next point is tried,
    // or, when none is left, the first construction is taken.
    let mut retry_failed = false;
    let built = loop {
        if std::mem::take(&mut retry_failed) {
            if let Some(state) = retry.as_mut().and_then(|r| r.next(&stats0)) {
                (facet_points, presplits, stats, first_work) = state;
            } else if let Some(r) = retry.take() {
                let (b, st, fp) = r.fallback;
                (stats, facet_points) = (st, fp);
                break b;
            }
        }
        opts.check_cancel()?;
        let prep = split.as_ref().unwrap_or(&base);
        // A construction after the first stops where the restarts' bound would end it
        // anyway: one region around a far vertex can cost minutes.
        let work_limit = if stats.restarts == 0 {
            u64::MAX
        } else {
            restart_work_bound(first_work).saturating_sub(stats.work)
        };
        let result = match attempt(
            plc,
            first_dt.take(),
            [prep, merged],
            (&facet_points, &presplits),
            opts,
            (&mut stats, work_limit),
            progress,
        ) {
            Err(Error::Mesh(MeshError::Failed(msg)))
                if msg.starts_with(UNFLAT_GROUP) && retry.is_none() =>
            {
                // Which group failed is in the message; split it and start again.
                let sources: Vec<usize> = msg[UNFLAT_GROUP.len()..]
                    .split(':')
                    .next()
                    .unwrap_or("")
                    .split(',')
                    .filter_map(|s| s.trim().parse().ok())
                    .collect();
                if sources.is_empty() || sources.iter().all(|s| keep_apart.contains(s)) {
                    return Err(MeshError::Failed(msg[UNFLAT_GROUP.len()..].to_string()).into());
                }
                keep_apart.extend(sources);
                keep_apart.sort_unstable();
                keep_apart.dedup();
                split = Some(prepare::prepare_except(plc, opts.merge, &keep_apart)?);
                facet_points.clear();
                presplits.clear();
                continue;
            }
            r => r,
        };
        // In a retry, a failed construction only moves on to the next point.
        let outcome = match result {
            Ok(o) => o,
            Err(_) if retry.is_some() => {
                retry_failed = true;
                continue;
            }
            // Updates in place may lead a construction astray where restarts would
            // not: it is done again without them.
            Err(e) if stats.in_place_splits > 0 && !stats.in_place_off => {
                if debug() {
                    eprintln!("restart {} without updates in place: {e}", stats.restarts);
                }
                (facet_points, presplits, first_work, stats) = without_updates(&stats0);
                continue;
            }
            Err(Error::Mesh(MeshError::WorkBound)) => {
                return Err(still_conflicting(facet_points.len()));
            }
            Err(e) => return Err(e),
        };
        match outcome {
            Attempt::Done(built) => match retry.as_mut() {
                None if !built.retry_points.is_empty() => {
                    if debug() {
                        eprintln!("{} tets left on facets: retries", built.flat_left.0);
                    }
                    let points = built.retry_points.clone();
                    let r = retry.insert(Retry {
                        fallback: (built, stats.clone(), facet_points.clone()),
                        points,
                        next: 0,
                    });
                    (facet_points, presplits, stats, first_work) = r.start(&stats0);
                    continue;
                }
                None => break built,
                Some(r) => {
                    if debug() {
                        eprintln!(
                            "retry with {:?}: {} left, covering {}",
                            r.points[r.next], built.flat_left.0, built.first_point_covers
                        );
                    }
                    if built.flat_left.0 == 0 && !built.first_point_covers {
                        break built;
                    }
                    retry_failed = true;
                    continue;
                }
            },
            Attempt::Restart(more, splits) => {
                stats.restarts += 1;
                if stats.restarts == 1 {
                    first_work = stats.work;
                }
                if debug() {
                    eprintln!(
                        "restart {} work {} first {}",
                        stats.restarts, stats.work, first_work
                    );
                }
                let over_steiner = facet_points.len() + more.len() > opts.max_steiner;
                // Restarts may cost far more than the first attempt when the polygons'
                // vertices are wildly off their planes: bound that work too.
                let over_work = stats.restarts > MAX_RESTARTS
                    || facet_points.len() + more.len() + presplits.len() + splits.len()
                        > max_facet_points(plc)
                    || stats.work > restart_work_bound(first_work);
                if (over_steiner || over_work) && retry.is_some() {
                    retry_failed = true;
                    continue;
                }
                if (over_steiner || over_work) && stats.in_place_splits > 0 && !stats.in_place_off {
                    (facet_points, presplits, first_work, stats) = without_updates(&stats0);
                    continue;
                }
                if over_steiner {
                    return Err(MeshError::Failed(format!(
                        "polygons that are not flat need more than {} Steiner points (the -S limit)",
                        opts.max_steiner
                    ))
                    .into());
                }
                if over_work {
                    return Err(still_conflicting(facet_points.len()));
                }
                facet_points.extend(more);
                presplits.extend(splits);
            }
        }
    };
    let prep = split.as_ref().unwrap_or(&base);
    let free = facet_points.iter().filter(|p| p.0 == FREE_POINT).count();
    stats.facet_steiner_points += facet_points.len() - free;
    stats.free_steiner_points += free;
    let (flat, first) = built.flat_left;
    stats.flat_tets_left = flat;
    if let Some(f) = first.filter(|_| flat > 0) {
        let why = if stats.free_searches_cut > 0 {
            "which the search for free Steiner points, cut short at its bound on work (a \
             vertex far out of the model's scale makes it long), did not remove"
        } else {
            "which no free Steiner point could remove"
        };
        warnings.push(format!(
            "{flat} flat tet(s) with all four vertices on one facet remain, the first on facet \
             {}: steps or dents of facets that are not flat, {why} (checks for shim tets flag \
             them)",
            facet_name(plc, &merged.facets[f as usize])
        ));
    }
    let mesh = finish(plc, prep, *built, opts, &mut stats, progress)?;
    Ok(PlcMesh {
        mesh,
        stats,
        warnings,
    })
}

/// The state of the constructions that follow one leaving a few thick tets on facets.
struct Retry {
    /// The first construction, with its figures and points: taken if no retry does better.
    fallback: (Box<Built>, PlcStats, Vec<FacetPoint>),
    /// The points to start the others with, one each.
    points: Vec<Point>,
    /// The one being tried.
    next: usize,
}

/// What a construction starts from: its points, splits, figures and first work.
type StartState = (Vec<FacetPoint>, Vec<SegmentSplit>, PlcStats, u64);

impl Retry {
    /// The state to start the construction with the current point.
    fn start(&self, stats0: &PlcStats) -> StartState {
        (
            vec![(FREE_POINT, self.points[self.next])],
            Vec::new(),
            stats0.clone(),
            0,
        )
    }

    /// Moves on to the next point, if there is one.
    fn next(&mut self, stats0: &PlcStats) -> Option<StartState> {
        self.next += 1;
        (self.next < self.points.len()).then(|| self.start(stats0))
    }
}

/// A finished CDT, before carving and output.
struct Built {
    cdt: Cdt,
    /// The subsegments with their markers.
    seg_markers: FxHashMap<(VertexId, VertexId), i32>,
    /// The CDT's carving, if one was made since it last changed.
    carved: Option<Carved>,
    /// How many flat tets lie on one facet (of the all-merged facets), and the facet of
    /// the first.
    flat_left: (usize, Option<u32>),
    /// When a few tets are left on facets: points for another construction that may
    /// leave none (see [`slivers::flat_left`]).
    retry_points: Vec<Point>,
    /// Whether a face around the first earlier point (a retry's own point) lies on a
    /// facet beside its triangles.
    first_point_covers: bool,
}

/// A Steiner point found by an earlier attempt: (merged facet or [`FREE_POINT`], point).
type FacetPoint = (usize, Point);
/// A split asked for by an earlier attempt: (segment, parameter along it).
type SegmentSplit = (usize, f64);

enum Attempt {
    Done(Box<Built>),
    Restart(Vec<FacetPoint>, Vec<SegmentSplit>),
}

/// One construction from scratch: Delaunay, segments, facets. `prep` is the PLC as
/// meshed, `merged` with every coplanar group merged (for [`slivers`]).
fn attempt(
    plc: &Plc,
    built: Option<(Delaunay, f64)>,
    [prep, merged]: [&PreparedPlc; 2],
    (facet_points, presplits): (&[FacetPoint], &[SegmentSplit]),
    opts: &PlcOptions,
    (stats, work_limit): (&mut PlcStats, u64),
    progress: Progress<'_>,
) -> Result<Attempt, Error> {
    let n_input = plc.points.len();
    let mut points = plc.points.clone();
    points.extend(facet_points.iter().map(|&(_, p)| p));
    // Duplicated input points go to their representative; only those are meshed.
    let mut dt = match built {
        // Built beforehand, of the input points only.
        Some((dt, secs)) if facet_points.is_empty() => {
            stats.delaunay_secs = secs;
            dt
        }
        _ => {
            progress(Stage::Delaunay);
            let t0 = Instant::now();
            let dt = Delaunay::build(&points)?.dt;
            stats.delaunay_secs = t0.elapsed().as_secs_f64();
            dt
        }
    };

    progress(Stage::Segments);
    let t1 = Instant::now();
    let mut next_pert = points.len() as u32;
    let budget = opts.max_steiner.saturating_sub(facet_points.len());
    let mut subsegs = segments::recover_segments(
        &mut dt,
        &prep.segments,
        points.len(),
        &mut next_pert,
        budget,
        presplits,
        opts.cancel_flag(),
    )?;
    stats.segment_secs = t1.elapsed().as_secs_f64();
    stats.steiner_points = facet_points.len() + subsegs.steiner_points;

    progress(Stage::Facets);
    let t2 = Instant::now();
    let inv = dt.internal_ids(points.len());
    let seg_index: FxHashMap<(u32, u32), usize> = prep
        .segments
        .iter()
        .enumerate()
        .map(|(i, s)| ((s[0], s[1]), i))
        .collect();
    // Each subsegment takes the marker of the first facet that contains its segment.
    let mut seg_marker = vec![None; prep.segments.len()];
    for_each_facet_segment(prep, &seg_index, |fi, si| {
        seg_marker[si].get_or_insert(prep.facets[fi].marker);
    });
    // Sized up front: growing maps of this many entries rehashes them over and over.
    let pieces: usize = subsegs.chains.iter().map(|c| c.len() - 1).sum();
    let mut seg_markers = FxHashMap::with_capacity_and_hasher(pieces, rustc_hash::FxBuildHasher);
    let mut seg_of: FxHashMap<(VertexId, VertexId), usize> =
        FxHashMap::with_capacity_and_hasher(pieces, rustc_hash::FxBuildHasher);
    for (i, chain) in subsegs.chains.iter().enumerate() {
        for w in chain.windows(2) {
            seg_markers.insert(edge_key(w[0], w[1]), seg_marker[i].unwrap_or(0));
            seg_of.insert(edge_key(w[0], w[1]), i);
        }
    }
    let mut extra: Vec<Vec<VertexId>> = vec![Vec::new(); prep.facets.len()];
    for (k, &(f, _)) in facet_points.iter().enumerate() {
        let v = inv[n_input + k];
        if v != u32::MAX && f != FREE_POINT {
            extra[f].push(v);
        }
    }
    // Each facet's triangles depend only on its vertices and subsegments, not on the
    // tets: all are computed up front, on two cores, and only they are indexed for the
    // lookups of the mesh faces.
    let t_surface = Instant::now();
    let mut facet_tris =
        FacetContext::new(plc, prep, &dt, &inv, &seg_index, &subsegs, &extra).triangulate_all();
    stats.surface_secs = t_surface.elapsed().as_secs_f64();
    let wanted: Vec<[VertexId; 3]> = facet_tris
        .iter()
        .flat_map(|r| r.as_ref().ok().into_iter().flatten().flatten())
        .map(|t| face_key(*t))
        .collect();
    let mut cdt = Cdt::new(dt);
    cdt.work_limit = work_limit;
    cdt.index_faces_of(&wanted);
    cdt.subfaces.reserve(wanted.len());
    let mut splits: Vec<(usize, f64)> = Vec::new();
    cdt.subsegs = seg_markers.clone();
    let mut queue: Vec<usize> = (0..prep.facets.len()).collect();
    queue.reverse();
    let mut queued = vec![true; prep.facets.len()];
    let mut steiner: Vec<(usize, Point)> = Vec::new();
    let mut steiner_facets: FxHashSet<usize> = FxHashSet::default();
    let mut rounds = 0usize;
    let max_rounds = 20 * prep.facets.len() + 1000;
    // Steiner points put on facets in this attempt, and the subsegments' ends they check.
    let mut placed_on_facets = 0usize;
    // Updates of the CDT in place of a restart (see `split_encroached`), bounded in all
    // and for each Steiner point (one that keeps asking for them is better made an
    // input vertex).
    let mut in_place = 0usize;
    let mut in_place_for: FxHashMap<[u64; 3], usize> = FxHashMap::default();
    // The splits and points they made, for the next construction if there is one.
    let mut carried: (Vec<SegmentSplit>, Vec<FacetPoint>) = (Vec::new(), Vec::new());
    let mut ends = None;
    // Facets to triangulate again once the current one is done (after a subsegment was
    // split in place), and the facets of each segment, made when first needed.
    let mut retriangulate: Vec<usize> = Vec::new();
    let mut facets_of_seg: Option<Vec<Vec<usize>>> = None;
    stats.facet_steiner_points = 0;
    stats.free_steiner_points = 0;
    // Free points whose cavities wrap around subfaces go in with those facets taken out,
    // which are then recovered again: the facet recovery, the shims and the free points
    // run again, pass after pass, on the one CDT (the free points' rounds, their search
    // and its budget are counted over them all).
    // What the flat-tet search needs, made once when first needed (free points leave
    // the subsegments as they are, but facets recovered again may split some: then its
    // record of them is made again), and the segment splits it knows of.
    let mut search: Option<slivers::Search> = None;
    let mut search_splits = 0usize;
    // The free points put in with facets recovered again, and the points the first of
    // them stood in for a restart with.
    let mut free_in_place: Vec<VertexId> = Vec::new();
    let mut restart_instead: Option<Vec<FacetPoint>> = None;
    // Whether refused free points have given way to subsegment splits.
    let mut free_splits = false;
    let mut free_rounds = 0usize;
    let mut budget: Option<u64> = None;
    let mut carved: Option<Carved>;
    // The flat tets left on facets, when known (`None` after points went in).
    let mut flat_left: Option<(usize, Option<u32>)>;
    // The work of the construction before its free points (their search is bounded apart).
    let mut facet_work;
    'recover: loop {
        while let Some(fi) = queue.pop() {
            opts.check_cancel()?;
            queued[fi] = false;
            rounds += 1;
            if rounds > max_rounds {
                return Err(MeshError::Failed("facet recovery does not converge".into()).into());
            }
            if steiner_facets.contains(&fi) {
                continue;
            }
            let f = &prep.facets[fi];
            let tris = match &facet_tris[fi] {
                Ok(Some(tris)) => tris,
                Ok(None) => continue,
                // The error is taken out to be returned.
                Err(_) => {
                    std::mem::replace(&mut facet_tris[fi], Ok(None))?;
                    continue;
                }
            };
            let mut missing = Vec::new();
            for t in tris {
                if cdt.has_face(t[0], t[1], t[2]) {
                    cdt.subfaces.insert(face_key(*t), fi as u32);
                } else {
                    missing.push(*t);
                }
            }
            let mut retriangulated = None;
            for region in regions_of(&missing, &seg_markers) {
                let fallbacks = stats.flips.fallbacks;
                let outcome = opts.inserter.insert(
                    &mut cdt,
                    &region,
                    fi as u32,
                    f.normal,
                    &mut stats.flips,
                )?;
                if stats.flips.fallbacks > fallbacks {
                    stats.flip_fallback_facets.push(fi as u32);
                }
                match outcome {
                    Outcome::Inserted(rs) => {
                        stats.regions += 1;
                        stats.recovered_subfaces += rs.subfaces;
                        stats.max_region_subfaces = stats.max_region_subfaces.max(rs.subfaces);
                        stats.crossing_tets += rs.crossing_tets;
                        stats.max_region_crossing_tets =
                            stats.max_region_crossing_tets.max(rs.crossing_tets);
                        stats.enlarged_tets += rs.enlarged_tets;
                        for lf in rs.lost {
                            if let Some(q) = queued.get_mut(lf as usize).filter(|q| !**q) {
                                *q = true;
                                queue.push(lf as usize);
                            }
                        }
                    }
                    Outcome::NeedsSteiner(p) => {
                        if debug() {
                            eprintln!("facet {fi}: Steiner point {p:?}");
                        }
                        // The point goes straight into the CDT, and the facet is triangulated
                        // again with it, if its triangles already in the mesh keep their
                        // place; otherwise the construction starts again with it.
                        let room = stats.steiner_points < opts.max_steiner
                            && placed_on_facets < max_facet_points(plc);
                        let asked = in_place_for.entry(p.map(f64::to_bits)).or_insert(0);
                        // Updates are meant to be cheaper than a restart: not once this
                        // construction has done a restart's worth of work.
                        let update = !stats.in_place_off
                            && in_place < MAX_IN_PLACE
                            && *asked < MAX_IN_PLACE_EACH
                            && stats.work + cdt.work.get() < RESTART_WORK / 4;
                        *asked += 1;
                        if room {
                            let at = ends.get_or_insert_with(|| free::subsegment_ends(&cdt));
                            let inserted = free::insert_point(&mut cdt, p, next_pert, at, false)?;
                            // Refused, and for which subsegment if one would be lost.
                            let refused = match &inserted {
                                free::Inserted::Refused { lost, .. } => Some(*lost),
                                _ => None,
                            };
                            if let free::Inserted::Yes { vertex, .. } = inserted {
                                extra[fi].push(vertex);
                                let ctx = FacetContext::new(
                                    plc, prep, &cdt.dt, &inv, &seg_index, &subsegs, &extra,
                                );
                                let again = ctx.triangles(fi);
                                if let Ok(Some(new)) = &again {
                                    let keys: FxHashSet<[VertexId; 3]> =
                                        new.iter().map(|t| face_key(*t)).collect();
                                    let kept = tris.iter().map(|t| face_key(*t)).all(|k| {
                                        cdt.subfaces.get(&k) != Some(&(fi as u32))
                                            || keys.contains(&k)
                                    });
                                    if kept {
                                        retriangulated = Some(again);
                                        next_pert += 1;
                                        placed_on_facets += 1;
                                        stats.steiner_points += 1;
                                        stats.facet_steiner_points += 1;
                                        queued[fi] = true;
                                        queue.push(fi);
                                        break;
                                    }
                                }
                                if debug() {
                                    eprintln!(
                                        "facet {fi}: its triangles would move with the point"
                                    );
                                }
                                extra[fi].pop();
                                free::take_back(&mut cdt, inserted);
                            } else if debug() {
                                eprintln!("facet {fi}: the CDT refuses the point");
                            }
                            // A point refused for encroaching upon a subsegment: the
                            // subsegment is split in place instead, and the facets through it
                            // are triangulated and recovered again (the paper's update of a
                            // CDT), which spares a whole construction. Failing that, the
                            // point lies on the facet, whose own subfaces need not wall it
                            // in: without them (and those it wraps around) it may go in, and
                            // the facets are triangulated with it and recovered again.
                            let mut segs = Segs {
                                subsegs: &mut subsegs,
                                seg_of: &mut seg_of,
                                markers: &mut seg_markers,
                                facets_of: &mut facets_of_seg,
                            };
                            let (mut split, mut unrecovered) = (None, None);
                            if let (Some(lost), true) = (refused, update) {
                                split = split_encroached(
                                    &mut cdt, p, lost, &mut segs, prep, &seg_index, next_pert, 0,
                                )?;
                                if split.is_none() {
                                    match insert_unrecovered(&mut cdt, p, fi, next_pert, at)? {
                                        Ok(done) => unrecovered = Some(done),
                                        // Then the subsegment it would remove is split.
                                        Err(Some(lost)) => {
                                            split = split_encroached(
                                                &mut cdt,
                                                p,
                                                Some(lost),
                                                &mut segs,
                                                prep,
                                                &seg_index,
                                                next_pert,
                                                0,
                                            )?;
                                        }
                                        Err(None) => {}
                                    }
                                }
                            }
                            let mut points = 1;
                            let facets = match (split, unrecovered) {
                                (Some((facets, at_splits)), _) => {
                                    points = at_splits.len() as u32;
                                    carried.0.extend(at_splits);
                                    Some(facets)
                                }
                                (None, Some((v, facets))) => {
                                    if debug() {
                                        eprintln!(
                                            "facet {fi}: in with facets {facets:?} unrecovered"
                                        );
                                    }
                                    carried.1.push((fi, p));
                                    extra[fi].push(v);
                                    placed_on_facets += 1;
                                    stats.facet_steiner_points += 1;
                                    Some(facets)
                                }
                                (None, None) => {
                                    if debug() {
                                        eprintln!(
                                        "facet {fi}: no update in place (allowed {update}, refused for {refused:?})"
                                    );
                                    }
                                    None
                                }
                            };
                            if let Some(facets) = facets {
                                ends = None;
                                next_pert += points;
                                stats.steiner_points += points as usize;
                                count_update(&mut cdt, &mut in_place, stats);
                                retriangulate.extend(facets);
                                retriangulate.push(fi);
                                break;
                            }
                        }
                        steiner.push((fi, p));
                        steiner_facets.insert(fi);
                        break;
                    }
                    Outcome::SplitSubsegment(u, v) => {
                        if debug() {
                            eprintln!("facet {fi}: split subsegment {u}-{v}");
                        }
                        let seg = seg_of[&edge_key(u, v)];
                        splits.push((seg, midpoint_parameter(&cdt, &subsegs.chains[seg], u, v)));
                        steiner_facets.insert(fi);
                        break;
                    }
                }
            }
            if let Some(again) = retriangulated {
                facet_tris[fi] = again;
            }
            if !retriangulate.is_empty() {
                let ctx = FacetContext::new(plc, prep, &cdt.dt, &inv, &seg_index, &subsegs, &extra);
                let queues = (&mut queue, &mut queued[..]);
                triangulate_again(&ctx, retriangulate.drain(..), &mut facet_tris, queues);
            }
        }
        stats.facet_secs = t2.elapsed().as_secs_f64() - stats.surface_secs;
        facet_work = cdt.work.get();
        // The carving of the CDT as it stands, while nothing changes it.
        carved = None;
        if steiner.is_empty() && splits.is_empty() {
            let (more, c) = resolve_shims(&mut cdt, plc, opts);
            steiner.extend(more);
            carved = c;
        }

        flat_left = None;
        let mut recover_again = false;
        if steiner.is_empty() && splits.is_empty() && stats.restarts < MAX_FREE_ROUNDS {
            // Free points go straight into the CDT (`free.rs`), round after round; only if
            // none of a round's can does the construction start again with them.
            let search = search.get_or_insert_with(|| {
                search_splits = subsegs.steiner_points;
                flat_tet_search(plc, merged, &subsegs, &cdt, opts)
            });
            if search_splits != subsegs.steiner_points {
                search_splits = subsegs.steiner_points;
                search.seg_ends = segment_ends(&subsegs, &cdt.dt.orig);
            }
            let mut stuck = Vec::new();
            // Room for a restart (for free points or flat tets' splits) in this pass.
            let restart_room =
                stats.restarts < MAX_FREE_RESTARTS && stats.work + facet_work < RESTART_WORK / 4;
            // The search tests candidate places against the slabs near them and walks to
            // them; around a vertex far out of the model's scale the slabs' boxes grow and
            // the walks get long, and it gives up past this much work.
            let budget = budget.get_or_insert_with(|| {
                FREE_SEARCH_WORK_PER_SLOT * cdt.dt.mesh.num_slots() as u64 + FREE_SEARCH_WORK
            });
            while free_rounds < MAX_FREE_ROUNDS {
                free_rounds += 1;
                let found = slivers::free_points(&mut cdt, search, &mut carved, budget);
                flat_left = Some(found.found);
                let free = found.points;
                stuck = found.stuck;
                if debug() && !free.is_empty() {
                    eprintln!("free points {free:?}");
                }
                // They only improve a valid CDT: within -S, or not at all.
                let room = opts
                    .max_steiner
                    .saturating_sub(stats.steiner_points + stats.free_steiner_points);
                let free = &free[..free.len().min(room)];
                if free.is_empty() {
                    break;
                }
                let (added, refused) =
                    free::insert_free(&mut cdt, free, &mut next_pert, |cdt, v| {
                        !search.on_facet_around(cdt, v)
                    })?;
                stats.free_steiner_points += added;
                if added > 0 {
                    carved = None;
                    flat_left = None;
                    continue;
                }
                // None fits into the CDT as it stands: the construction starts again with
                // them, if that restart stays well within the bounds on restarts.
                if debug() {
                    eprintln!("free points refused by the CDT: {refused:?}");
                }
                // A point that an earlier attempt already had is not tried again.
                let new: Vec<FacetPoint> = refused
                    .iter()
                    .filter(|p| !facet_points.iter().any(|(_, q)| q == *p))
                    .map(|&p| (FREE_POINT, p))
                    .collect();
                // Rather than that, the refused points go in with the facets whose
                // subfaces their cavities wrap around taken out, and those are recovered
                // again. Only where the restart could still come: should a face around
                // such a point cover a facet once those are recovered, it does.
                let update = restart_room
                    && !new.is_empty()
                    && !stats.in_place_off
                    && in_place + refused.len() <= MAX_IN_PLACE;
                if update {
                    let at = ends.get_or_insert_with(|| free::subsegment_ends(&cdt));
                    match insert_free_unrecovering(&mut cdt, &refused, next_pert, at)? {
                        FreeInPlace::In(vertices, facets) => {
                            if debug() {
                                eprintln!(
                                    "free points {refused:?}: in with facets {facets:?} unrecovered"
                                );
                            }
                            for &v in &vertices {
                                free_in_place.push(v);
                                next_pert += 1;
                                stats.free_steiner_points += 1;
                                count_update(&mut cdt, &mut in_place, stats);
                            }
                            for g in facets {
                                enqueue(&mut queue, &mut queued, g);
                            }
                            recover_again = true;
                        }
                        FreeInPlace::Encroaching(lost) if !free_splits => {
                            // As in Ruppert's refinement, a free point that would remove a
                            // subsegment gives way to a split of it (in place, with the
                            // facets through it triangulated and recovered again); the
                            // next round finds the flat tets' points anew. Once only: at
                            // a corner whose flat tets' spheres lie in a slab (`mpi.off`)
                            // the next points encroach again, closer to the corner each
                            // time. Nor are these splits carried into a restart, which
                            // is then the one they stood in for.
                            free_splits = true;
                            let mut segs = Segs {
                                subsegs: &mut subsegs,
                                seg_of: &mut seg_of,
                                markers: &mut seg_markers,
                                facets_of: &mut facets_of_seg,
                            };
                            let mut again = Vec::new();
                            for (p, e) in lost {
                                let split = split_encroached(
                                    &mut cdt,
                                    p,
                                    Some(e),
                                    &mut segs,
                                    prep,
                                    &seg_index,
                                    next_pert,
                                    0,
                                )?;
                                let Some((facets, at_splits)) = split else {
                                    continue;
                                };
                                if debug() {
                                    eprintln!("free point {p:?}: splits {at_splits:?} instead");
                                }
                                next_pert += at_splits.len() as u32;
                                stats.steiner_points += at_splits.len();
                                count_update(&mut cdt, &mut in_place, stats);
                                again.extend(facets);
                            }
                            if !again.is_empty() {
                                ends = None;
                                let ctx = FacetContext::new(
                                    plc, prep, &cdt.dt, &inv, &seg_index, &subsegs, &extra,
                                );
                                let queues = (&mut queue, &mut queued[..]);
                                triangulate_again(&ctx, again, &mut facet_tris, queues);
                                recover_again = true;
                            }
                        }
                        _ => {}
                    }
                    if recover_again {
                        restart_instead.get_or_insert_with(|| new.clone());
                        break;
                    }
                }
                if restart_room {
                    steiner.extend(new);
                }
                break;
            }
            if recover_again {
                continue 'recover;
            }
            stats.steiner_points += stats.free_steiner_points;

            // A flat tet whose circumsphere lies within its facet's slab spans a gap between
            // segments closer than the slab is thick. Its size, not its shape, makes it flat:
            // splitting its longest subsegment makes the tets there smaller against the gap.
            // Like free points, they only improve a valid CDT: only while the restart they
            // cost stays well within the bounds on restarts and their work.
            let affordable =
                restart_room && 2 * (presplits.len() + stuck.len()) <= max_facet_points(plc);
            if steiner.is_empty() && affordable {
                splits.extend(flat_tet_splits(&cdt, &stuck, &seg_of, &subsegs));
                if debug() && !splits.is_empty() {
                    eprintln!("flat tets {stuck:?}: splits {splits:?}");
                }
            }
        }
        break;
    }
    stats.work += facet_work;
    if budget == Some(0) {
        stats.free_searches_cut += 1;
    }
    if steiner.is_empty() && splits.is_empty() && !free_in_place.is_empty() {
        // A face around such a point that lies on a facet beside its triangles (in the
        // slab of a facet far from flat) makes the construction start again instead, with
        // the points as input vertices.
        let search =
            search.get_or_insert_with(|| flat_tet_search(plc, merged, &subsegs, &cdt, opts));
        let covering = free_in_place
            .iter()
            .any(|&v| search.covering_face_around(&cdt, v, false));
        if covering {
            if debug() {
                eprintln!("free points put in with facets recovered again cover a facet: restart");
            }
            steiner.extend(restart_instead.take().into_iter().flatten());
        }
    }
    if !steiner.is_empty() || !splits.is_empty() {
        // What the updates in place put in goes into the next construction too, which
        // would otherwise have to find it again. Free points put in with facets recovered
        // again stood in for a restart: the points it would have had go into this one.
        let (more_splits, more_points) = carried;
        splits.extend(more_splits);
        steiner.extend(more_points);
        for p in restart_instead.into_iter().flatten() {
            if !steiner.contains(&p) {
                steiner.push(p);
            }
        }
        return Ok(Attempt::Restart(steiner, splits));
    }
    let (flat_left, retry_points) = match flat_left {
        // Known, and too many (or none) for other constructions: no search needed.
        Some(known) if !(1..=MAX_RETRY_TETS).contains(&known.0) => (known, Vec::new()),
        _ => {
            let search =
                search.get_or_insert_with(|| flat_tet_search(plc, merged, &subsegs, &cdt, opts));
            slivers::flat_left(&mut cdt, search, &mut carved, MAX_RETRY_TETS)
        }
    };
    let first_point_covers = match facet_points.first() {
        Some(&(FREE_POINT, _)) => {
            let v = inv.get(n_input).copied().filter(|&v| v != u32::MAX);
            let search =
                search.get_or_insert_with(|| flat_tet_search(plc, merged, &subsegs, &cdt, opts));
            v.is_some_and(|v| search.covering_face_around(&cdt, v, true))
        }
        _ => false,
    };
    Ok(Attempt::Done(Box::new(Built {
        cdt,
        seg_markers,
        carved,
        flat_left,
        retry_points,
        first_point_covers,
    })))
}

/// What the search for flat tets on facets needs besides the CDT.
fn flat_tet_search<'a>(
    plc: &'a Plc,
    merged: &'a PreparedPlc,
    subsegs: &segments::Subsegments,
    cdt: &Cdt,
    opts: &PlcOptions,
) -> slivers::Search<'a> {
    slivers::Search {
        prep: merged,
        input: &plc.points,
        seg_ends: segment_ends(subsegs, &cdt.dt.orig),
        domain: slivers::Domain {
            holes: &plc.holes,
            regions: &plc.regions,
            keep_hull: opts.keep_hull,
        },
        index: Default::default(),
    }
}

/// The input ends of the segment of each Steiner point on one (`orig` maps vertices to
/// input indices), which name the facets a flat tet of such points may lie on.
fn segment_ends(subsegs: &segments::Subsegments, orig: &[u32]) -> FxHashMap<VertexId, [u32; 2]> {
    let mut seg_ends: FxHashMap<VertexId, [u32; 2]> = FxHashMap::default();
    for chain in subsegs.chains.iter().filter(|c| c.len() > 2) {
        let ends = [chain[0], chain[chain.len() - 1]].map(|x| orig[x as usize]);
        for &v in &chain[1..chain.len() - 1] {
            seg_ends.insert(v, ends);
        }
    }
    seg_ends
}

/// For each flat tet, the split of its longest edge that is a subsegment, as (segment,
/// parameter along it).
fn flat_tet_splits(
    cdt: &Cdt,
    stuck: &[[VertexId; 4]],
    seg_of: &FxHashMap<(VertexId, VertexId), usize>,
    subsegs: &segments::Subsegments,
) -> Vec<(usize, f64)> {
    let mut out: Vec<(usize, f64)> = Vec::new();
    let mut split: FxHashSet<(VertexId, VertexId)> = FxHashSet::default();
    for v in stuck {
        let len2 = |&(a, b): &(VertexId, VertexId)| {
            let d = crate::geom::sub(&cdt.dt.points[a as usize], &cdt.dt.points[b as usize]);
            crate::geom::dot(&d, &d)
        };
        let longest = crate::mesh::EDGE_VERTS
            .iter()
            .map(|&(i, j)| edge_key(v[i], v[j]))
            .filter(|e| seg_of.contains_key(e))
            .max_by(|x, y| len2(x).total_cmp(&len2(y)));
        if let Some(e) = longest {
            if split.insert(e) {
                let seg = seg_of[&e];
                out.push((seg, midpoint_parameter(cdt, &subsegs.chains[seg], e.0, e.1)));
            }
        }
    }
    out
}

/// The triangles of `tris` on the inner side of `f`'s rings, flooding across edges that
/// are not constraints.
fn inside_polygons(
    points: &[Point],
    tris: &[[VertexId; 3]],
    f: &prepare::MergedFacet,
    inv: &[VertexId],
    seg_index: &FxHashMap<(u32, u32), usize>,
    subsegs: &segments::Subsegments,
    constraints: &[[VertexId; 2]],
) -> Vec<[VertexId; 3]> {
    let n = f.normal;
    let axis = (0..3)
        .max_by(|&a, &b| n[a].abs().total_cmp(&n[b].abs()))
        .unwrap_or(2);
    let (u, w) = ((axis + 1) % 3, (axis + 2) % 3);
    let o2 = |a: VertexId, b: VertexId, c: VertexId| {
        let p = |v: VertexId| robust::Coord {
            x: points[v as usize][u],
            y: points[v as usize][w],
        };
        robust::orient2d(p(a), p(b), p(c))
    };
    let walls: FxHashSet<(VertexId, VertexId)> =
        constraints.iter().map(|c| edge_key(c[0], c[1])).collect();
    let mut by_edge: FxHashMap<(VertexId, VertexId), Vec<usize>> = FxHashMap::default();
    for (i, t) in tris.iter().enumerate() {
        for k in 0..3 {
            by_edge
                .entry(edge_key(t[k], t[(k + 1) % 3]))
                .or_default()
                .push(i);
        }
    }
    let mut keep = vec![false; tris.len()];
    let mut stack = Vec::new();
    for ring in &f.rings {
        // The ring's orientation in the projection (shoelace): its inner side.
        let area: f64 = (0..ring.len())
            .map(|k| {
                let (a, b) = (
                    points[inv[ring[k] as usize] as usize],
                    points[inv[ring[(k + 1) % ring.len()] as usize] as usize],
                );
                a[u] * b[w] - b[u] * a[w]
            })
            .sum();
        if area == 0.0 {
            continue;
        }
        for k in 0..ring.len() {
            let (a, b) = (ring[k], ring[(k + 1) % ring.len()]);
            let mut chain: Vec<VertexId> = match seg_index.get(&(a.min(b), a.max(b))) {
                Some(&si) => subsegs.chains[si].clone(),
                None => vec![inv[a as usize], inv[b as usize]],
            };
            if chain.first() != Some(&inv[a as usize]) {
                chain.reverse();
            }
            for e in chain.windows(2) {
                for &ti in by_edge
                    .get(&edge_key(e[0], e[1]))
                    .map(|x| x.as_slice())
                    .unwrap_or(&[])
                {
                    let x = tris[ti]
                        .iter()
                        .copied()
                        .find(|&x| x != e[0] && x != e[1])
                        .unwrap_or(e[0]);
                    if o2(e[0], e[1], x) * area > 0.0 && !keep[ti] {
                        keep[ti] = true;
                        stack.push(ti);
                    }
                }
            }
        }
    }
    while let Some(ti) = stack.pop() {
        let t = tris[ti];
        for k in 0..3 {
            let e = edge_key(t[k], t[(k + 1) % 3]);
            if walls.contains(&e) {
                continue;
            }
            for &tj in &by_edge[&e] {
                if !keep[tj] {
                    keep[tj] = true;
                    stack.push(tj);
                }
            }
        }
    }
    tris.iter()
        .zip(keep)
        .filter(|(_, k)| *k)
        .map(|(t, _)| *t)
        .collect()
}

/// What the triangulation of each facet needs: the facets, the vertices (internal ids
/// via `inv`), the subsegment chains and the Steiner points on facets.
struct FacetContext<'a> {
    plc: &'a Plc,
    prep: &'a PreparedPlc,
    points: &'a [Point],
    orig: &'a [u32],
    inv: &'a [VertexId],
    seg_index: &'a FxHashMap<(u32, u32), usize>,
    subsegs: &'a segments::Subsegments,
    extra: &'a [Vec<VertexId>],
}

/// A facet's triangles (`None` for a facet without rings), or why it has none.
type FacetTris = Result<Option<Vec<[VertexId; 3]>>, Error>;

impl<'a> FacetContext<'a> {
    /// The context of the facets of `prep` in the tetrahedralization `dt`.
    fn new(
        plc: &'a Plc,
        prep: &'a PreparedPlc,
        dt: &'a Delaunay,
        inv: &'a [VertexId],
        seg_index: &'a FxHashMap<(u32, u32), usize>,
        subsegs: &'a segments::Subsegments,
        extra: &'a [Vec<VertexId>],
    ) -> Self {
        FacetContext {
            plc,
            prep,
            points: &dt.points,
            orig: &dt.orig,
            inv,
            seg_index,
            subsegs,
            extra,
        }
    }

    /// Every facet's triangles; with enough work, the facets split in two halves of about
    /// equal work, one on a second core.
    fn triangulate_all(&self) -> Vec<FacetTris> {
        let facets = &self.prep.facets;
        let work: Vec<usize> = facets
            .iter()
            .map(|f| f.rings.iter().map(|r| r.len()).sum::<usize>() + f.isolated.len() + 1)
            .collect();
        let total: usize = work.iter().sum();
        // A thread costs more than a few small facets.
        if total < 4096 {
            return (0..facets.len()).map(|fi| self.triangles(fi)).collect();
        }
        let mut acc = 0;
        let half = work
            .iter()
            .position(|w| {
                acc += w;
                2 * acc >= total
            })
            .map_or(facets.len(), |i| i + 1);
        std::thread::scope(|s| {
            let second = s.spawn(|| (half..facets.len()).map(|fi| self.triangles(fi)).collect());
            let mut all: Vec<FacetTris> = (0..half).map(|fi| self.triangles(fi)).collect();
            let rest: Vec<FacetTris> = second
                .join()
                .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
            all.extend(rest);
            all
        })
    }

    /// Most facets of surface meshes are single triangles whose edges no Steiner point
    /// splits: their triangle, oriented as [`facet2d::single_triangle`] does, without
    /// gathering vertices and constraints. `None` for any other facet.
    fn unsplit_triangle(&self, f: &prepare::MergedFacet, fi: usize) -> Option<[VertexId; 3]> {
        let ([ring], [], [], [], [_]) = (
            &f.rings[..],
            &f.inner_segments[..],
            &f.isolated[..],
            &f.holes[..],
            &f.source_facets[..],
        ) else {
            return None;
        };
        if ring.len() != 3 || !self.extra[fi].is_empty() {
            return None;
        }
        for k in 0..3 {
            let (a, b) = (ring[k], ring[(k + 1) % 3]);
            if let Some(&si) = self.seg_index.get(&(a.min(b), a.max(b))) {
                if self.subsegs.chains[si].len() != 2 {
                    return None;
                }
            }
        }
        let mut t = [0, 1, 2].map(|k| self.inv[ring[k] as usize]);
        if t.contains(&u32::MAX) {
            return None;
        }
        t.sort_unstable();
        facet2d::single_triangle(self.points, t, f.normal)
    }

    /// The triangles of facet `fi`: its 2D CDT with its subsegments, restricted to its
    /// polygons.
    fn triangles(&self, fi: usize) -> FacetTris {
        let (plc, inv, seg_index, subsegs) = (self.plc, self.inv, self.seg_index, self.subsegs);
        let f = &self.prep.facets[fi];
        if let Some(t) = self.unsplit_triangle(f, fi) {
            return Ok(Some(vec![t]));
        }
        let mut verts: Vec<VertexId> = Vec::new();
        let mut constraints: Vec<[VertexId; 2]> = Vec::new();
        let add_edge =
            |a: u32, b: u32, verts: &mut Vec<VertexId>, cons: &mut Vec<[VertexId; 2]>| {
                match seg_index.get(&(a.min(b), a.max(b))) {
                    Some(&si) => {
                        let chain = &subsegs.chains[si];
                        verts.extend_from_slice(chain);
                        cons.extend(chain.windows(2).map(|w| [w[0], w[1]]));
                    }
                    None => {
                        verts.push(inv[a as usize]);
                        verts.push(inv[b as usize]);
                    }
                }
            };
        for_each_edge(f, |a, b| add_edge(a, b, &mut verts, &mut constraints));
        for &v in &f.isolated {
            verts.push(inv[v as usize]);
        }
        verts.extend_from_slice(&self.extra[fi]);
        if verts.contains(&u32::MAX) {
            return Err(MeshError::Internal(format!(
                "facet {fi} has a vertex missing from the mesh"
            ))
            .into());
        }
        verts.sort_unstable();
        verts.dedup();
        if f.rings.is_empty() {
            return Ok(None);
        }
        // Most facets of surface meshes are single triangles: no 2D CDT for them.
        let single = match (&f.rings[..], verts.len()) {
            ([ring], 3) if f.holes.is_empty() && f.source_facets.len() == 1 && ring.len() == 3 => {
                facet2d::single_triangle(self.points, [0, 1, 2].map(|k| verts[k]), f.normal)
            }
            _ => None,
        };
        let tris = match single {
            Some(t) => Ok(vec![t]),
            None => facet2d::triangulate_facet(
                self.points,
                self.orig,
                &verts,
                &constraints,
                &f.holes,
                f.normal,
            ),
        }
        .map_err(|e| {
            if debug() {
                eprintln!(
                    "facet {fi}: sources {:?} rings {:?}",
                    f.source_facets, f.rings
                );
                let o: Vec<(u32, u32)> = constraints
                    .iter()
                    .map(|c| (self.orig[c[0] as usize], self.orig[c[1] as usize]))
                    .collect();
                eprintln!("  constraints (output ids) {o:?}");
            }
            if f.source_facets.len() > 1 {
                let list: Vec<String> = f.source_facets.iter().map(|s| s.to_string()).collect();
                MeshError::Failed(format!(
                    "{UNFLAT_GROUP}{}: facet {}: {e}",
                    list.join(","),
                    facet_name(plc, f)
                ))
            } else {
                MeshError::Failed(format!("facet {}: {e}", facet_name(plc, f)))
            }
        })?;
        // A merged facet covers only its polygons: keep the triangles reachable from the
        // inner side of its polygons' edges without crossing a subsegment (gaps that the
        // polygons enclose without covering are not reachable from the hull's flood).
        if f.source_facets.len() > 1 {
            return Ok(Some(inside_polygons(
                self.points,
                &tris,
                f,
                inv,
                seg_index,
                subsegs,
                &constraints,
            )));
        }
        Ok(Some(tris))
    }
}

/// Inserts point `p` (perturbation index `pert`), on facet `fi`, into the CDT with the
/// facet's subfaces taken out, so that they do not wall its cavity in, and those of up to
/// [`MAX_UNRECOVERED`] more facets whose subfaces are in its way (see
/// [`insert_unrecovering`]). Its vertex and the facets taken out, to be triangulated and
/// recovered again; or, with the subfaces put back, the subsegment it would remove, if
/// that is why the CDT refuses it all the same. `at` as for [`free::insert_point`]
/// (taking subfaces out leaves it).
fn insert_unrecovered(
    cdt: &mut Cdt,
    p: Point,
    fi: usize,
    pert: u32,
    at: &crate::mesh::VertexLists<VertexId>,
) -> Result<Unrecovered, MeshError> {
    let mut facets = vec![fi];
    let mut removed = take_out_subfaces(cdt, |f| f as usize == fi);
    let limit = 1 + MAX_UNRECOVERED;
    let inserted = insert_unrecovering(cdt, (p, pert), at, (&mut facets, limit), &mut removed)?;
    Ok(match inserted {
        free::Inserted::Yes { vertex, .. } => Ok((vertex, facets)),
        refused => {
            cdt.subfaces.extend(removed);
            Err(match refused {
                free::Inserted::Refused { lost, .. } => lost,
                _ => None,
            })
        }
    })
}

/// Triangulates facets `gs` again (a subsegment on them was split) into `facet_tris`, and
/// queues them for recovery.
fn triangulate_again(
    ctx: &FacetContext<'_>,
    gs: impl IntoIterator<Item = usize>,
    facet_tris: &mut [FacetTris],
    (queue, queued): (&mut Vec<usize>, &mut [bool]),
) {
    for g in gs {
        facet_tris[g] = ctx.triangles(g);
        enqueue(queue, queued, g);
    }
}

/// Queues facet `g` for recovery, unless it is queued already.
fn enqueue(queue: &mut Vec<usize>, queued: &mut [bool], g: usize) {
    if !queued[g] {
        queued[g] = true;
        queue.push(g);
    }
}

/// Counts an update of the CDT in place of a restart. Updates stand in for restarts, and
/// are bounded as they are, by the work done before the first one.
fn count_update(cdt: &mut Cdt, in_place: &mut usize, stats: &mut PlcStats) {
    stats.in_place_splits += 1;
    *in_place += 1;
    if *in_place == 1 {
        let before = cdt.work.get();
        cdt.work_limit = cdt.work_limit.min(before + restart_work_bound(before));
    }
}

/// What [`insert_free_unrecovering`] did with a round's refused free points.
enum FreeInPlace {
    /// All went in: their vertices, and the facets to recover again.
    In(Vec<VertexId>, Vec<usize>),
    /// Each went in or would remove a subsegment, and those that did go in were taken
    /// back: the points that would, with their subsegments.
    Encroaching(Vec<(Point, (VertexId, VertexId))>),
    /// Some would do neither: nothing changed.
    No,
}

/// Inserts free points `ps` (perturbation indices from `pert` on), refused by the CDT as
/// it stands, each with the facets whose subfaces its cavity wraps around taken out (up
/// to [`MAX_UNRECOVERED`] for each): all of them, or none, with nothing changed (one left
/// out would make the construction start again anyway), and then the subsegments that
/// some would remove, if that is what kept them out.
fn insert_free_unrecovering(
    cdt: &mut Cdt,
    ps: &[Point],
    pert: u32,
    at: &crate::mesh::VertexLists<VertexId>,
) -> Result<FreeInPlace, MeshError> {
    let mut done: Vec<(free::Inserted, TakenOut)> = Vec::new();
    let mut facets = Vec::new();
    let mut lost = Vec::new();
    let mut left_out = false;
    for (k, &p) in ps.iter().enumerate() {
        let (mut through, mut removed) = (Vec::new(), Vec::new());
        let limit = MAX_UNRECOVERED;
        let pk = (p, pert + k as u32);
        let inserted = insert_unrecovering(cdt, pk, at, (&mut through, limit), &mut removed)?;
        match inserted {
            free::Inserted::Yes { .. } => {
                done.push((inserted, removed));
                facets.extend(through);
                continue;
            }
            free::Inserted::Refused { lost: Some(e), .. } => lost.push((p, e)),
            _ => left_out = true,
        }
        cdt.subfaces.extend(removed);
        if left_out {
            break;
        }
    }
    if lost.is_empty() && !left_out {
        facets.sort_unstable();
        facets.dedup();
        let vertices = done
            .iter()
            .filter_map(|(inserted, _)| match inserted {
                free::Inserted::Yes { vertex, .. } => Some(*vertex),
                _ => None,
            })
            .collect();
        return Ok(FreeInPlace::In(vertices, facets));
    }
    // Taken back in the reverse order, each while it is the last change.
    for (inserted, removed) in done.into_iter().rev() {
        free::take_back(cdt, inserted);
        cdt.subfaces.extend(removed);
    }
    Ok(if left_out {
        FreeInPlace::No
    } else {
        FreeInPlace::Encroaching(lost)
    })
}

/// Subfaces taken out of the CDT with their facets, to be put back.
type TakenOut = Vec<([VertexId; 3], u32)>;

/// Takes the subfaces of the facets that `of` picks out of the CDT (unrecovering those
/// facets), and returns them, to be put back with their facets.
fn take_out_subfaces(cdt: &mut Cdt, of: impl Fn(u32) -> bool) -> TakenOut {
    let out: TakenOut = cdt
        .subfaces
        .iter()
        .filter(|(_, &f)| of(f))
        .map(|(&k, &f)| (k, f))
        .collect();
    for (k, _) in &out {
        cdt.subfaces.remove(k);
    }
    out
}

/// Calls `f(facet, segment)` for each input segment on each facet's boundary or inside it.
fn for_each_facet_segment(
    prep: &PreparedPlc,
    seg_index: &FxHashMap<(u32, u32), usize>,
    mut f: impl FnMut(usize, usize),
) {
    for (fi, facet) in prep.facets.iter().enumerate() {
        for_each_edge(facet, |a, b| {
            if let Some(&si) = seg_index.get(&(a.min(b), a.max(b))) {
                f(fi, si);
            }
        });
    }
}

/// What [`insert_unrecovered`] did: the point's vertex and the facets taken out, or
/// (refused) the subsegment the point would remove, if that is why.
type Unrecovered = Result<(VertexId, Vec<usize>), Option<(VertexId, VertexId)>>;

/// The most facets besides its own that [`insert_unrecovered`] takes out for a point.
const MAX_UNRECOVERED: usize = 4;

/// The most updates of the CDT in place of a restart in one construction: each makes
/// facets recovered again, and where they keep needing more (polygons far from flat)
/// a restart, with the points as input vertices, settles it sooner.
const MAX_IN_PLACE: usize = 64;

/// The most updates in place for one Steiner point: past them, its splits have been
/// closing in on it without settling it.
const MAX_IN_PLACE_EACH: usize = 8;

/// How many subsegments [`split_encroached`] passes the split on to, one after another.
const MAX_SPLIT_DEPTH: usize = 4;

/// The segments' state that splitting a subsegment in place updates.
struct Segs<'a> {
    subsegs: &'a mut segments::Subsegments,
    seg_of: &'a mut FxHashMap<(VertexId, VertexId), usize>,
    markers: &'a mut FxHashMap<(VertexId, VertexId), i32>,
    /// The facets through each segment, made when first needed.
    facets_of: &'a mut Option<Vec<Vec<usize>>>,
}

impl Segs<'_> {
    /// Takes subsegment `e` out of the constraints, so that a point may go in on it; its
    /// marker, to put it back with ([`Segs::put_back`]) or to give its pieces.
    fn take_out(&mut self, cdt: &mut Cdt, e: (VertexId, VertexId)) -> i32 {
        cdt.subsegs.remove(&e);
        self.markers.remove(&e).unwrap_or(0)
    }

    /// Puts subsegment `e` back among the constraints, with its marker.
    fn put_back(&mut self, cdt: &mut Cdt, e: (VertexId, VertexId), marker: i32) {
        self.markers.insert(e, marker);
        cdt.subsegs.insert(e, marker);
    }

    /// Records vertex `w`, put in on subsegment `e` (taken out) of segment `seg`, as
    /// splitting it: its two pieces take its place in the chain and the constraints.
    fn record_split(
        &mut self,
        cdt: &mut Cdt,
        seg: usize,
        e: (VertexId, VertexId),
        w: VertexId,
        marker: i32,
    ) {
        let chain = &mut self.subsegs.chains[seg];
        if let Some(i) = chain.windows(2).position(|x| edge_key(x[0], x[1]) == e) {
            chain.insert(i + 1, w);
        }
        self.subsegs.steiner_points += 1;
        self.seg_of.remove(&e);
        for piece in [edge_key(e.0, w), edge_key(w, e.1)] {
            self.seg_of.insert(piece, seg);
            self.put_back(cdt, piece, marker);
        }
    }
}

/// Splits, in place, the subsegment that point `p` (a refused Steiner point on a
/// polygon) would remove (`lost`, when known) or else encroaches upon most closely, at
/// its middle (perturbation index `pert`).
/// The facets through it lose their subfaces (with those of facets whose subfaces are in
/// the split point's way), which the caller triangulates and recovers again; they are
/// returned, with the splits made (one, or several for [`split_group`]). `None`, with
/// nothing changed, if `p` encroaches upon no subsegment or the CDT refuses the split
/// point too.
#[allow(clippy::too_many_arguments)] // the recursion passes them all on
fn split_encroached(
    cdt: &mut Cdt,
    p: Point,
    lost: Option<(VertexId, VertexId)>,
    segs: &mut Segs<'_>,
    prep: &PreparedPlc,
    seg_index: &FxHashMap<(u32, u32), usize>,
    pert: u32,
    depth: usize,
) -> Result<Option<InPlaceSplit>, MeshError> {
    let pt = |x: VertexId| cdt.dt.points[x as usize];
    // Inside the diametral sphere: the angle at `p` is obtuse. The closest such
    // subsegment (by distance to its middle) is the one to split.
    let mut best: Option<((VertexId, VertexId), f64)> = lost
        .filter(|e| segs.markers.contains_key(e))
        .map(|e| (e, 0.0));
    for (&(u, v), _) in segs.markers.iter().filter(|_| lost.is_none()) {
        let (a, b) = (pt(u), pt(v));
        let along: f64 = (0..3).map(|k| (a[k] - p[k]) * (b[k] - p[k])).sum();
        if along >= 0.0 {
            continue;
        }
        let d: f64 = (0..3).map(|k| (0.5 * (a[k] + b[k]) - p[k]).powi(2)).sum();
        if best.is_none_or(|(e, bd)| d < bd || (d == bd && (u, v) < e)) {
            best = Some(((u, v), d));
        }
    }
    let Some(((u, v), _)) = best else {
        return Ok(None);
    };
    let seg = segs.seg_of[&(u, v)];
    let chain = &segs.subsegs.chains[seg];
    let s = midpoint_parameter(cdt, chain, u, v);
    let m = point_at(cdt, chain, s);
    let e = match split_at(cdt, &[((u, v), seg, s)], segs, prep, seg_index, pert)? {
        Ok(done) => return Ok(Some(done)),
        Err(Some(e)) if e != (u, v) && depth < MAX_SPLIT_DEPTH => e,
        Err(_) => return Ok(None),
    };
    // Two subsegments at a sharp corner encroach upon each other's middles: both are
    // split at once, at one distance from the corner (with those their split points
    // would remove).
    if let Some(done) = split_group(cdt, (u, v), e, segs, prep, seg_index, pert)? {
        return Ok(Some(done));
    }
    // A split point that would remove another subsegment splits that one instead, a few
    // levels deep (a chain of encroachments, as in Ruppert's refinement).
    split_encroached(cdt, m, Some(e), segs, prep, seg_index, pert, depth + 1)
}

/// Inserts point `m` (perturbation index `pert`) with [`free::insert_point`]; where a
/// subface of another facet is in its way, that facet is unrecovered too (its subfaces
/// go to `removed`, the facet to `through`, up to `limit` facets there) and the point
/// tried again.
fn insert_unrecovering(
    cdt: &mut Cdt,
    (m, pert): (Point, u32),
    at: &crate::mesh::VertexLists<VertexId>,
    (through, limit): (&mut Vec<usize>, usize),
    removed: &mut TakenOut,
) -> Result<free::Inserted, MeshError> {
    loop {
        let inserted = free::insert_point(cdt, m, pert, at, true)?;
        let g = match &inserted {
            free::Inserted::Refused {
                lost: None,
                wrapped: Some(face),
            } => cdt.subfaces.get(&face_key(*face)).map(|&g| g as usize),
            _ => None,
        };
        match g {
            Some(g) if through.len() < limit => {
                removed.extend(take_out_subfaces(cdt, |f| f as usize == g));
                through.push(g);
            }
            _ => return Ok(inserted),
        }
    }
}

/// An update in place by splits: the facets to triangulate and recover again, and the
/// splits made (carried into a restart, if one comes).
type InPlaceSplit = (Vec<usize>, Vec<SegmentSplit>);

/// The facets through the segments `of` (their lists made when first needed).
fn facets_through(
    segs: &mut Segs<'_>,
    prep: &PreparedPlc,
    seg_index: &FxHashMap<(u32, u32), usize>,
    of: &[usize],
) -> Vec<usize> {
    let facets = segs.facets_of.get_or_insert_with(|| {
        let mut of = vec![Vec::new(); prep.segments.len()];
        for_each_facet_segment(prep, seg_index, |fi, si| {
            if of[si].last() != Some(&fi) {
                of[si].push(fi);
            }
        });
        of
    });
    let mut through: Vec<usize> = of.iter().flat_map(|&g| facets[g].iter().copied()).collect();
    through.sort_unstable();
    through.dedup();
    through
}

/// Splits in place two subsegments `a` and `b` of segments that share an end, each of
/// whose middles would remove the other (segments at a sharp corner): both at the same
/// distance from that corner, the middle of the distances both span (Ruppert's
/// concentric shells), so that neither split point encroaches upon the other's pieces.
/// A split point that would remove another subsegment adds that one to the group (up to
/// [`MAX_GROUP`]): split on the shell too if it is a piece of a segment from the corner
/// that spans the shell's radius, else at its middle. Perturbation indices from `pert`
/// on. `None`, with nothing changed, if the segments share no end, the subsegments span
/// no common distance from it, or the CDT does not then have all the pieces as edges.
fn split_group(
    cdt: &mut Cdt,
    a: (VertexId, VertexId),
    b: (VertexId, VertexId),
    segs: &mut Segs<'_>,
    prep: &PreparedPlc,
    seg_index: &FxHashMap<(u32, u32), usize>,
    pert: u32,
) -> Result<Option<InPlaceSplit>, MeshError> {
    let (Some(&sa), Some(&sb)) = (segs.seg_of.get(&a), segs.seg_of.get(&b)) else {
        return Ok(None);
    };
    let ends = |segs: &Segs<'_>, g: usize| chain_ends(&segs.subsegs.chains[g]);
    let ((a0, a1), (b0, b1)) = (ends(segs, sa), ends(segs, sb));
    let Some(c) = [a0, a1]
        .into_iter()
        .find(|&x| sa != sb && (x == b0 || x == b1))
    else {
        if debug() {
            eprintln!("pair {a:?} {b:?}: no common end ({a0},{a1}) ({b0},{b1})");
        }
        return Ok(None);
    };
    // The distances from the corner that subsegment `e` spans.
    let span = |cdt: &Cdt, e: (VertexId, VertexId)| {
        let pt = |x: VertexId| cdt.dt.points[x as usize];
        let dist = |x: Point, y: Point| (0..3).map(|k| (x[k] - y[k]).powi(2)).sum::<f64>().sqrt();
        let (x, y) = (dist(pt(c), pt(e.0)), dist(pt(c), pt(e.1)));
        (x.min(y), x.max(y))
    };
    let (lo, hi) = {
        let ((la, ha), (lb, hb)) = (span(cdt, a), span(cdt, b));
        (la.max(lb), ha.min(hb))
    };
    if lo.partial_cmp(&hi) != Some(std::cmp::Ordering::Less) {
        if debug() {
            eprintln!("pair {a:?} {b:?}: no common span {lo} {hi}");
        }
        return Ok(None);
    }
    let r = 0.5 * (lo + hi);
    // The parameter along segment `g` at distance `r` from the corner.
    let on_shell = |cdt: &Cdt, segs: &Segs<'_>, g: usize| {
        let chain = &segs.subsegs.chains[g];
        let len = segment_length(cdt, chain);
        if chain[0] == c {
            r / len
        } else {
            1.0 - r / len
        }
    };
    let mut cut = vec![
        (a, sa, on_shell(cdt, segs, sa)),
        (b, sb, on_shell(cdt, segs, sb)),
    ];
    // Tried with the subsegments in `cut`; a split point that would remove another
    // subsegment adds it: on the shell if it spans the shell's radius on a segment from
    // the corner, else at its middle (as in Ruppert's refinement).
    loop {
        match split_at(cdt, &cut, segs, prep, seg_index, pert)? {
            Ok(done) => return Ok(Some(done)),
            Err(Some(e)) if cut.len() < MAX_GROUP && !cut.iter().any(|&(x, ..)| x == e) => {
                let Some(&g) = segs.seg_of.get(&e) else {
                    return Ok(None);
                };
                let (g0, g1) = ends(segs, g);
                let (x, y) = span(cdt, e);
                let s = if (g0 == c || g1 == c) && x < r && r < y {
                    on_shell(cdt, segs, g)
                } else {
                    midpoint_parameter(cdt, &segs.subsegs.chains[g], e.0, e.1)
                };
                cut.push((e, g, s));
            }
            Err(_) => return Ok(None),
        }
    }
}

/// The first and last vertices of a segment's chain: its ends.
fn chain_ends(chain: &[VertexId]) -> (VertexId, VertexId) {
    (chain[0], *chain.last().unwrap_or(&chain[0]))
}

/// The length of the segment whose chain is `chain`.
fn segment_length(cdt: &Cdt, chain: &[VertexId]) -> f64 {
    let p = |x: VertexId| cdt.dt.points[x as usize];
    let (a, b) = chain_ends(chain);
    let (pa, pb) = (p(a), p(b));
    (0..3).map(|k| (pb[k] - pa[k]).powi(2)).sum::<f64>().sqrt()
}

/// Splits the subsegments `cut` (each with its segment and the parameter along it of
/// its split point, with perturbation indices from `pert` on), all of them or none, in
/// place: the facets through their segments are unrecovered, since their subfaces would
/// wall the split points' cavities in on both sides (with those of facets whose subfaces
/// are in the way), and returned to be triangulated and recovered again with the splits.
/// When refused, nothing changed, with the subsegment a split point would remove if that
/// is why.
fn split_at(
    cdt: &mut Cdt,
    cut: &[((VertexId, VertexId), usize, f64)],
    segs: &mut Segs<'_>,
    prep: &PreparedPlc,
    seg_index: &FxHashMap<(u32, u32), usize>,
    pert: u32,
) -> Result<Result<InPlaceSplit, Option<(VertexId, VertexId)>>, MeshError> {
    let pt = |x: VertexId| cdt.dt.points[x as usize];
    // Each split point's parameter along its segment, and the point.
    let mut at_r = Vec::with_capacity(cut.len());
    for &(e, seg, s) in cut {
        let chain = &segs.subsegs.chains[seg];
        let m = point_at(cdt, chain, s);
        let (t0, t1) = (parameter(cdt, chain, e.0), parameter(cdt, chain, e.1));
        if !(t0.min(t1) < s && s < t0.max(t1)) || m == pt(e.0) || m == pt(e.1) {
            return Ok(Err(None));
        }
        at_r.push((e, seg, s, m));
    }
    let segments: Vec<usize> = cut.iter().map(|&(_, g, _)| g).collect();
    let mut through = facets_through(segs, prep, seg_index, &segments);
    let mut removed = take_out_subfaces(cdt, |f| through.contains(&(f as usize)));
    let markers: Vec<i32> = cut.iter().map(|&(e, ..)| segs.take_out(cdt, e)).collect();
    let at = free::subsegment_ends(cdt);
    let limit = through.len() + MAX_UNRECOVERED;
    // All points go in, or none: each may remove the others' subsegments alone.
    let mut done: Vec<(VertexId, free::Inserted)> = Vec::with_capacity(at_r.len());
    let mut lost = None;
    for (k, &(.., m)) in at_r.iter().enumerate() {
        let inserted = insert_unrecovering(
            cdt,
            (m, pert + k as u32),
            &at,
            (&mut through, limit),
            &mut removed,
        )?;
        match inserted {
            free::Inserted::Yes { vertex, .. } => done.push((vertex, inserted)),
            free::Inserted::Refused { lost: e, .. } => {
                lost = e;
                break;
            }
            free::Inserted::OnVertex => break,
        }
    }
    let pieces_in = done.len() == at_r.len()
        && at_r
            .iter()
            .zip(&done)
            .all(|(&(e, ..), &(w, _))| cdt.has_edge(e.0, w) && cdt.has_edge(w, e.1));
    if !pieces_in {
        if debug() {
            eprintln!(
                "splits {cut:?}: {} of {} in, pieces missing (lost {lost:?})",
                done.len(),
                at_r.len()
            );
        }
        for (_, inserted) in done.into_iter().rev() {
            free::take_back(cdt, inserted);
        }
        cdt.subfaces.extend(removed);
        for (&(e, ..), marker) in cut.iter().zip(markers) {
            segs.put_back(cdt, e, marker);
        }
        return Ok(Err(lost));
    }
    let n = at_r.len();
    let mut splits = Vec::with_capacity(n);
    for ((e, seg, s, m), ((w, _), marker)) in at_r.into_iter().zip(done.into_iter().zip(markers)) {
        if debug() {
            let (u, v) = e;
            eprintln!("split subsegment {u}-{v} in place at {m:?}, in a group of {n}: facets {through:?} again");
        }
        segs.record_split(cdt, seg, e, w, marker);
        splits.push((seg, s));
    }
    Ok(Ok((through, splits)))
}

/// The most subsegments that [`split_group`] splits at once. Groups of up to 16 spare a
/// few restarts against 8 (64 against 68 over 120 small fine stars); larger ones (all
/// the spokes of a fine fan, split on one shell) left flat tets on fine folded surfaces
/// after later restarts (124 on one small fine star with 32).
const MAX_GROUP: usize = 16;

/// The parameter of vertex `x` along the segment whose chain is `chain` (0 at its first
/// end, 1 at its last), of its projection on the line through them.
fn parameter(cdt: &Cdt, chain: &[VertexId], x: VertexId) -> f64 {
    let p = |x: VertexId| cdt.dt.points[x as usize];
    let (a, b) = chain_ends(chain);
    let (pa, pb) = (p(a), p(b));
    let d: [f64; 3] = std::array::from_fn(|k| pb[k] - pa[k]);
    let den: f64 = (0..3).map(|k| d[k] * d[k]).sum();
    (0..3).map(|k| (p(x)[k] - pa[k]) * d[k]).sum::<f64>() / den
}

/// The point at parameter `s` along the segment whose chain is `chain`.
fn point_at(cdt: &Cdt, chain: &[VertexId], s: f64) -> Point {
    let p = |x: VertexId| cdt.dt.points[x as usize];
    let (a, b) = chain_ends(chain);
    let (pa, pb) = (p(a), p(b));
    std::array::from_fn(|k| pa[k] + (pb[k] - pa[k]) * s)
}

/// The parameter along its segment (whose chain is `chain`) of the midpoint of `u`–`v`.
fn midpoint_parameter(cdt: &Cdt, chain: &[VertexId], u: VertexId, v: VertexId) -> f64 {
    0.5 * (parameter(cdt, chain, u) + parameter(cdt, chain, v))
}

/// Removes shim tets (four vertices on one facet) from the domain. A shim that carving
/// would keep has its two subfaces on the outer side; taking its other two faces as the
/// polygon's triangles instead puts it outside, where carving removes it. A shim that
/// both sides keep (an inner polygon) needs a Steiner point on the polygon: those points
/// are returned, and the construction starts again. Also returns the carving of the CDT
/// as left, if one was made.
fn resolve_shims(
    cdt: &mut Cdt,
    plc: &Plc,
    opts: &PlcOptions,
) -> (Vec<(usize, Point)>, Option<Carved>) {
    // A shim has four vertices on one facet, and facets of three vertices have none:
    // each vertex lists the facets of more than one subface it is on. These short lists
    // rule out most tets without looking up their faces. (Swaps below exchange a shim's
    // subfaces for its other faces, on the same four vertices: the lists stay right.)
    let on = {
        let facets = cdt.subfaces.values().max().map_or(0, |&f| f as usize + 1);
        let mut count = vec![0u32; facets];
        for &f in cdt.subfaces.values() {
            count[f as usize] += 1;
        }
        let mut pairs: Vec<(VertexId, u32)> = cdt
            .subfaces
            .iter()
            .filter(|(_, &f)| count[f as usize] > 1)
            .flat_map(|(k, &f)| k.map(|v| (v, f)))
            .collect();
        if pairs.is_empty() {
            return (Vec::new(), None);
        }
        pairs.sort_unstable();
        pairs.dedup();
        crate::mesh::VertexLists::new(cdt.dt.points.len(), pairs.into_iter())
    };
    let on_facet = |x: VertexId, f: u32| on.of(x).contains(&f);
    let mut carved = carve(cdt, &plc.holes, &plc.regions, opts.keep_hull);
    for _round in 0..64 {
        let kept = carved.kept_mask(cdt.dt.mesh.num_slots());
        let mut swapped: Vec<crate::mesh::TetId> = Vec::new();
        let mut needs: Vec<(usize, Point)> = Vec::new();
        for &t in &carved.tets {
            let v = cdt.dt.mesh.verts(t);
            if !on
                .of(v[0])
                .iter()
                .any(|&f| (1..4).all(|i| on_facet(v[i], f)))
            {
                continue;
            }
            let faces: [[VertexId; 3]; 4] =
                crate::mesh::FACE_VERTS.map(|fv| face_key([v[fv[0]], v[fv[1]], v[fv[2]]]));
            let Some(facet) = faces.iter().find_map(|k| cdt.subfaces.get(k).copied()) else {
                continue;
            };
            if !v.iter().all(|&x| on_facet(x, facet)) {
                continue;
            }
            let (sub, free): (Vec<[VertexId; 3]>, Vec<[VertexId; 3]>) =
                faces.iter().partition(|k| cdt.subfaces.contains_key(*k));
            // The shim can leave the domain only if nothing behind its subfaces is in it.
            let kept_behind_sub = sub.iter().any(|k: &[VertexId; 3]| {
                let i = (0..4).find(|&i| !k.contains(&v[i])).unwrap_or(0);
                kept[cdt.dt.mesh.adj(crate::mesh::FaceRef::new(t, i)).tet() as usize]
            });
            if debug() {
                eprintln!(
                    "shim {v:?} facet {facet} free {} kept_behind_sub {kept_behind_sub}",
                    free.len()
                );
            }
            if opts.keep_hull && kept_behind_sub {
                // With the hull kept, both sides of every polygon stay; a Steiner point
                // at a subface does not help slivers outside the polygon, so leave them.
                continue;
            }
            // Edges between the subfaces disappear with the swap. If one is a
            // subsegment, the shim stays: splitting the subsegment only makes smaller
            // shims of the same shape (a step or dent at a segment), so a flat one is
            // left to a free vertex (see `slivers`).
            let lost_subsegment = crate::mesh::EDGE_VERTS.iter().any(|&(i, j)| {
                let (a, b) = edge_key(v[i], v[j]);
                let in_faces = |fs: &[[VertexId; 3]]| {
                    fs.iter()
                        .filter(|k| k.contains(&a) && k.contains(&b))
                        .count()
                };
                in_faces(&sub) == 2 && in_faces(&free) == 0 && cdt.subsegs.contains_key(&(a, b))
            });
            if lost_subsegment {
                continue;
            }
            if free.is_empty() || kept_behind_sub {
                // Both sides of the polygon keep the shim: only a Steiner point helps.
                let f = sub[0].map(|x| cdt.dt.points[x as usize]);
                let c: Point = std::array::from_fn(|k| (f[0][k] + f[1][k] + f[2][k]) / 3.0);
                needs.push((facet as usize, c));
                continue;
            }
            for k in &sub {
                cdt.subfaces.remove(k);
            }
            for k in free {
                cdt.subfaces.insert(k, facet);
            }
            swapped.push(t);
        }
        // Swaps can uncover shims stacked behind others: Steiner points are only for
        // what no swap can remove.
        if swapped.is_empty() {
            return (needs, Some(carved));
        }
        if !opts.keep_hull && plc.regions.is_empty() {
            // A swap opens the shim's faces towards removed tets and closes its others:
            // the shim is removed, and nothing else changes, so no new flood is needed
            // (a full one cost 5% of a large model's time). With the hull kept,
            // nothing floods in from outside; region floods could have passed through
            // the shim: in those cases the carving starts afresh.
            swapped.sort_unstable();
            carved.tets.retain(|t| swapped.binary_search(t).is_err());
            carved.attributes = vec![0.0; carved.tets.len()];
            debug_assert_eq!(
                carved.tets,
                carve(cdt, &plc.holes, &plc.regions, opts.keep_hull).tets,
                "a shim swap changed the carving beyond its shim"
            );
        } else {
            carved = carve(cdt, &plc.holes, &plc.regions, opts.keep_hull);
        }
    }
    (Vec::new(), None)
}

/// Calls `f` on every edge of the facet's rings and inner segments.
fn for_each_edge(f: &prepare::MergedFacet, mut g: impl FnMut(u32, u32)) {
    for ring in &f.rings {
        for k in 0..ring.len() {
            g(ring[k], ring[(k + 1) % ring.len()]);
        }
    }
    for s in &f.inner_segments {
        g(s[0], s[1]);
    }
}

/// A facet's name for messages: its first input facet, numbered as in the file.
fn facet_name(plc: &Plc, f: &prepare::MergedFacet) -> String {
    let first = f.source_facets.first().copied().unwrap_or(0);
    let line = plc.facets.get(first).map(|x| x.line).unwrap_or(0);
    if line > 0 {
        format!("{} (line {line})", first + plc.first_index)
    } else {
        format!("{}", first + plc.first_index)
    }
}

/// Groups missing triangles into regions connected through shared edges that are not
/// subsegments.
fn regions_of(
    missing: &[[VertexId; 3]],
    subsegs: &FxHashMap<(VertexId, VertexId), i32>,
) -> Vec<Vec<[VertexId; 3]>> {
    let mut by_edge: FxHashMap<(VertexId, VertexId), Vec<usize>> = FxHashMap::default();
    for (i, t) in missing.iter().enumerate() {
        for k in 0..3 {
            by_edge
                .entry(edge_key(t[k], t[(k + 1) % 3]))
                .or_default()
                .push(i);
        }
    }
    let mut comp = vec![usize::MAX; missing.len()];
    let mut out = Vec::new();
    for s in 0..missing.len() {
        if comp[s] != usize::MAX {
            continue;
        }
        comp[s] = out.len();
        let mut region = Vec::new();
        let mut stack = vec![s];
        while let Some(i) = stack.pop() {
            region.push(missing[i]);
            let t = missing[i];
            for k in 0..3 {
                let e = edge_key(t[k], t[(k + 1) % 3]);
                if subsegs.contains_key(&e) {
                    continue;
                }
                for &j in &by_edge[&e] {
                    if comp[j] == usize::MAX {
                        comp[j] = out.len();
                        stack.push(j);
                    }
                }
            }
        }
        out.push(region);
    }
    out
}

/// Carves the mesh and puts it in output form.
fn finish(
    plc: &Plc,
    prep: &PreparedPlc,
    built: Built,
    opts: &PlcOptions,
    stats: &mut PlcStats,
    progress: Progress<'_>,
) -> Result<MeshOut, Error> {
    progress(Stage::Carve);
    let Built {
        mut cdt,
        seg_markers,
        carved,
        flat_left: _,
        retry_points: _,
        first_point_covers: _,
    } = built;
    let t = Instant::now();
    let carved =
        carved.unwrap_or_else(|| carve(&mut cdt, &plc.holes, &plc.regions, opts.keep_hull));
    stats.carve_secs = t.elapsed().as_secs_f64();
    if carved.tets.is_empty() {
        return Err(crate::error::InputError::Invalid {
            file: plc.source.clone(),
            msg: crate::precheck::empty_domain_message(plc),
        }
        .into());
    }
    let n_out = cdt
        .dt
        .orig
        .iter()
        .map(|&o| o as usize + 1)
        .max()
        .unwrap_or(0)
        .max(plc.points.len());
    let mut points = plc.points.clone();
    points.resize(n_out, [0.0; 3]);
    for (v, &o) in cdt.dt.orig.iter().enumerate() {
        points[o as usize] = cdt.dt.points[v];
    }
    let orig_ids = cdt.dt.orig.clone();
    let orig = |v: VertexId| orig_ids[v as usize];
    let mut kept = vec![false; cdt.dt.mesh.num_slots()];
    for &t in &carved.tets {
        kept[t as usize] = true;
    }
    let tets: Vec<[u32; 4]> = carved
        .tets
        .iter()
        .map(|&t| cdt.dt.mesh.verts(t).map(orig))
        .collect();
    // Each subface is found through the face index's hint (a walk only where the mesh
    // changed since), and written from a kept side: from the lower tet if both are kept.
    let mut keys: Vec<([VertexId; 3], u32)> = cdt.subfaces.iter().map(|(k, &f)| (*k, f)).collect();
    keys.sort_unstable();
    let mut subfaces: Vec<([u32; 3], i32)> = Vec::with_capacity(keys.len());
    for (k, f) in keys {
        let Some(a) = cdt.face_ref(k[0], k[1], k[2]) else {
            continue;
        };
        let b = cdt.dt.mesh.adj(a);
        let side = match (kept[a.tet() as usize], kept[b.tet() as usize]) {
            (true, true) if b.tet() < a.tet() => b,
            (true, _) => a,
            (false, true) => b,
            (false, false) => continue,
        };
        // Seen from the kept tet, as TetGen orients subfaces: they face into the mesh.
        let w = cdt.dt.mesh.face_verts(side.tet(), side.face()).map(orig);
        subfaces.push((w, prep.facets[f as usize].marker));
    }
    let mut subsegments: Vec<([u32; 2], i32)> = seg_markers
        .iter()
        .map(|(&(a, b), &m)| ([orig(a).min(orig(b)), orig(a).max(orig(b))], m))
        .collect();
    subsegments.sort_unstable();
    // A polygon dangling in the exterior (a fin on a surface) would be carved away with
    // it: its edges would bound no tet, and the mesh would silently lose a constraint.
    // One pass over the tets marks the subsegments found.
    let mut listed =
        crate::mesh::ListedEdges::new(n_out, subsegments.iter().map(|&([a, b], _)| (a, b)));
    listed.mark(tets.iter().copied());
    // `subsegments` is sorted: the flags are in its order.
    let found_edge = listed.flags();
    let lost = found_edge.iter().filter(|&&f| !f).count();
    if let Some(k) = found_edge.iter().position(|&f| !f) {
        let [a, b] = subsegments[k].0;
        let name = |v: u32| v as usize + plc.first_index;
        return Err(crate::error::InputError::Invalid {
            file: plc.source.clone(),
            msg: crate::precheck::exterior_polygon_message(plc, lost, (name(a), name(b))),
        }
        .into());
    }
    stats.output_tets = tets.len();
    stats.output_subfaces = subfaces.len();
    let n_attr = plc.num_point_attrs;
    let mut point_attrs = plc.point_attrs.clone();
    point_attrs.resize(n_out * n_attr, 0.0);
    let point_markers = plc.point_markers.clone().map(|mut m| {
        m.resize(n_out, 0);
        m
    });
    let (num_tet_attrs, tet_attrs) = if opts.region_attributes {
        (1, carved.attributes)
    } else {
        (0, Vec::new())
    };
    let mesh = MeshOut {
        points,
        num_point_attrs: n_attr,
        point_attrs,
        point_markers,
        tets,
        neighbors: Vec::new(),
        num_tet_attrs,
        tet_attrs,
        subfaces,
        subsegments,
        plc_mode: true,
        subfaces_oriented: true,
        first_index: plc.first_index,
        convex_hull_kept: opts.keep_hull,
        ..Default::default()
    };
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cancelled_run_stops_with_its_own_error() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("data/examples/box_with_hole.poly");
        let plc = crate::io::read_plc(&path).unwrap();
        let flag = Arc::new(AtomicBool::new(false));
        let opts = PlcOptions {
            cancel: Some(flag.clone()),
            wake_when_prepared: None,
            ..Default::default()
        };
        assert!(mesh_plc(&plc, &opts).is_ok());
        flag.store(true, Ordering::Relaxed);
        match mesh_plc(&plc, &opts) {
            Err(Error::Mesh(MeshError::Failed(m))) => assert_eq!(m, CANCELLED),
            Err(e) => panic!("unexpected error {e}"),
            Ok(_) => panic!("a cancelled run meshed"),
        }
    }
}
