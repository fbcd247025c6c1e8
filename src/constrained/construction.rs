//! One construction of the CDT from scratch: the Delaunay tetrahedralization of the
//! input points (with the Steiner points earlier constructions asked for), segment
//! recovery, facet recovery with the updates in place its Steiner points need, shims
//! and free points for the flat tets left on facets. What it cannot settle in place it
//! hands back as the points and splits of the next construction.

use super::cavity::Outcome;
use super::cdt::{edge_key, face_key, triangles_by_edge, Cdt};
use super::domain::{domain, Domain};
use super::in_place::{
    for_each_facet_segment, insert_free_unrecovering, insert_unrecovered, midpoint_parameter,
    split_encroached, FreeInPlace, Segs, MAX_IN_PLACE, MAX_IN_PLACE_EACH,
};
use super::{
    debug, free, max_facet_points, restart_work_bound, segments, slivers, FacetContext, FacetPoint,
    FacetTris, PlcOptions, PlcStats, SegmentSplit, FREE_POINT, RESTART_WORK,
};
use crate::delaunay::Delaunay;
use crate::error::{Error, MeshError};
use crate::geom::Point;
use crate::mesh::VertexId;
use crate::plc::prepare::PreparedPlc;
use crate::plc::Plc;
use crate::progress::{Progress, Stage};
use rustc_hash::{FxHashMap, FxHashSet};
use std::time::Instant;

/// At most this many tets left on facets are worth other constructions (fans of needle
/// triangles leave many, which no single point removes).
const MAX_RETRY_TETS: usize = 4;

/// Rounds of free points (see [`slivers`]) in one construction.
const MAX_FREE_ROUNDS: usize = 12;

/// Work ([`slivers::free_points`]) that the search for free points may do in one
/// construction, per tet slot of the mesh (the corpus takes at most 17 per slot, on
/// `112544.off`)...
const FREE_SEARCH_WORK_PER_SLOT: u64 = 64;
/// ... and beyond that, for small meshes.
const FREE_SEARCH_WORK: u64 = 1_000_000;

/// Restarts after which free points the CDT refuses and flat-tet splits no longer start
/// the construction again: each costs a whole construction. Fans of needle triangles
/// need many: each restart's splits settle some flat tets and leave fewer new ones
/// (`112544.off` takes 11 to 13), but the count does not fall at every restart.
const MAX_FREE_RESTARTS: usize = 20;
const _: () = assert!(MAX_FREE_RESTARTS + 2 < super::MAX_RESTARTS);

/// Restarts after which flat tets' splits cut pieces to length at once, and flat tets
/// covering a facet get them too (before, a piece is halved).
const LENS_RESTARTS: usize = 3;

/// A piece split for a flat tet is cut into parts no longer than this many times the
/// distance from it to the tet's nearest other vertex (see [`flat_tet_splits`])...
const LENS_PIECE: f64 = 0.9;
/// ... and into at most this many.
const MAX_LENS_PARTS: usize = 64;

/// A finished CDT, before carving and output.
pub(crate) struct Built {
    pub cdt: Cdt,
    /// The subsegments with their markers.
    pub seg_markers: FxHashMap<(VertexId, VertexId), i32>,
    /// The CDT's carving, if one was made since it last changed.
    pub carved: Option<Domain>,
    /// The tets left with all four vertices on one facet (of the all-merged facets).
    pub flat_left: slivers::OnFacets,
    /// When a few tets are left on facets: points for another construction that may
    /// leave none (see [`slivers::flat_left`]).
    pub retry_points: Vec<Point>,
    /// Whether a face around the first earlier point (a retry's own point) lies on a
    /// facet beside its triangles.
    pub first_point_covers: bool,
    /// The flat tets that lie on no facet but cover one with a face (counted only after
    /// a restart, when constructions are compared).
    pub covering: usize,
}

impl Built {
    /// CDT `cdt` with subsegments `seg_markers`, nothing known of its flat tets.
    pub fn of(cdt: Cdt, seg_markers: FxHashMap<(VertexId, VertexId), i32>) -> Self {
        Built {
            cdt,
            seg_markers,
            carved: None,
            flat_left: slivers::OnFacets::default(),
            retry_points: Vec::new(),
            first_point_covers: false,
            covering: 0,
        }
    }

    /// How far it is from a mesh without tets on facets: the fewer the better.
    pub fn tets_on_facets(&self) -> usize {
        self.flat_left.tets + self.covering
    }
}

/// How a construction ended.
pub(super) enum Attempt {
    /// With a CDT.
    Done(Box<Built>),
    /// Asking for another, with these points and splits; with its own complete CDT when
    /// the points and splits only improve it (free points and flat tets' splits), to be
    /// taken if no later construction does better.
    Restart(Vec<FacetPoint>, Vec<SegmentSplit>, Option<Box<Built>>),
}

