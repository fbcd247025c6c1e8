//! Constrained Delaunay tetrahedralization of a PLC: preparation of the PLC, segment
//! recovery with Steiner points, and facet insertion; [`crate::carve`] then keeps its
//! domain.
//!
//! `construct` runs Delaunay → segments → facets, one construction
//! (`construction.rs`) after another. When a polygon that is not flat needs a Steiner
//! point on it (paper §3.1), the point goes into the CDT by a walled cavity and flips
//! (`free.rs`) and the polygon is triangulated again with it, or the CDT is updated in
//! place (`in_place.rs`); where neither can be done, the point is added to the facet and
//! the whole construction starts again from the Delaunay tetrahedralization.

mod bistellar;
pub mod cavity;
pub mod cdt;
pub(crate) mod construction;
pub(crate) mod domain;
pub mod enclosure;
pub mod flip;
mod flip_queue;
pub(crate) mod free;
mod in_place;
pub mod segments;
pub(crate) mod slivers;

pub(crate) use construction::regions_of;

use crate::delaunay::Delaunay;
use crate::error::{Error, MeshError};
use crate::geom::{facet2d, Point};
use crate::mesh::VertexId;
use crate::plc::prepare::{self, prepare, PreparedPlc};
use crate::plc::Plc;
use crate::progress::{Progress, Stage};
use cavity::{insert_region, Outcome};
use cdt::{edge_key, Cdt};
use construction::{attempt, Attempt, Built};
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
    /// Thick tets left with all four vertices on one facet: squashed within the slab
    /// of a facet that bends, where their faces may cover it beside its triangles.
    pub thick_tets_left: usize,
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
    /// Points added by quality refinement (`-q`, `-a`).
    pub refine_points: usize,
    /// Tets left over the quality bounds next to small input angles.
    pub refine_left: usize,
    /// Seconds for quality refinement.
    pub refine_secs: f64,
    /// The facet insertion algorithm used.
    pub inserter: FacetInserter,
    /// Flip insertion's figures (`-F`).
    pub flips: flip::FlipCounts,
    /// Facets whose regions fell back from flips to cavity retriangulation.
    pub flip_fallback_facets: Vec<u32>,
}