/// One construction from scratch: Delaunay, segments, facets. `prep` is the PLC as
/// meshed, `merged` with every coplanar group merged (for [`slivers`]).
pub(super) fn attempt(
    plc: &Plc,
    built: Option<(Delaunay, f64)>,
    [prep, merged]: [&PreparedPlc; 2],
    (facet_points, presplits): (&[FacetPoint], &[SegmentSplit]),
    opts: &PlcOptions,
    (stats, work_limit): (&mut PlcStats, u64),
    progress: Progress<'_>,
) -> Result<Attempt, Error> {
    let mut c = Construction::new(
        plc,
        built,
        [prep, merged],
        (facet_points, presplits),
        opts,
        (stats, work_limit),
        progress,
    )?;
    // Free points whose cavities wrap around subfaces go in with those facets taken out,
    // which are then recovered again: the facet recovery, the shims and the free points
    // run again, pass after pass, on the one CDT (the free points' rounds, their search
    // and its budget are counted over them all).
    loop {
        c.recover_facets()?;
        if !c.settle_flat_tets()? {
            break;
        }
    }
    c.finish()
}

/// The segments' state of construction `$c` that splits in place update, borrowed apart
/// from its CDT (a macro, since a method would borrow the whole construction).
macro_rules! segs {
    ($c:expr) => {
        Segs {
            subsegs: &mut $c.subsegs,
            seg_of: &mut $c.seg_of,
            markers: &mut $c.seg_markers,
            facets_of: &mut $c.facets_of_seg,
            prep: $c.prep,
            seg_index: &$c.seg_index,
        }
    };
}

/// The state of one construction, from its segment recovery on.
struct Construction<'a> {
    plc: &'a Plc,
    prep: &'a PreparedPlc,
    merged: &'a PreparedPlc,
    opts: &'a PlcOptions,
    /// The points of earlier constructions that this one starts with.
    facet_points: &'a [FacetPoint],
    /// The splits of earlier constructions that its segment recovery starts with.
    presplits: &'a [SegmentSplit],
    stats: &'a mut PlcStats,
    n_input: usize,
    /// Internal vertex ids of the points (input, then earlier Steiner points).
    inv: Vec<VertexId>,
    /// Each segment of `prep` by its input ends.
    seg_index: FxHashMap<(u32, u32), usize>,
    cdt: Cdt,
    subsegs: segments::Subsegments,
    seg_markers: FxHashMap<(VertexId, VertexId), i32>,
    seg_of: FxHashMap<(VertexId, VertexId), usize>,
    /// The Steiner points on each facet.
    extra: Vec<Vec<VertexId>>,
    facet_tris: Vec<FacetTris>,
    next_pert: u32,
    /// Facets to recover, and which are queued.
    queue: Vec<usize>,
    queued: Vec<bool>,
    /// Points and splits for the next construction, and the facets that asked for them.
    steiner: Vec<FacetPoint>,
    steiner_facets: FxHashSet<usize>,
    splits: Vec<SegmentSplit>,
    rounds: usize,
    max_rounds: usize,
    /// Steiner points put on facets in this construction.
    placed_on_facets: usize,
    /// Updates of the CDT in place of a restart (see `split_encroached`), bounded in all
    /// and for each Steiner point (one that keeps asking for them is better made an
    /// input vertex).
    in_place: usize,
    in_place_for: FxHashMap<[u64; 3], usize>,
    /// The splits and points they made, for the next construction if there is one.
    carried: (Vec<SegmentSplit>, Vec<FacetPoint>),
    /// Facets to triangulate again once the current one is done (after a subsegment was
    /// split in place), and the facets of each segment, made when first needed.
    retriangulate: Vec<usize>,
    facets_of_seg: Option<Vec<Vec<usize>>>,
    /// What the flat-tet search needs, made once when first needed.
    search: Option<slivers::Search<'a>>,
    /// The free points put in with facets recovered again, and the points the first of
    /// them stood in for a restart with.
    free_in_place: Vec<VertexId>,
    restart_instead: Option<Vec<FacetPoint>>,
    /// Whether refused free points have given way to subsegment splits.
    free_splits: bool,
    /// Whether the CDT is complete: facets recovered, free points put in.
    complete: bool,
    free_rounds: usize,
    budget: Option<u64>,
    /// The carving of the CDT as it stands, while nothing changes it.
    carved: Option<Domain>,
    /// The flat tets left on facets, when known (`None` after points went in).
    flat_left: Option<slivers::OnFacets>,
    /// The work of the construction before its free points (their search is bounded
    /// apart).
    facet_work: u64,
    /// When facet recovery started.
    t_facets: Instant,
}