/// Whether to trace restarts, Steiner points, cavity widening and flip fallbacks on
/// stderr (`TETCDT_DEBUG=1`).
pub(crate) fn debug() -> bool {
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

/// The most restarts for Steiner points on polygons before giving up.
const MAX_RESTARTS: usize = 24;

/// Work ([`Cdt::work`]) that restarts may spend beyond eight times the first attempt's.
const RESTART_WORK: u64 = 20_000_000;

/// The work all restarts may do, by the first construction's `first` (see
/// [`RESTART_WORK`]).
fn restart_work_bound(first: u64) -> u64 {
    RESTART_WORK + 8 * first
}

/// The error of restarts that end over their bounds, after `points` Steiner points on
/// polygons.
fn still_conflicting(points: usize) -> Error {
    MeshError::Failed(format!(
        "polygons that are not flat still conflict after {points} Steiner points on them"
    ))
    .into()
}

/// A finished CDT of a PLC before carving: what [`crate::pipeline::mesh_plc`] carves, and what
/// [`crate::live::Cdt`] keeps to insert into.
pub(crate) struct Constructed {
    /// The CDT.
    pub built: Box<Built>,
    /// The PLC as meshed when some merged groups were kept apart (else `base`): its facet
    /// indices are the subfaces'.
    pub split: Option<PreparedPlc>,
    /// The PLC as prepared, which the certifier judges against.
    pub base: PreparedPlc,
    /// Figures.
    pub stats: PlcStats,
    /// Warnings for the user.
    pub warnings: Vec<String>,
}

/// The CDT of `plc`, not yet carved.
pub(crate) fn construct(
    plc: &Plc,
    opts: &PlcOptions,
    progress: Progress<'_>,
) -> Result<Constructed, Error> {
    progress(Stage::Delaunay);
    let ((base, all_merged, (keep_apart, split)), first_dt) = prepare_beside_delaunay(plc, opts)?;
    let merged = all_merged.as_ref().unwrap_or(&base);
    let mut warnings = duplicate_warnings(plc, &base);
    let stats = PlcStats {
        inserter: opts.inserter,
        input_points: plc.points.len(),
        input_polygons: plc.facets.iter().map(|f| f.polygons.len()).sum(),
        duplicate_points: base.duplicates.len(),
        ..Default::default()
    };
    let mut run = Constructions {
        plc,
        opts,
        base: &base,
        merged,
        split,
        keep_apart,
        first_dt: Some(first_dt),
        stats0: stats.clone(),
        stats,
        facet_points: Vec::new(),
        presplits: Vec::new(),
        first_work: 0,
        retry: None,
        retry_failed: false,
        best: None,
    };
    let built = loop {
        if let Next::Done(built) = run.step(progress)? {
            break built;
        }
    };
    let Constructions {
        mut stats,
        facet_points,
        split,
        ..
    } = run;
    let free = facet_points.iter().filter(|p| p.0 == FREE_POINT).count();
    stats.facet_steiner_points += facet_points.len() - free;
    stats.free_steiner_points += free;
    let left = built.flat_left;
    stats.flat_tets_left = left.flat;
    stats.thick_tets_left = left.tets - left.flat;
    if let Some(f) = left.first.filter(|_| left.tets > 0) {
        let facet = facet_name(plc, &merged.facets[f as usize]);
        warnings.push(flat_tets_warning(left, &facet, stats.free_searches_cut > 0));
    }
    Ok(Constructed {
        built,
        split,
        base,
        stats,
        warnings,
    })
}

/// A warning for each input point that coincides with an earlier one.
fn duplicate_warnings(plc: &Plc, prep: &PreparedPlc) -> Vec<String> {
    prep.duplicates
        .iter()
        .map(|&(dup, kept)| {
            let p = plc.points[kept as usize];
            format!(
                "point {} coincides with point {} at ({}, {}, {}) and is merged with it",
                dup as usize + plc.first_index,
                kept as usize + plc.first_index,
                p[0],
                p[1],
                p[2]
            )
        })
        .collect()
}

/// The constructions of one PLC, one after another, and what carries over between them.
struct Constructions<'a> {
    plc: &'a Plc,
    opts: &'a PlcOptions,
    /// The PLC as prepared, and with every coplanar group merged.
    base: &'a PreparedPlc,
    merged: &'a PreparedPlc,
    /// `base` with the groups that could not be triangulated in one plane kept apart
    /// (their input facets in `keep_apart`).
    split: Option<PreparedPlc>,
    keep_apart: Vec<usize>,
    /// The Delaunay tetrahedralization of the input points, made beside the preparation,
    /// for the first construction.
    first_dt: Option<(Delaunay, f64)>,
    stats: PlcStats,
    /// The figures as at the start.
    stats0: PlcStats,
    /// Steiner points on polygons found by earlier constructions: (merged facet, point);
    /// and split points on segments: (segment, parameter).
    facet_points: Vec<FacetPoint>,
    presplits: Vec<SegmentSplit>,
    /// The work of the first construction (bounds the restarts').
    first_work: u64,
    /// A construction that leaves a few thick tets on facets is followed by others, each
    /// started with one point off such a tet's facet; the first that leaves none is
    /// taken, else the first construction. `retry_failed` is set when a retry's
    /// construction fails or does no better: the next point is tried.
    retry: Option<Retry>,
    retry_failed: bool,
    /// The complete construction with the fewest tets on facets among those that asked
    /// for another only to improve on it: taken if the restarts end no better, or, if it
    /// left none, over their bounds (they only improve a valid CDT).
    best: Option<Kept>,
}

/// What [`Constructions::step`] leads to.
enum Next {
    /// Another construction.
    Again,
    /// The CDT to carve.
    Done(Box<Built>),
}

impl Constructions<'_> {
    /// One construction, and what comes after it.
    fn step(&mut self, progress: Progress<'_>) -> Result<Next, Error> {
        if std::mem::take(&mut self.retry_failed) {
            if let Some(state) = self.retry.as_mut().and_then(|r| r.next(&self.stats0)) {
                (
                    self.facet_points,
                    self.presplits,
                    self.stats,
                    self.first_work,
                ) = state;
            } else if let Some(r) = self.retry.take() {
                let (b, st, fp) = r.fallback;
                (self.stats, self.facet_points) = (st, fp);
                return Ok(Next::Done(b));
            }
        }
        self.opts.check_cancel()?;
        let prep = self.split.as_ref().unwrap_or(self.base);
        // A construction after the first stops where the restarts' bound would end it
        // anyway: one region around a far vertex can cost minutes.
        let work_limit = if self.stats.restarts == 0 {
            u64::MAX
        } else {
            restart_work_bound(self.first_work).saturating_sub(self.stats.work)
        };
        let result = attempt(
            self.plc,
            self.first_dt.take(),
            [prep, self.merged],
            (&self.facet_points, &self.presplits),
            self.opts,
            (&mut self.stats, work_limit),
            progress,
        );
        let outcome = match result {
            Ok(o) => o,
            Err(e) => return self.after_failure(e),
        };
        match outcome {
            Attempt::Done(built) => Ok(self.after_done(built)),
            Attempt::Restart(more, splits, fallback) => self.after_restart(more, splits, fallback),
        }
    }

    /// After a construction that failed with `e`.
    fn after_failure(&mut self, e: Error) -> Result<Next, Error> {
        match e {
            Error::Mesh(MeshError::UnflatGroup {
                sources,
                facet,
                reason,
            }) if self.retry.is_none() => {
                // The group is split and meshed again, unless it already was.
                if sources.is_empty() || sources.iter().all(|s| self.keep_apart.contains(s)) {
                    return Err(MeshError::Failed(format!("facet {facet}: {reason}")).into());
                }
                self.best = None;
                self.keep_apart.extend(sources);
                self.keep_apart.sort_unstable();
                self.keep_apart.dedup();
                self.split = Some(prepare::prepare_except(
                    self.plc,
                    self.opts.merge,
                    &self.keep_apart,
                )?);
                self.facet_points.clear();
                self.presplits.clear();
                Ok(Next::Again)
            }
            // In a retry, a failed construction only moves on to the next point.
            _ if self.retry.is_some() => {
                self.retry_failed = true;
                Ok(Next::Again)
            }
            // Updates in place may lead a construction astray where restarts would
            // not: it is done again without them.
            e if self.stats.in_place_splits > 0 && !self.stats.in_place_off => {
                if debug() {
                    eprintln!(
                        "restart {} without updates in place: {e}",
                        self.stats.restarts
                    );
                }
                self.start_without_updates();
                Ok(Next::Again)
            }
            Error::Mesh(MeshError::WorkBound) => match self.best.take() {
                Some(b) if b.0.tets_on_facets() == 0 => Ok(Next::Done(self.take_best(b))),
                _ => Err(still_conflicting(self.facet_points.len())),
            },
            e => Err(e),
        }
    }

    /// After a construction that ended with a CDT.
    fn after_done(&mut self, built: Box<Built>) -> Next {
        let Some(r) = self.retry.as_mut() else {
            if !built.retry_points.is_empty() {
                if debug() {
                    eprintln!("{} tets left on facets: retries", built.flat_left.tets);
                }
                let points = built.retry_points.clone();
                let r = self.retry.insert(Retry {
                    fallback: (built, self.stats.clone(), self.facet_points.clone()),
                    points,
                    next: 0,
                });
                (
                    self.facet_points,
                    self.presplits,
                    self.stats,
                    self.first_work,
                ) = r.start(&self.stats0);
                return Next::Again;
            }
            return match self.best.take() {
                Some(b) if b.0.tets_on_facets() < built.tets_on_facets() => {
                    if debug() {
                        eprintln!(
                            "{} tets on facets left: an earlier construction's {} taken",
                            built.tets_on_facets(),
                            b.0.tets_on_facets()
                        );
                    }
                    Next::Done(self.take_best(b))
                }
                _ => Next::Done(built),
            };
        };
        if debug() {
            eprintln!(
                "retry with {:?}: {} left, covering {}",
                r.points[r.next], built.flat_left.tets, built.first_point_covers
            );
        }
        if built.flat_left.tets == 0 && !built.first_point_covers {
            return Next::Done(built);
        }
        self.retry_failed = true;
        Next::Again
    }

    /// After a construction that asked for another with Steiner points `more` and
    /// segment splits `splits` (with its own CDT, `fallback`, when they only improve it).
    fn after_restart(
        &mut self,
        more: Vec<FacetPoint>,
        splits: Vec<SegmentSplit>,
        fallback: Option<Box<Built>>,
    ) -> Result<Next, Error> {
        self.stats.restarts += 1;
        if let Some(b) = fallback {
            if self
                .best
                .as_ref()
                .is_none_or(|x| b.tets_on_facets() < x.0.tets_on_facets())
            {
                self.best = Some((b, self.stats.clone(), self.facet_points.clone()));
            }
        }
        if self.stats.restarts == 1 {
            self.first_work = self.stats.work;
        }
        if debug() {
            eprintln!(
                "restart {} work {} first {}",
                self.stats.restarts, self.stats.work, self.first_work
            );
        }
        let points = self.facet_points.len() + more.len();
        let over_steiner = points > self.opts.max_steiner;
        // Restarts may cost far more than the first attempt when the polygons' vertices
        // are wildly off their planes: bound that work too.
        let over_work = self.stats.restarts > MAX_RESTARTS
            || points + self.presplits.len() + splits.len() > max_facet_points(self.plc)
            || self.stats.work > restart_work_bound(self.first_work);
        if over_steiner || over_work {
            // Past the bounds, an earlier construction is taken only if it left no tets on
            // facets; one that did is no mesh to succeed with.
            let clean = self
                .best
                .as_ref()
                .is_some_and(|b| b.0.tets_on_facets() == 0);
            if self.retry.is_none() && clean {
                if let Some(b) = self.best.take() {
                    return Ok(Next::Done(self.take_best(b)));
                }
            }
            if self.retry.is_some() {
                self.retry_failed = true;
                return Ok(Next::Again);
            }
            if self.stats.in_place_splits > 0 && !self.stats.in_place_off {
                self.start_without_updates();
                return Ok(Next::Again);
            }
            if over_steiner {
                return Err(MeshError::Failed(format!(
                    "polygons that are not flat need more than {} Steiner points (the -S limit)",
                    self.opts.max_steiner
                ))
                .into());
            }
            return Err(still_conflicting(self.facet_points.len()));
        }
        self.facet_points.extend(more);
        self.presplits.extend(splits);
        Ok(Next::Again)
    }

    /// Starts the constructions over with updates in place turned off: no points from
    /// earlier attempts, no work done.
    fn start_without_updates(&mut self) {
        self.stats = PlcStats {
            in_place_off: true,
            ..self.stats0.clone()
        };
        self.facet_points.clear();
        self.presplits.clear();
        self.first_work = 0;
    }

    /// Takes kept construction `kept` as the outcome: its figures and points replace the
    /// current ones, but the restarts made since are still counted.
    fn take_best(&mut self, (built, mut kept_stats, kept_points): Kept) -> Box<Built> {
        kept_stats.restarts = self.stats.restarts;
        self.stats = kept_stats;
        self.facet_points = kept_points;
        built
    }
}