impl<'a> Construction<'a> {
    /// Builds the Delaunay tetrahedralization (or takes `built`), recovers the segments
    /// and triangulates the facets, all queued for recovery.
    fn new(
        plc: &'a Plc,
        built: Option<(Delaunay, f64)>,
        [prep, merged]: [&'a PreparedPlc; 2],
        (facet_points, presplits): (&'a [FacetPoint], &'a [SegmentSplit]),
        opts: &'a PlcOptions,
        (stats, work_limit): (&'a mut PlcStats, u64),
        progress: Progress<'_>,
    ) -> Result<Self, Error> {
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
        let subsegs = segments::recover_segments(
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
        let t_facets = Instant::now();
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
        let mut seg_markers =
            FxHashMap::with_capacity_and_hasher(pieces, rustc_hash::FxBuildHasher);
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
        let facet_tris =
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
        cdt.subsegs = seg_markers.clone();
        let mut queue: Vec<usize> = (0..prep.facets.len()).collect();
        queue.reverse();
        stats.facet_steiner_points = 0;
        stats.free_steiner_points = 0;
        Ok(Construction {
            plc,
            prep,
            merged,
            opts,
            facet_points,
            presplits,
            stats,
            n_input,
            inv,
            seg_index,
            cdt,
            subsegs,
            seg_markers,
            seg_of,
            extra,
            facet_tris,
            next_pert,
            queue,
            queued: vec![true; prep.facets.len()],
            steiner: Vec::new(),
            steiner_facets: FxHashSet::default(),
            splits: Vec::new(),
            rounds: 0,
            max_rounds: 20 * prep.facets.len() + 1000,
            placed_on_facets: 0,
            in_place: 0,
            in_place_for: FxHashMap::default(),
            carried: (Vec::new(), Vec::new()),
            retriangulate: Vec::new(),
            facets_of_seg: None,
            search: None,
            free_in_place: Vec::new(),
            restart_instead: None,
            free_splits: false,
            complete: false,
            free_rounds: 0,
            budget: None,
            carved: None,
            flat_left: None,
            facet_work: 0,
            t_facets,
        })
    }

    /// Recovers the queued facets, with the Steiner points and updates in place they
    /// ask for.
    fn recover_facets(&mut self) -> Result<(), Error> {
        while let Some(fi) = self.queue.pop() {
            self.opts.check_cancel()?;
            self.queued[fi] = false;
            self.rounds += 1;
            if self.rounds > self.max_rounds {
                return Err(MeshError::Failed("facet recovery does not converge".into()).into());
            }
            if self.steiner_facets.contains(&fi) {
                continue;
            }
            // Taken out while the facet is recovered (an error is returned), and put back
            // unless the facet is triangulated again.
            let Some(tris) = std::mem::replace(&mut self.facet_tris[fi], Ok(None))? else {
                continue;
            };
            self.facet_tris[fi] = match self.recover_facet(fi, &tris)? {
                Some(again) => again,
                None => Ok(Some(tris)),
            };
            if !self.retriangulate.is_empty() {
                let gs = std::mem::take(&mut self.retriangulate);
                self.triangulate_again(gs);
            }
        }
        Ok(())
    }

    /// Recovers facet `fi`, whose triangles are `tris`, region after region. Its new
    /// triangles, if a Steiner point went in on it.
    fn recover_facet(
        &mut self,
        fi: usize,
        tris: &[[VertexId; 3]],
    ) -> Result<Option<FacetTris>, Error> {
        let normal = self.prep.facets[fi].normal;
        let missing = self.cdt.keep_present(tris, fi as u32);
        for region in regions_of(&missing, &self.seg_markers) {
            let stats = &mut *self.stats;
            let fallbacks = stats.flips.fallbacks;
            let outcome = self.opts.inserter.insert(
                &mut self.cdt,
                &region,
                fi as u32,
                normal,
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
                    let mut lost: Vec<u32> = rs.lost.iter().map(|&(_, f)| f).collect();
                    lost.sort_unstable();
                    lost.dedup();
                    for lf in lost {
                        if let Some(q) = self.queued.get_mut(lf as usize).filter(|q| !**q) {
                            *q = true;
                            self.queue.push(lf as usize);
                        }
                    }
                }
                Outcome::NeedsSteiner(p) => {
                    if debug() {
                        eprintln!("facet {fi}: Steiner point {p:?}");
                    }
                    return self.facet_point(fi, p, tris);
                }
                Outcome::SplitSubsegment(u, v) => {
                    if debug() {
                        eprintln!("facet {fi}: split subsegment {u}-{v}");
                    }
                    let seg = self.seg_of[&edge_key(u, v)];
                    let chain = &self.subsegs.chains[seg];
                    self.splits
                        .push((seg, midpoint_parameter(&self.cdt, chain, u, v)));
                    self.steiner_facets.insert(fi);
                    return Ok(None);
                }
            }
        }
        Ok(None)
    }

    /// Steiner point `p` on facet `fi` (whose triangles are `tris`): it goes straight into
    /// the CDT, and the facet is triangulated again with it (returned), if its triangles
    /// already in the mesh keep their place; otherwise an update in place (a split of a
    /// subsegment it encroaches upon, or the point in with the facets in its way
    /// unrecovered) is tried; failing that, the next construction gets it.
    fn facet_point(
        &mut self,
        fi: usize,
        p: Point,
        tris: &[[VertexId; 3]],
    ) -> Result<Option<FacetTris>, Error> {
        let room = self.stats.steiner_points < self.opts.max_steiner
            && self.placed_on_facets < max_facet_points(self.plc);
        let asked = self.in_place_for.entry(p.map(f64::to_bits)).or_insert(0);
        // Updates are meant to be cheaper than a restart: not once this construction has
        // done a restart's worth of work.
        let update = !self.stats.in_place_off
            && self.in_place < MAX_IN_PLACE
            && *asked < MAX_IN_PLACE_EACH
            && self.stats.work + self.cdt.work.get() < RESTART_WORK / 4;
        *asked += 1;
        if room {
            let inserted = free::insert_point(&mut self.cdt, p, self.next_pert, false)?;
            // Refused, and for which subsegment if one would be lost.
            let refused = match &inserted {
                free::Inserted::Refused { lost, .. } => Some(*lost),
                _ => None,
            };
            if let free::Inserted::Yes { vertex, .. } = inserted {
                self.extra[fi].push(vertex);
                let again = self.triangles(fi);
                if let Ok(Some(new)) = &again {
                    let keys: FxHashSet<[VertexId; 3]> = new.iter().map(|t| face_key(*t)).collect();
                    let kept = tris.iter().map(|t| face_key(*t)).all(|k| {
                        self.cdt.subfaces.get(&k) != Some(&(fi as u32)) || keys.contains(&k)
                    });
                    if kept {
                        self.next_pert += 1;
                        self.placed_on_facets += 1;
                        self.stats.steiner_points += 1;
                        self.stats.facet_steiner_points += 1;
                        self.queued[fi] = true;
                        self.queue.push(fi);
                        return Ok(Some(again));
                    }
                }
                if debug() {
                    eprintln!("facet {fi}: its triangles would move with the point");
                }
                self.extra[fi].pop();
                free::take_back(&mut self.cdt, inserted);
            } else if debug() {
                eprintln!("facet {fi}: the CDT refuses the point");
            }
            // A point refused for encroaching upon a subsegment: the subsegment is split
            // in place instead, and the facets through it are triangulated and recovered
            // again (the paper's update of a CDT), which spares a whole construction.
            // Failing that, the point lies on the facet, whose own subfaces need not wall
            // it in: without them (and those it wraps around) it may go in, and the
            // facets are triangulated with it and recovered again.
            let mut segs = segs!(self);
            let cdt = &mut self.cdt;
            let pert = self.next_pert;
            let (mut split, mut unrecovered) = (None, None);
            if let (Some(lost), true) = (refused, update) {
                split = split_encroached(cdt, p, lost, &mut segs, pert, 0)?;
                if split.is_none() {
                    match insert_unrecovered(cdt, p, fi, pert)? {
                        Ok(done) => unrecovered = Some(done),
                        // Then the subsegment it would remove is split.
                        Err(Some(lost)) => {
                            split = split_encroached(cdt, p, Some(lost), &mut segs, pert, 0)?;
                        }
                        Err(None) => {}
                    }
                }
            }
            let mut points = 1;
            let facets = match (split, unrecovered) {
                (Some((facets, at_splits)), _) => {
                    points = at_splits.len() as u32;
                    self.carried.0.extend(at_splits);
                    Some(facets)
                }
                (None, Some((v, facets))) => {
                    if debug() {
                        eprintln!("facet {fi}: in with facets {facets:?} unrecovered");
                    }
                    self.carried.1.push((fi, p));
                    self.extra[fi].push(v);
                    self.placed_on_facets += 1;
                    self.stats.facet_steiner_points += 1;
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
                self.next_pert += points;
                self.stats.steiner_points += points as usize;
                count_update(&mut self.cdt, &mut self.in_place, self.stats);
                self.retriangulate.extend(facets);
                self.retriangulate.push(fi);
                return Ok(None);
            }
        }
        self.steiner.push((fi, p));
        self.steiner_facets.insert(fi);
        Ok(None)
    }

    /// Triangulates facets `gs` again (a subsegment on them was split, or a point went
    /// in on them), and queues them for recovery.
    fn triangulate_again(&mut self, gs: impl IntoIterator<Item = usize>) {
        for g in gs {
            self.facet_tris[g] = self.triangles(g);
            enqueue(&mut self.queue, &mut self.queued, g);
        }
    }

    /// Facet `g`'s triangles, with the vertices and subsegments it has now.
    fn triangles(&self, g: usize) -> FacetTris {
        let (dt, extra) = (&self.cdt.dt, &self.extra);
        FacetContext::new(
            self.plc,
            self.prep,
            dt,
            &self.inv,
            &self.seg_index,
            &self.subsegs,
            extra,
        )
        .triangles(g)
    }

    /// After facet recovery: the shims, then rounds of free points for the flat tets
    /// left on facets, then splits for those the points cannot remove. Whether facets
    /// were taken out for free points, to be recovered again.
    fn settle_flat_tets(&mut self) -> Result<bool, Error> {
        self.complete = false;
        self.stats.facet_secs = self.t_facets.elapsed().as_secs_f64() - self.stats.surface_secs;
        self.facet_work = self.cdt.work.get();
        self.carved = None;
        if self.steiner.is_empty() && self.splits.is_empty() {
            let (more, c) = resolve_shims(&mut self.cdt, self.plc, self.opts);
            self.steiner.extend(more);
            self.carved = c;
        }
        self.flat_left = None;
        if !(self.steiner.is_empty()
            && self.splits.is_empty()
            && self.stats.restarts <= MAX_FREE_RESTARTS)
        {
            return Ok(false);
        }
        // Taken out while the rounds run, which change the rest of the state.
        let search = match self.search.take() {
            Some(search) => search,
            None => flat_tet_search(self.plc, self.merged, self.opts),
        };
        // Room for a restart (for free points or flat tets' splits) in this pass.
        let restart_room = self.stats.restarts < MAX_FREE_RESTARTS
            && self.stats.work + self.facet_work < RESTART_WORK / 4;
        let rounds = self.free_point_rounds(&search, restart_room);
        self.search = Some(search);
        let Some(mut stuck) = rounds? else {
            return Ok(true);
        };
        // Facets are recovered and free points put in: a CDT, whatever comes next.
        self.complete = true;
        self.stats.steiner_points += self.stats.free_steiner_points;

        // A flat tet that no free point removes is folded over a subsegment between
        // nearly coplanar facets, its sphere centred beyond the surface, or spans a gap
        // between segments closer than a facet's slab is thick. Splitting a subsegment of
        // it (see [`flat_tet_splits`]) changes that. Like free points, the splits only
        // improve a valid CDT: only while the restart they cost stays well within the
        // bounds on restarts, their work and the Steiner points on segments.
        if !(self.steiner.is_empty() && restart_room) {
            return Ok(false);
        }
        // Past the first restarts, the flat tets left are the stubborn kind: those on no
        // facet that cover one with a face need splits too, and pieces are cut to length
        // at once.
        let lens = self.stats.restarts >= LENS_RESTARTS;
        if let (true, Some(search)) = (lens, self.search.as_ref()) {
            let covering = slivers::covering_flat_tets(&mut self.cdt, search, &mut self.carved);
            if debug() {
                eprintln!("flat tets covering a facet {covering:?}");
            }
            stuck.extend(covering);
        }
        let more = flat_tet_splits(&self.cdt, &stuck, &self.seg_of, &self.subsegs, lens);
        if 2 * (self.presplits.len() + more.len()) <= max_facet_points(self.plc) {
            self.splits.extend(more);
            if debug() && !self.splits.is_empty() {
                eprintln!("flat tets {stuck:?}: splits {:?}", self.splits);
            }
        }
        Ok(false)
    }

    /// Free points go straight into the CDT (`free.rs`), round after round; only if none
    /// of a round's can does the construction start again with them, or, in its place,
    /// they go in with facets taken out or give way to subsegment splits (`None`: those
    /// facets are to be recovered again). Otherwise the flat tets that no point could be
    /// found for.
    fn free_point_rounds(
        &mut self,
        search: &slivers::Search<'a>,
        restart_room: bool,
    ) -> Result<Option<Vec<[VertexId; 4]>>, Error> {
        let mut stuck = Vec::new();
        // The search tests candidate places against the slabs near them and walks to
        // them; around a vertex far out of the model's scale the slabs' boxes grow and
        // the walks get long, and it gives up past this much work.
        let slots = self.cdt.dt.mesh.num_slots() as u64;
        let budget = self
            .budget
            .get_or_insert_with(|| FREE_SEARCH_WORK_PER_SLOT * slots + FREE_SEARCH_WORK);
        while self.free_rounds < MAX_FREE_ROUNDS {
            self.free_rounds += 1;
            let found = slivers::free_points(&mut self.cdt, search, &mut self.carved, budget);
            self.flat_left = Some(found.found);
            let free = found.points;
            stuck = found.stuck;
            if debug() && !free.is_empty() {
                eprintln!("free points {free:?}");
            }
            // They only improve a valid CDT: within -S, or not at all.
            let room = self
                .opts
                .max_steiner
                .saturating_sub(self.stats.steiner_points + self.stats.free_steiner_points);
            let free = &free[..free.len().min(room)];
            if free.is_empty() {
                break;
            }
            let (added, refused) =
                free::insert_free(&mut self.cdt, free, &mut self.next_pert, |cdt, v| {
                    !search.on_facet_around(cdt, v)
                })?;
            self.stats.free_steiner_points += added;
            if added > 0 {
                self.carved = None;
                self.flat_left = None;
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
                .filter(|p| !self.facet_points.iter().any(|(_, q)| q == *p))
                .map(|&p| (FREE_POINT, p))
                .collect();
            // Rather than that, the refused points go in with the facets whose subfaces
            // their cavities wrap around taken out, and those are recovered again. Only
            // where the restart could still come: should a face around such a point
            // cover a facet once those are recovered, it does.
            let update = restart_room
                && !new.is_empty()
                && !self.stats.in_place_off
                && self.in_place + refused.len() <= MAX_IN_PLACE;
            if update && self.free_in_place_update(&refused)? {
                self.restart_instead.get_or_insert_with(|| new.clone());
                return Ok(None);
            }
            if restart_room {
                self.steiner.extend(new);
            }
            break;
        }
        Ok(Some(stuck))
    }

    /// Puts free points `refused`, which the CDT refuses as it stands, in with the
    /// facets their cavities wrap around taken out, or else (once per construction)
    /// splits the subsegments they would remove. Whether either was done: the facets
    /// are then queued to be recovered again.
    fn free_in_place_update(&mut self, refused: &[Point]) -> Result<bool, Error> {
        match insert_free_unrecovering(&mut self.cdt, refused, self.next_pert)? {
            FreeInPlace::In(vertices, facets) => {
                if debug() {
                    eprintln!("free points {refused:?}: in with facets {facets:?} unrecovered");
                }
                for &v in &vertices {
                    self.free_in_place.push(v);
                    self.next_pert += 1;
                    self.stats.free_steiner_points += 1;
                    count_update(&mut self.cdt, &mut self.in_place, self.stats);
                }
                for g in facets {
                    enqueue(&mut self.queue, &mut self.queued, g);
                }
                Ok(true)
            }
            FreeInPlace::Encroaching(lost) if !self.free_splits => {
                // As in Ruppert's refinement, a free point that would remove a subsegment
                // gives way to a split of it (in place, with the facets through it
                // triangulated and recovered again); the next round finds the flat tets'
                // points anew. Once only: at a corner whose flat tets' spheres lie in a
                // slab (`mpi.off`) the next points encroach again, closer to the corner
                // each time. Nor are these splits carried into a restart, which is then
                // the one they stood in for.
                self.free_splits = true;
                let mut segs = segs!(self);
                let mut again = Vec::new();
                for (p, e) in lost {
                    let split =
                        split_encroached(&mut self.cdt, p, Some(e), &mut segs, self.next_pert, 0)?;
                    let Some((facets, at_splits)) = split else {
                        continue;
                    };
                    if debug() {
                        eprintln!("free point {p:?}: splits {at_splits:?} instead");
                    }
                    self.next_pert += at_splits.len() as u32;
                    self.stats.steiner_points += at_splits.len();
                    count_update(&mut self.cdt, &mut self.in_place, self.stats);
                    again.extend(facets);
                }
                if again.is_empty() {
                    return Ok(false);
                }
                self.triangulate_again(again);
                Ok(true)
            }
            _ => Ok(false),
        }
    }

    /// The construction's end: a restart with the points and splits it asked for, or
    /// its CDT with what the retries need to know.
    fn finish(mut self) -> Result<Attempt, Error> {
        self.stats.work += self.facet_work;
        if self.budget == Some(0) {
            self.stats.free_searches_cut += 1;
        }
        let (plc, merged, opts) = (self.plc, self.merged, self.opts);
        if self.steiner.is_empty() && self.splits.is_empty() && !self.free_in_place.is_empty() {
            // A face around such a point that lies on a facet beside its triangles (in the
            // slab of a facet far from flat) makes the construction start again instead,
            // with the points as input vertices.
            let search = self
                .search
                .get_or_insert_with(|| flat_tet_search(plc, merged, opts));
            let covering = self
                .free_in_place
                .iter()
                .any(|&v| search.covering_face_around(&self.cdt, v, false, |_| true));
            if covering {
                if debug() {
                    eprintln!(
                        "free points put in with facets recovered again cover a facet: restart"
                    );
                }
                self.steiner
                    .extend(self.restart_instead.take().into_iter().flatten());
            }
        }
        if !self.steiner.is_empty() || !self.splits.is_empty() {
            // What the updates in place put in goes into the next construction too, which
            // would otherwise have to find it again. Free points put in with facets
            // recovered again stood in for a restart: the points it would have had go into
            // this one.
            let (mut steiner, mut splits) = (self.steiner, self.splits);
            let (more_splits, more_points) = self.carried;
            splits.extend(more_splits);
            steiner.extend(more_points);
            for p in self.restart_instead.into_iter().flatten() {
                if !steiner.contains(&p) {
                    steiner.push(p);
                }
            }
            let fallback = if self.complete && steiner.iter().all(|p| p.0 == FREE_POINT) {
                let search = self
                    .search
                    .get_or_insert_with(|| flat_tet_search(plc, merged, opts));
                let (flat_left, _) = slivers::flat_left(&mut self.cdt, search, &mut self.carved, 0);
                let covering =
                    slivers::covering_flat_tets(&mut self.cdt, search, &mut self.carved).len();
                Some(Box::new(Built {
                    cdt: self.cdt,
                    seg_markers: self.seg_markers,
                    carved: self.carved,
                    flat_left,
                    retry_points: Vec::new(),
                    first_point_covers: false,
                    covering,
                }))
            } else {
                None
            };
            return Ok(Attempt::Restart(steiner, splits, fallback));
        }
        let (flat_left, retry_points) = match self.flat_left {
            // Known, and too many (or none) for other constructions: no search needed.
            Some(known) if !(1..=MAX_RETRY_TETS).contains(&known.tets) => (known, Vec::new()),
            _ => {
                let search = self
                    .search
                    .get_or_insert_with(|| flat_tet_search(plc, merged, opts));
                slivers::flat_left(&mut self.cdt, search, &mut self.carved, MAX_RETRY_TETS)
            }
        };
        let first_point_covers = match self.facet_points.first() {
            Some(&(FREE_POINT, _)) => {
                let v = self
                    .inv
                    .get(self.n_input)
                    .copied()
                    .filter(|&v| v != u32::MAX);
                let search = self
                    .search
                    .get_or_insert_with(|| flat_tet_search(plc, merged, opts));
                v.is_some_and(|v| search.covering_face_around(&self.cdt, v, true, |_| true))
            }
            _ => false,
        };
        let covering = if self.stats.restarts > 0 {
            let search = self
                .search
                .get_or_insert_with(|| flat_tet_search(plc, merged, opts));
            slivers::covering_flat_tets(&mut self.cdt, search, &mut self.carved).len()
        } else {
            0
        };
        Ok(Attempt::Done(Box::new(Built {
            cdt: self.cdt,
            seg_markers: self.seg_markers,
            carved: self.carved,
            flat_left,
            retry_points,
            first_point_covers,
            covering,
        })))
    }
}

/// Into how many equal parts a piece `len` long is cut so that a vertex `d` from its line
/// lies in no part's diametral sphere: parts no longer than [`LENS_PIECE`] times `d`, at
/// least two, at most [`MAX_LENS_PARTS`].
fn lens_parts(len: f64, d: f64) -> usize {
    if d > 0.0 && d.is_finite() && len.is_finite() {
        ((len / (LENS_PIECE * d)).ceil() as usize).clamp(2, MAX_LENS_PARTS)
    } else {
        2
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

/// What the search for flat tets on facets needs besides the CDT.
fn flat_tet_search<'a>(
    plc: &'a Plc,
    merged: &'a PreparedPlc,
    opts: &PlcOptions,
) -> slivers::Search<'a> {
    slivers::Search {
        prep: merged,
        input: &plc.points,
        domain: slivers::DomainOf {
            holes: &plc.holes,
            regions: &plc.regions,
            keep_hull: opts.keep_hull,
        },
        index: Default::default(),
        shared: None,
    }
}

/// For each flat tet that no free point removes, splits of one subsegment near it: its
/// longest edge that is one, or else the longest subsegment at one of its vertices. The
/// piece is cut into equal parts no longer than `LENS_PIECE` times the distance from its
/// line to the tet's nearest other vertex, so that vertex no longer lies in the
/// diametral sphere of any part: then the subfaces on either side of the piece are
/// Delaunay across it, and a tet folded over it has its sphere's centre in the domain,
/// where a free point reaches it (one midpoint split at a time took a restart per
/// halving, more than the restarts allow).
fn flat_tet_splits(
    cdt: &Cdt,
    stuck: &[[VertexId; 4]],
    seg_of: &FxHashMap<(VertexId, VertexId), usize>,
    subsegs: &segments::Subsegments,
    lens: bool,
) -> Vec<(usize, f64)> {
    use crate::geom::{cross, norm, sub};
    let pt = |x: VertexId| cdt.dt.points[x as usize];
    let len = |&(a, b): &(VertexId, VertexId)| norm(&sub(&pt(a), &pt(b)));
    // The subsegments at each vertex on a segment.
    let mut at: FxHashMap<VertexId, Vec<(VertexId, VertexId)>> = FxHashMap::default();
    if stuck.iter().any(|v| {
        !crate::mesh::EDGE_VERTS
            .iter()
            .any(|&(i, j)| seg_of.contains_key(&edge_key(v[i], v[j])))
    }) {
        for &e in seg_of.keys() {
            at.entry(e.0).or_default().push(e);
            at.entry(e.1).or_default().push(e);
        }
    }
    let mut out: Vec<(usize, f64)> = Vec::new();
    let mut split: FxHashSet<(VertexId, VertexId)> = FxHashSet::default();
    for v in stuck {
        let own = crate::mesh::EDGE_VERTS
            .iter()
            .map(|&(i, j)| edge_key(v[i], v[j]))
            .filter(|e| seg_of.contains_key(e))
            .max_by(|x, y| len(x).total_cmp(&len(y)));
        let e = own.or_else(|| {
            v.iter()
                .filter_map(|x| at.get(x))
                .flatten()
                .copied()
                .max_by(|x, y| len(x).total_cmp(&len(y)))
        });
        let Some(e) = e else { continue };
        if !split.insert(e) {
            continue;
        }
        let (pa, pb) = (pt(e.0), pt(e.1));
        let l = len(&e);
        let ab = sub(&pb, &pa);
        let d = v
            .iter()
            .filter(|&&x| x != e.0 && x != e.1)
            .map(|&x| norm(&cross(&ab, &sub(&pt(x), &pa))) / l)
            .fold(f64::INFINITY, f64::min);
        let parts = if lens { lens_parts(l, d) } else { 2 };
        let seg = seg_of[&e];
        let chain = &subsegs.chains[seg];
        let (s0, s1) = (
            super::in_place::parameter(cdt, chain, e.0),
            super::in_place::parameter(cdt, chain, e.1),
        );
        out.extend((1..parts).map(|i| (seg, s0 + (s1 - s0) * i as f64 / parts as f64)));
    }
    out
}

/// Removes shim tets (four vertices on one facet) from the domain. A shim that carving
/// would keep has its two subfaces on the outer side; taking its other two faces as the
/// polygon's triangles instead puts it outside, where carving removes it. A shim that
/// both sides keep (an inner polygon) needs a Steiner point on the polygon: those points
/// are returned, and the construction starts again. Also returns the carving of the CDT
/// as left, if one was made.
pub(super) fn resolve_shims(
    cdt: &mut Cdt,
    plc: &Plc,
    opts: &PlcOptions,
) -> (Vec<(usize, Point)>, Option<Domain>) {
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
    let mut carved = domain(cdt, &plc.holes, &plc.regions, opts.keep_hull);
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
                domain(cdt, &plc.holes, &plc.regions, opts.keep_hull).tets,
                "a shim swap changed the carving beyond its shim"
            );
        } else {
            carved = domain(cdt, &plc.holes, &plc.regions, opts.keep_hull);
        }
    }
    (Vec::new(), None)
}

/// Groups missing triangles into regions connected through shared edges that are not
/// subsegments.
pub(crate) fn regions_of(
    missing: &[[VertexId; 3]],
    subsegs: &FxHashMap<(VertexId, VertexId), i32>,
) -> Vec<Vec<[VertexId; 3]>> {
    let by_edge = triangles_by_edge(missing);
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_piece_is_cut_so_that_a_near_vertex_encroaches_upon_no_part() {
        for (len, d) in [(1.0, 0.1), (0.137, 0.0043), (1.0, 0.6), (0.00098, 1.24e-5)] {
            let k = lens_parts(len, d);
            // The vertex is `d` from the line, a part's diametral sphere `part / 2` from it.
            let part = len / k as f64;
            assert!(part / 2.0 < d && k >= 2, "{len} {d}: {k} parts");
            if k > 2 && k < MAX_LENS_PARTS {
                assert!(
                    len / (k - 1) as f64 > LENS_PIECE * d,
                    "{len} {d}: {k} parts"
                );
            }
        }
        assert_eq!(lens_parts(1.0, 0.0), 2);
        assert_eq!(lens_parts(1.0, 10.0), 2);
        assert_eq!(lens_parts(1.0, 1e-9), MAX_LENS_PARTS);
        assert_eq!(lens_parts(f64::INFINITY, 1.0), 2);
    }
}