/// The PLC as prepared; (without merging) as prepared with every group merged; and the
/// input facets of merged groups that cannot be triangulated in one plane, with the PLC
/// prepared again with them kept apart, if there are any.
type Prepared = (
    PreparedPlc,
    Option<PreparedPlc>,
    (Vec<usize>, Option<PreparedPlc>),
);

/// The PLC prepared (and, without merging, prepared again with every coplanar group
/// merged, on which flat tets are judged; with merging, the groups that cannot be
/// triangulated in one plane are kept apart from the start: their segments' Steiner
/// points can still make others so, see `Constructions::after_failure`) and its first
/// Delaunay tetrahedralization with its time: they do not depend on each other, and run
/// on two cores. An open surface is found once prepared (the Delaunay stage then stops
/// early) and refused.
fn prepare_beside_delaunay(
    plc: &Plc,
    opts: &PlcOptions,
) -> Result<(Prepared, (Delaunay, f64)), Error> {
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
            // switches and the splitting of groups did.
            let all_merged = if opts.merge {
                None
            } else {
                Some(prepare(plc, true)?)
            };
            let keep_apart = if opts.merge {
                prepare::unflat_groups(plc, &base)
            } else {
                Vec::new()
            };
            let split = match keep_apart.is_empty() {
                true => None,
                false => Some(prepare::prepare_except(plc, opts.merge, &keep_apart)?),
            };
            Ok((base, all_merged, (keep_apart, split)))
        });
        let t0 = Instant::now();
        let dt =
            Delaunay::build_until(&plc.points, &open).map(|b| (b.dt, t0.elapsed().as_secs_f64()));
        let prepared = preparing
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
        (prepared, dt)
    });
    let prepared = prepared?;
    // The message lists the boundary edges in the input's own terms.
    if open.load(Ordering::Relaxed) {
        return Err(crate::error::InputError::Invalid {
            file: plc.source.clone(),
            msg: crate::precheck::empty_domain_message(plc),
        }
        .into());
    }
    Ok((prepared, first_dt?))
}

/// The warning for the tets `left` on facets, the first on `facet` (`cut`: the search
/// for free points stopped at its bound on work).
fn flat_tets_warning(left: slivers::OnFacets, facet: &str, cut: bool) -> String {
    let why = if cut {
        "which the search for free Steiner points, cut short at its bound on work (a \
         vertex far out of the model's scale makes it long), did not remove"
    } else {
        "which no free Steiner point could remove"
    };
    let thick = left.tets - left.flat;
    let what = match (left.flat, thick) {
        (flat, 0) => format!("{flat} flat tet(s) with all four vertices on one facet remain"),
        (0, _) => format!(
            "{thick} thick tet(s) with all four vertices on one facet, squashed within the \
             slab where it bends, remain"
        ),
        (flat, _) => format!(
            "{flat} flat tet(s) with all four vertices on one facet remain, and {thick} \
             thick one(s) squashed within the slab of a facet that bends"
        ),
    };
    format!(
        "{what}, the first on facet {facet}: steps or dents of facets that are not flat, \
         {why} (checks for shim tets, `--check` among them, flag the flat ones)"
    )
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

/// A complete construction kept in case later ones do no better: its CDT, its figures
/// and the points it started from.
type Kept = (Box<Built>, PlcStats, Vec<FacetPoint>);

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

/// A Steiner point found by an earlier attempt: (merged facet or [`FREE_POINT`], point).
type FacetPoint = (usize, Point);
/// A split asked for by an earlier attempt: (segment, parameter along it).
type SegmentSplit = (usize, f64);

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
    let by_edge = cdt::triangles_by_edge(tris);
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
                MeshError::UnflatGroup {
                    sources: f.source_facets.clone(),
                    facet: facet_name(plc, f),
                    reason: e,
                }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Thick tets in a bent facet's slab are not called flat: a warning once said "302
    /// flat tet(s)" of a mesh with 52 flat ones.
    #[test]
    fn the_warning_tells_flat_tets_from_thick_ones() {
        let left = |tets, flat| slivers::OnFacets {
            tets,
            flat,
            first: Some(0),
        };
        let w = flat_tets_warning(left(3, 3), "7", false);
        assert!(
            w.starts_with(
                "3 flat tet(s) with all four vertices on one facet remain, the first on facet 7:"
            ),
            "{w}"
        );
        assert!(!w.contains("thick"), "{w}");
        let w = flat_tets_warning(left(302, 52), "90", false);
        assert!(
            w.starts_with(
                "52 flat tet(s) with all four vertices on one facet remain, and 250 thick one(s)"
            ),
            "{w}"
        );
        let w = flat_tets_warning(left(4, 0), "1", true);
        assert!(
            w.starts_with("4 thick tet(s) with all four vertices on one facet"),
            "{w}"
        );
        assert!(!w.contains("flat tet"), "{w}");
        assert!(w.contains("cut short"), "{w}");
    }

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
        assert!(crate::pipeline::mesh_plc(&plc, &opts).is_ok());
        flag.store(true, Ordering::Relaxed);
        match crate::pipeline::mesh_plc(&plc, &opts) {
            Err(Error::Mesh(MeshError::Failed(m))) => assert_eq!(m, CANCELLED),
            Err(e) => panic!("unexpected error {e}"),
            Ok(_) => panic!("a cancelled run meshed"),
        }
    }
}
