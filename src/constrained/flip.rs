//! Facet insertion by bistellar flips (Shewchuk's flip algorithm; the paper's §3.2).
//!
//! The tets crossing a missing region R are flipped until no crossing triangle is left.
//! Left vertices (one side of the polygon's plane) are lifted at a rate proportional to
//! their height `Orient3D(a, b, c, v)`, so the tets in R stay a weighted CDT as time τ
//! grows; each crossing triangle is certified with the time at which its two tets become
//! cohyperplanar (Equation 1), and the earliest flip is done first. Flip times are
//! compared exactly, ties broken by TetGen's symbolic perturbation (`geom::lifted`), so
//! flips come off the queue in the right order.
//!
//! The paper's three safeguards are kept (and counted): a flip that would remove a tet
//! outside R is refused; non-crossing faces next to new non-crossing tets are checked for
//! local regularity and flipped if needed; a flip that cannot be done yet waits in a list
//! L and is retried after every flip. If the region is still missing when the queue runs
//! dry, the region falls back to cavity retriangulation, which is counted and reported;
//! but a polygon that is not flat, whose vertices off the lifting plane break the order
//! the flips rely on, gets a Steiner point instead, the flips taken back first (up to
//! two per facet and construction, `MAX_STUCK_POINTS`; then it falls back too).
//!
//! After the region is in, the weights are restored: faces in R that are not locally
//! Delaunay (polygons that are not exactly flat) are repaired by flips where possible,
//! and otherwise the region asks for a Steiner point on the polygon, like the cavity
//! algorithm does.

use super::bistellar::{self, Few, Kind};
use super::cavity::{self, crossing_tets, steiner_point, Outcome, Region, RegionStats};
use super::cdt::{edge_key, face_key, Cdt};
use super::flip_queue::{FlipQueue, Interval, Order};
use crate::delaunay::Change;
use crate::error::MeshError;
use crate::geom::lifted::{cross_sign, Approx, CompareCounts, FlipTime, Lifting};
use crate::geom::{cross, dot, insphere_sos, sub, Point, Sign};
use crate::mesh::{FaceRef, TetId, VertexId, GHOST};
use rustc_hash::FxHashSet;

/// Figures of flip insertion, summed over regions.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FlipCounts {
    /// 2-3 flips.
    pub flips23: usize,
    /// 3-2 flips.
    pub flips32: usize,
    /// 4-4 flips.
    pub flips44: usize,
    /// Flips that restored local Delaunayhood after the weights were restored.
    pub repair_flips: usize,
    /// Safeguard 1: flips refused because they would remove a tet outside R.
    pub outside_r: usize,
    /// Safeguard 2: non-crossing faces found not locally regular, and flipped.
    pub not_regular: usize,
    /// Safeguard 3: flips that could not be done when dequeued and went to list L.
    pub deferred: usize,
    /// Flips refused because they would remove a subsegment or a triangle of the region.
    pub constrained: usize,
    /// Regions that fell back to cavity retriangulation.
    pub fallbacks: usize,
    /// Regions of polygons that are not flat whose flips got stuck (crossing tets left,
    /// or the polygon triangulated otherwise than the region): the flips were taken back
    /// and the region asked for a Steiner point on the polygon, as the paper does for
    /// the other troubles of such polygons.
    pub not_flat_stuck: usize,
    /// Of those, regions stuck after their facet's last own point
    /// (`MAX_STUCK_POINTS`) whose point the cavity code placed: asked to insert the
    /// region on the CDT as it was, it found that the region needs a point there too.
    pub not_flat_cavity_points: usize,
    /// Flip-time comparisons that needed exact arithmetic.
    pub exact_compares: usize,
    /// Of those, exact ties broken by the symbolic perturbation.
    pub perturbed_compares: usize,
}

impl FlipCounts {
    /// Adds `o` to these counts.
    pub fn add(&mut self, o: &FlipCounts) {
        self.flips23 += o.flips23;
        self.flips32 += o.flips32;
        self.flips44 += o.flips44;
        self.repair_flips += o.repair_flips;
        self.outside_r += o.outside_r;
        self.not_regular += o.not_regular;
        self.deferred += o.deferred;
        self.constrained += o.constrained;
        self.fallbacks += o.fallbacks;
        self.not_flat_stuck += o.not_flat_stuck;
        self.not_flat_cavity_points += o.not_flat_cavity_points;
        self.exact_compares += o.exact_compares;
        self.perturbed_compares += o.perturbed_compares;
    }

    /// All flips done.
    pub fn total(&self) -> usize {
        self.flips23 + self.flips32 + self.flips44
    }
}

/// Why a flip was not done.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Refusal {
    /// It would remove a tet outside R (safeguard 1).
    OutsideR,
    /// It would remove a subsegment or a triangle of the region.
    Constrained,
    /// The tets around the face do not allow a 2-3, 3-2 or 4-4 flip now.
    NotFlippable,
}

/// A certified face, in 24 bytes: the face as seen from its first tet and the
/// certificate's five vertices (the face's three and the two apices). The flip time
/// itself is only in the queue entry, as an interval, with what tells whether the event
/// is stale; where the interval does not settle an order, which is rare, the time is
/// computed again from the five vertices, which never move. Events are written at
/// random slots, so their size is cache misses.
#[derive(Clone, Copy)]
struct Event {
    face: FaceRef,
    verts: [VertexId; 5],
}

impl Event {
    /// The five vertices, sorted: two certificates with the same five are the same
    /// event (one lifted hyperplane).
    fn five(&self) -> [VertexId; 5] {
        let mut v = self.verts;
        v.sort_unstable();
        v
    }
}

/// A queued event: an interval `[lo, hi]` holding its flip time, its index with a flag,
/// and its tets with their generations. Nearly all comparisons are settled from the
/// entries alone, and stale entries (70% of pops) are recognised without touching the
/// events. (Entries of 40 bytes made a binary heap of all events 15% slower; the
/// radix queue moves them in sweeps.)
#[derive(Clone, Copy)]
struct Entry {
    lo: f64,
    hi: f64,
    /// The event's index, with [`FORCED`] set if the face was found not locally
    /// regular now (safeguard 2: such events come first).
    e: u32,
    /// The face's tets (the event's first, the other across the face) and their
    /// generations when it was certified.
    t1: TetId,
    t2: TetId,
    g1: u32,
    g2: u32,
}

impl Interval for Entry {
    #[inline]
    fn lo(&self) -> f64 {
        self.lo
    }
    #[inline]
    fn hi(&self) -> f64 {
        self.hi
    }
}

/// The most entries [`Flipper::times`] and [`Flipper::orders`] keep.
const KEPT_TIMES: usize = 16;

/// The flag of [`Entry::e`] for events that come first.
const FORCED: u32 = 1 << 31;

impl Entry {
    #[inline]
    fn event(&self) -> u32 {
        self.e & !FORCED
    }

    #[inline]
    fn forced(&self) -> bool {
        self.e & FORCED != 0
    }

    /// A forced event's interval is `[−∞, −∞]`: it comes before every event with a
    /// finite lower end by the intervals alone, and ties only with forced events and
    /// those whose interval is everything, which [`Flipper::earlier_tied`] orders.
    /// `tets`: the face's two tets and their generations now.
    fn new(lo: f64, hi: f64, e: u32, forced: bool, tets: [u32; 4]) -> Self {
        let (lo, hi) = if forced {
            (f64::NEG_INFINITY, f64::NEG_INFINITY)
        } else {
            (lo, hi)
        };
        Entry {
            lo,
            hi,
            e: if forced { e | FORCED } else { e },
            t1: tets[0],
            t2: tets[1],
            g1: tets[2],
            g2: tets[3],
        }
    }
}

/// A face certified in the same batch as an event of the same five vertices: a face of
/// the same coming flip, which is not queued (a sixth of all certificates on Figure 9,
/// each a push and a stale pop). When its event is done with (flipped, stale, or left
/// in list L at the end), the face goes into the queue after all if its two tets are
/// still there: a flip of other tets may leave it standing, still due.
#[derive(Clone, Copy)]
struct Cover {
    /// The next cover of the same event ([`NO_COVER`]: none).
    next: u32,
    face: FaceRef,
    verts: [VertexId; 5],
    lo: f64,
    hi: f64,
    /// The face's tets and their generations, as in [`Entry`].
    tets: [u32; 4],
}

/// The end of a list of covers.
const NO_COVER: u32 = u32::MAX;

impl Order<Entry> for Flipper<'_> {
    #[inline]
    fn earlier(&mut self, a: &Entry, b: &Entry) -> bool {
        Flipper::earlier(self, *a, *b)
    }

    /// A stale entry with no faces riding on it is dropped on its way to the front (most
    /// pops were stale): its event's slot is free at once. One with riders stays, to
    /// release them when popped.
    #[inline]
    fn keep(&mut self, x: &Entry) -> bool {
        let e = x.event();
        if self.valid(x) || self.cover_head[e as usize] != NO_COVER {
            return true;
        }
        self.free_events.push(e);
        false
    }
}

/// Stores `x` in a free slot of `slots` (from `free`) or a new one; its index.
fn put<T>(slots: &mut Vec<T>, free: &mut Vec<u32>, x: T) -> u32 {
    match free.pop() {
        Some(i) => {
            slots[i as usize] = x;
            i
        }
        None => {
            slots.push(x);
            (slots.len() - 1) as u32
        }
    }
}

/// Steiner points a facet may get in one construction for flips stuck on its polygon
/// that is not flat; past them its stuck regions fall back to cavity retriangulation:
/// each point costs the region's flips again, and where a few do not settle them (a
/// polygon 1e-3 of its size off flat among points near it) more seldom do.
const MAX_STUCK_POINTS: u32 = 2;

/// Work units ([`Cdt::work`]) per unit of [`CompareCounts::exact_work`]: a product of
/// components costs about 64 ns, a crossing test about 35 ns (both measured with perf).
const EXACT_WORK_UNITS: u64 = 2;

/// Inserts the region `tris` of facet `facet` by flips; same contract as
/// [`cavity::insert_region`]. Adds this region's figures to `total`, whatever the outcome.
pub fn insert_region(
    cdt: &mut Cdt,
    tris: &[[VertexId; 3]],
    facet: u32,
    normal: [f64; 3],
    total: &mut FlipCounts,
) -> Result<Outcome, MeshError> {
    let region = Region::new(cdt, tris);
    let crossing = crossing_tets(cdt, &region)?;
    if crossing.is_empty() {
        // Nothing to flip: the cavity code adopts the mesh's own faces or asks for a point.
        return cavity::insert_region(cdt, tris, facet, normal);
    }
    let lift = Lifting {
        abc: largest_triangle(cdt, &region),
    };
    let flat = region
        .verts
        .iter()
        .all(|&v| lift.side(&cdt.dt.points[v as usize]) == 0);
    // Where the polygon is not flat, the flips are recorded, to be taken back if they
    // get stuck.
    let mut fl = Flipper::new(cdt, &region, lift, &crossing, !flat);
    let done = fl.run()?;
    let problem = if done {
        fl.repair(flat)?
    } else {
        Some(Problem::Stuck)
    };
    // Taken after the repair, whose flips count and may destroy subfaces too.
    let counts = total;
    let mut here = fl.counts;
    here.exact_compares = fl.cmp.exact;
    here.perturbed_compares = fl.cmp.perturbed;
    // A comparison of flip times that needs exact arithmetic is cheap on near-ties of
    // nearby points, but a vertex 1e19 away makes every one of them long expansions:
    // counted as work, such runs end under the bound on restarts instead of hanging.
    let exact_work = fl.cmp.exact_work;
    fl.cdt
        .work
        .set(fl.cdt.work.get() + EXACT_WORK_UNITS * exact_work);
    counts.add(&here);
    let mut at_risk = std::mem::take(&mut fl.at_risk);
    let stuck_near = std::mem::take(&mut fl.stuck_near);
    let journal = fl.journal.take();
    drop(fl);
    if super::debug() {
        eprintln!(
            "facet {facet}: {} crossing tets, {} flips, problem {problem:?}, {} exact compares",
            crossing.len(),
            counts.total(),
            here.exact_compares
        );
    }
    // A polygon that is not flat (the only one whose flips are recorded) with any
    // problem gets a Steiner point or the cavity code, on the CDT as it was: its flips
    // are taken back first, so that no face is left that is not locally Delaunay and no
    // subface of another facet is lost.
    if let (Some(_), Some(changes)) = (&problem, &journal) {
        cdt.dt.undo_changes(changes);
    }
    match problem {
        None => {}
        Some(Problem::Stuck)
            if !flat && cdt.flips_stuck.get(&facet).copied().unwrap_or(0) >= MAX_STUCK_POINTS =>
        {
            // Steiner points did not settle this polygon's flips: the region goes to
            // the cavity code on the CDT as it was. Where that inserts it, it is a
            // counted fallback; where it finds that the region needs a point (it
            // decides so before changing the mesh), the region is no more insertable
            // by cavities than by flips, and gets that point: the Steiner point code
            // the two algorithms share.
            let outcome = cavity::insert_region(cdt, tris, facet, normal)?;
            if matches!(outcome, Outcome::Inserted(_)) {
                counts.fallbacks += 1;
            } else {
                counts.not_flat_stuck += 1;
                counts.not_flat_cavity_points += 1;
            }
            if super::debug() {
                let how = match outcome {
                    Outcome::Inserted(_) => "inserted by cavities",
                    _ => "the cavity code asks for a point",
                };
                eprintln!("facet {facet}: stuck, polygon not flat: flips taken back, {how}");
            }
            return Ok(outcome);
        }
        Some(Problem::Stuck) if !flat => {
            // The weights order the flips as if the polygon's vertices lay on the lifting
            // plane; off it, the flips can get stuck, with crossing tets left or with the
            // polygon triangulated otherwise than the region (whose faces then need not
            // be locally Delaunay once the weights are restored). The mesh goes back to
            // the CDT it was and the polygon gets a point near the trouble, where the
            // cavity code would put it for a shim, so the next try has smaller, flatter
            // pieces.
            counts.not_flat_stuck += 1;
            *cdt.flips_stuck.entry(facet).or_insert(0) += 1;
            let near = nearest_triangle(tris, &stuck_near).unwrap_or(tris[0]);
            if super::debug() {
                eprintln!("facet {facet}: stuck, polygon not flat: flips taken back, Steiner point near {near:?}");
            }
            return Ok(Outcome::NeedsSteiner(steiner_point(
                cdt, tris, near, normal,
            )));
        }
        Some(Problem::Shim(f)) | Some(Problem::NotDelaunay(f)) if !flat => {
            // The point goes on the polygon, at the region triangle nearest the trouble.
            let near = nearest_triangle(tris, &f).unwrap_or(f);
            return Ok(Outcome::NeedsSteiner(steiner_point(
                cdt, tris, near, normal,
            )));
        }
        Some(p) => {
            // A flat polygon: with exact flip times this should not happen.
            counts.fallbacks += 1;
            if super::debug() {
                eprintln!("facet {facet}: flips fall back to the cavity code ({p:?})");
            }
            let mut lost = cdt.take_lost_subfaces(&mut at_risk);
            return Ok(match cavity::insert_region(cdt, tris, facet, normal)? {
                Outcome::Inserted(mut rs) => {
                    rs.lost.append(&mut lost);
                    rs.lost.sort_unstable();
                    rs.lost.dedup();
                    Outcome::Inserted(rs)
                }
                other => other,
            });
        }
    }
    let lost = cdt.take_lost_subfaces(&mut at_risk);
    for t in tris {
        cdt.subfaces.insert(face_key(*t), facet);
    }
    Ok(Outcome::Inserted(RegionStats {
        lost,
        crossing_tets: crossing.len(),
        enlarged_tets: 0,
        subfaces: tris.len(),
    }))
}

/// The triangle of `tris` with the most vertices among `near` (the last of the most).
fn nearest_triangle(tris: &[[VertexId; 3]], near: &[VertexId]) -> Option<[VertexId; 3]> {
    tris.iter()
        .max_by_key(|t| t.iter().filter(|x| near.contains(x)).count())
        .copied()
}

/// Three region vertices spanning approximately the largest triangle: the farthest
/// vertex from the first, then the vertex farthest from their line.
fn largest_triangle(cdt: &Cdt, region: &Region) -> [Point; 3] {
    let p = |v: VertexId| cdt.dt.points[v as usize];
    let mut verts: Vec<VertexId> = region.verts.iter().copied().collect();
    verts.sort_unstable();
    let a = p(verts[0]);
    let d2 = |x: Point, y: Point| (0..3).map(|k| (x[k] - y[k]).powi(2)).sum::<f64>();
    let b = verts
        .iter()
        .map(|&v| p(v))
        .max_by(|x, y| d2(*x, a).total_cmp(&d2(*y, a)))
        .unwrap_or(a);
    let area = |c: Point| {
        let n = cross(&sub(&b, &a), &sub(&c, &a));
        dot(&n, &n)
    };
    let c = verts
        .iter()
        .map(|&v| p(v))
        .max_by(|x, y| area(*x).total_cmp(&area(*y)))
        .unwrap_or(a);
    [a, b, c]
}

/// One vertex's mark: the region it was marked for (a stamp), its side and its height,
/// side by side, so that a lookup reads one place in memory.
#[derive(Clone, Copy)]
struct Mark {
    stamp: u32,
    side: i8,
    h: Approx,
}

/// Per-vertex sides and heights for one region: an array indexed by vertex id, kept
/// from one region to the next, valid where a mark carries the region's stamp.
/// Per-region hash maps cost more than the flips themselves, and clearing arrays the
/// size of the mesh for every region would cost more still.
struct Marks {
    vert: Vec<Mark>,
    /// The stamp of the current region.
    now: u32,
}

thread_local! {
    static MARKS: std::cell::RefCell<(Vec<Mark>, u32)> = const { std::cell::RefCell::new((Vec::new(), 0)) };
}

impl Marks {
    /// Starts a region: no vertex marked, arrays large enough for the mesh.
    fn new(verts: usize) -> Self {
        let (mut vert, now) = MARKS.with(|m| std::mem::take(&mut *m.borrow_mut()));
        let now = cavity::next_stamp(now, &mut vert, |m| &mut m.stamp);
        if vert.len() < verts {
            let blank = Mark {
                stamp: 0,
                side: 0,
                h: Approx { v: 0.0, p: 0.0 },
            };
            vert.resize(verts, blank);
        }
        Marks { vert, now }
    }

    #[inline]
    fn side(&self, v: VertexId) -> Option<(i8, Approx)> {
        let m = self.vert.get(v as usize)?;
        (m.stamp == self.now).then_some((m.side, m.h))
    }

    /// The side of vertex `v` at `p`, marked now if it was not: 0 on the polygon
    /// (`on_polygon`, asked only then), else the side of the lifting plane, with its
    /// height.
    fn mark(
        &mut self,
        v: VertexId,
        p: &Point,
        on_polygon: impl FnOnce() -> bool,
        lift: &Lifting,
    ) -> i8 {
        if let Some((s, _)) = self.side(v) {
            return s;
        }
        let s = if on_polygon() { 0 } else { lift.side(p) as i8 };
        self.vert[v as usize] = Mark {
            stamp: self.now,
            side: s,
            h: lift.height_approx(p, s == 1),
        };
        s
    }
}

impl Drop for Marks {
    fn drop(&mut self) {
        let vert = std::mem::take(&mut self.vert);
        let now = self.now;
        MARKS.with(|m| *m.borrow_mut() = (vert, now));
    }
}

/// Per tet slot: its generation and its region stamp (see [`Gens`]).
type SlotGens = Vec<(u32, u32)>;

/// Generations of the tet slots: every tet the flips make or delete gets a number never
/// used before, so an event whose tets have changed, even into a slot reused for
/// another tet, is recognised by two array reads. Kept from one region to the next
/// (numbers only grow), since only the flips change tets while a region is processed.
/// Also which slots hold tets of R, by a stamp per region.
struct Gens {
    /// Per tet slot: its generation, and the stamp of the region whose R holds it (one
    /// entry, since a tet's generation is read right after its membership).
    of: SlotGens,
    next: u32,
    /// The stamp of the current region.
    now: u32,
}

thread_local! {
    static GENS: std::cell::RefCell<(SlotGens, u32, u32)> =
        const { std::cell::RefCell::new((Vec::new(), 1, 0)) };
}

impl Gens {
    /// Starts a region with R empty.
    fn new(slots: usize) -> Self {
        let (mut of, mut next, now) = GENS.with(|g| std::mem::take(&mut *g.borrow_mut()));
        // Numbers start afresh (between regions, when no event is pending) long before
        // they could wrap: one region would need 2^31 tet changes to wrap them.
        if next == 0 || next > 1 << 31 {
            of.iter_mut().for_each(|g| g.0 = 0);
            next = 1;
        }
        let now = cavity::next_stamp(now, &mut of, |g| &mut g.1);
        if of.len() < slots {
            of.resize(slots, (0, 0));
        }
        Gens { of, next, now }
    }

    #[inline]
    fn of(&self, t: TetId) -> u32 {
        self.of.get(t as usize).map_or(0, |g| g.0)
    }

    /// Slot `t`'s entry, the array grown to hold it.
    fn slot(&mut self, t: TetId) -> &mut (u32, u32) {
        if self.of.len() <= t as usize {
            self.of.resize(t as usize + 1, (0, 0));
        }
        &mut self.of[t as usize]
    }

    /// Gives slot `t` a new generation: its tet was made or deleted.
    fn renew(&mut self, t: TetId) {
        self.slot(t).0 = self.next;
        self.next += 1;
    }

    /// Is tet `t` in R?
    #[inline]
    fn in_r(&self, t: TetId) -> bool {
        self.of.get(t as usize).is_some_and(|g| g.1 == self.now)
    }

    /// Puts tet `t` in R, or (`false`) takes it out.
    fn set_in_r(&mut self, t: TetId, inside: bool) {
        let now = self.now;
        self.slot(t).1 = if inside { now } else { 0 };
    }
}

impl Drop for Gens {
    fn drop(&mut self) {
        let of = std::mem::take(&mut self.of);
        let (next, now) = (self.next, self.now);
        GENS.with(|g| *g.borrow_mut() = (of, next, now));
    }
}

/// What keeps a finished region from being a CDT.
#[derive(Clone, Copy, Debug)]
enum Problem {
    /// The queue ran dry (or the flip budget ran out) with the region still missing.
    Stuck,
    /// A tet with four vertices on the polygon; one of its faces.
    Shim([VertexId; 3]),
    /// A face that is not locally Delaunay and no flip repairs.
    NotDelaunay([VertexId; 3]),
}

/// The state of one region's flip insertion.
struct Flipper<'a> {
    cdt: &'a mut Cdt,
    region: &'a Region,
    lift: Lifting,
    /// Per-vertex sides and heights, in arrays stamped for this region.
    marks: Marks,
    /// The tets put in R (some since flipped away: filter with `in_r`).
    r_list: Vec<TetId>,
    region_faces: FxHashSet<[VertexId; 3]>,
    events: Vec<Event>,
    /// Tet generations, for [`Flipper::valid`], and which tets are in R now (they
    /// change as flips replace them).
    gens: Gens,
    /// Event slots free for reuse.
    free_events: Vec<u32>,
    /// The priority queue (most comparisons are settled by the entries' intervals
    /// alone, without touching the events).
    queue: Option<Box<FlipQueue<Entry>>>,
    /// List L: dequeued flips that could not be done yet.
    deferred: Vec<Entry>,
    /// The event being processed: the current time.
    current: Option<u32>,
    counts: FlipCounts,
    cmp: CompareCounts,
    /// Flip times of queued events computed again for the orderings the intervals
    /// leave open, by their sorted five vertices, kept with the exact values they
    /// computed: in degenerate inputs the same few tied events are compared again and
    /// again.
    times: Vec<([VertexId; 5], FlipTime)>,
    /// The signs of [`cross_sign`] of pairs of queued events that the intervals left
    /// open, by their sorted five vertices.
    orders: Vec<([VertexId; 5], [VertexId; 5], i32)>,
    /// Subfaces among the faces of deleted tets.
    at_risk: Vec<[VertexId; 3]>,
    /// The sorted fives of the events queued in this batch (after one flip, or around
    /// one tet at the start), with their events: another face of the same five is a
    /// face of the same coming flip, and rides on that event as a [`Cover`].
    batch: Vec<([VertexId; 5], u32)>,
    /// Faces riding on events, in slots linked from [`Flipper::cover_head`].
    covers: Vec<Cover>,
    /// Cover slots free for reuse.
    free_covers: Vec<u32>,
    /// The first cover of each event ([`NO_COVER`]: none).
    cover_head: Vec<u32>,
    /// Where the flips got stuck: the vertices of the crossing tets (a left and a right
    /// vertex) left when the queue ran dry, or else of the region's missing triangles.
    stuck_near: Vec<VertexId>,
    /// Every flip made, oldest first, when they may have to be taken back.
    journal: Option<Vec<Change>>,
}

impl<'a> Flipper<'a> {
    fn new(
        cdt: &'a mut Cdt,
        region: &'a Region,
        lift: Lifting,
        crossing: &[TetId],
        journal: bool,
    ) -> Self {
        let mut marks = Marks::new(cdt.dt.points.len());
        let mut gens = Gens::new(cdt.dt.mesh.num_slots());
        for &t in crossing {
            gens.set_in_r(t, true);
            for v in cdt.dt.mesh.verts(t) {
                let p = &cdt.dt.points[v as usize];
                marks.mark(v, p, || region.verts.contains(&v), &lift);
            }
        }
        Flipper {
            cdt,
            region,
            lift,
            marks,
            r_list: crossing.to_vec(),
            region_faces: region.tris.iter().map(|t| face_key(*t)).collect(),
            events: Vec::new(),
            gens,
            free_events: Vec::new(),
            queue: Some(Box::new(FlipQueue::new())),
            deferred: Vec::new(),
            current: None,
            counts: FlipCounts::default(),
            cmp: CompareCounts::default(),
            times: Vec::new(),
            orders: Vec::new(),
            at_risk: Vec::new(),
            batch: Vec::new(),
            covers: Vec::new(),
            free_covers: Vec::new(),
            cover_head: Vec::new(),
            stuck_near: Vec::new(),
            journal: journal.then(Vec::new),
        }
    }

    /// Flips until no crossing triangle is left; true if the region's triangles are then
    /// all mesh faces.
    fn run(&mut self) -> Result<bool, MeshError> {
        let r = self.tets_of_r();
        for &t in &r {
            self.batch.clear();
            for i in 0..4 {
                let f = FaceRef::new(t, i);
                let n = self.cdt.dt.mesh.adj(f).tet();
                if t < n && self.in_r(n) {
                    self.certify(f);
                }
            }
        }
        let budget = 50 * r.len() + 1000;
        let mut flips = 0;
        loop {
            while let Some(entry) = self.pop() {
                let e = entry.event();
                if !self.valid(&entry) {
                    self.release_covers(e);
                    self.free_events.push(e);
                    continue;
                }
                flips += 1;
                if flips > budget {
                    return Ok(false);
                }
                if self.cdt.work.get() + EXACT_WORK_UNITS * self.cmp.exact_work
                    > self.cdt.work_limit
                {
                    return Err(MeshError::WorkBound);
                }
                match self.try_flip(self.events[e as usize].face, false)? {
                    Ok(new) => {
                        if let Some(old) = self.current.replace(e) {
                            self.free_events.push(old);
                        }
                        self.after_flip(&new, !entry.forced());
                        self.release_covers(e);
                        self.retry_deferred()?;
                    }
                    Err(why) => {
                        self.count_refusal(why);
                        self.deferred.push(entry);
                        self.counts.deferred += 1;
                    }
                }
            }
            // The faces riding on flips still in list L get their own chance.
            let waiting: Vec<u32> = self.deferred.iter().map(|x| x.event()).collect();
            let mut any = false;
            for e in waiting {
                any |= self.release_covers(e);
            }
            if !any {
                break;
            }
        }
        let tris = self.region.tris.clone();
        let ok = tris
            .iter()
            .all(|t| self.cdt.find_face(t[0], t[1], t[2]).is_some());
        if !ok {
            let r = self.tets_of_r();
            let left: Vec<TetId> = r
                .iter()
                .copied()
                .filter(|&t| self.is_crossing(&self.cdt.dt.mesh.verts(t)))
                .collect();
            // Near the crossing tets left, or else near the region's triangles that are
            // not faces (the flips triangulated the polygon otherwise).
            self.stuck_near = left
                .iter()
                .flat_map(|&t| self.cdt.dt.mesh.verts(t))
                .collect();
            if self.stuck_near.is_empty() {
                self.stuck_near = tris
                    .iter()
                    .filter(|t| self.cdt.find_face(t[0], t[1], t[2]).is_none())
                    .flatten()
                    .copied()
                    .collect();
            }
            if super::debug() {
                eprintln!(
                    "stuck: {} tets in R, {} crossing, {} deferred flips",
                    r.len(),
                    left.len(),
                    self.deferred.len()
                );
            }
        }
        Ok(ok)
    }

    fn count_refusal(&mut self, why: Refusal) {
        match why {
            Refusal::OutsideR => self.counts.outside_r += 1,
            Refusal::Constrained => self.counts.constrained += 1,
            Refusal::NotFlippable => {}
        }
    }

    /// Retries the flips in list L until none succeeds; drops the stale ones.
    fn retry_deferred(&mut self) -> Result<(), MeshError> {
        loop {
            let mut progress = false;
            let list = std::mem::take(&mut self.deferred);
            let mut keep = Vec::new();
            for entry in list {
                let e = entry.event();
                if !self.valid(&entry) {
                    self.release_covers(e);
                    self.free_events.push(e);
                    continue;
                }
                match self.try_flip(self.events[e as usize].face, false)? {
                    Ok(new) => {
                        self.after_flip(&new, !entry.forced());
                        self.release_covers(e);
                        self.free_events.push(e);
                        progress = true;
                    }
                    Err(_) => keep.push(entry),
                }
            }
            self.deferred.extend(keep);
            if !progress || self.deferred.is_empty() {
                return Ok(());
            }
        }
    }

    /// Certifies the crossing faces of the new tets, and checks the non-crossing faces
    /// between non-crossing tets for local regularity now (safeguard 2).
    ///
    /// `due` says that the flip was due (its face's `J > 0`). Then a 2-3 or 3-2 flip's
    /// inner faces are not certified: they join the same five points in the opposite
    /// configuration, whose `J` is the negation, so they never flip (a quarter of all
    /// certificates). A 4-4 flip's inner faces join other fives of its six points.
    fn after_flip(&mut self, new: &[TetId], due: bool) {
        self.batch.clear();
        let skip_inner = due && new.len() <= 3;
        // What the loop below reads of the neighbours (their generations, apices, and
        // the apices' marks and points) is scattered over memory: loaded first, in a loop
        // that no branch on them holds up, the misses overlap instead of coming one after
        // another (facet recovery 18% faster on Figure 9 with 200,000 points).
        let touched = new.iter().fold(0, |x, &t| x ^ self.neighbour_word(t));
        std::hint::black_box(touched);
        for &t in new {
            // Which of the tet's vertices are left and right, as bit masks: a face (all
            // vertices but one) crosses if both masks keep a bit without that vertex.
            let (mut left, mut right) = (0u8, 0u8);
            for (k, v) in self.cdt.dt.mesh.verts(t).into_iter().enumerate() {
                match self.marks.side(v) {
                    Some((1, _)) => left |= 1 << k,
                    Some((-1, _)) => right |= 1 << k,
                    _ => {}
                }
            }
            let crossing_tet = left != 0 && right != 0;
            for i in 0..4 {
                let f = FaceRef::new(t, i);
                let g = self.cdt.dt.mesh.adj(f);
                if !self.in_r(g.tet()) {
                    continue;
                }
                let others = !(1u8 << i);
                if left & others != 0 && right & others != 0 {
                    // A face between two new tets: certified once, from the lower id.
                    let inner = new.contains(&g.tet());
                    if !inner || (g.tet() > t && !skip_inner) {
                        self.certify(f);
                    }
                    continue;
                }
                if crossing_tet || self.is_crossing(&self.cdt.dt.mesh.verts(g.tet())) {
                    continue;
                }
                let Some(cur) = self.current else { continue };
                // On one closed side the lift is affine: regularity cannot change. (Tested
                // before the constraints, which take two hash lookups.)
                let apex = self.cdt.dt.mesh.verts(g.tet())[g.face()];
                let tv = self.cdt.dt.mesh.verts(t);
                if !self.is_crossing(&[tv[0], tv[1], tv[2], tv[3], apex]) {
                    continue;
                }
                let fv = self.cdt.dt.mesh.face_verts(t, i);
                if self.region_faces.contains(&face_key(fv)) || self.cdt.is_subface(t, i) {
                    continue;
                }
                let verts = self.certificate_verts(f);
                let time = self.time_from(verts);
                let now = self.time_from(self.events[cur as usize].verts);
                if cross_sign(&now, &time, &self.lift, &mut self.cmp) > 0 {
                    self.counts.not_regular += 1;
                    self.push_event(f, verts, time.interval(), true);
                }
            }
        }
    }

    /// A word of everything certificates read of tet `t`'s neighbours (their
    /// generations, their apices, and the apices' marks and points), read only to bring
    /// it into the cache (see [`Flipper::after_flip`]).
    #[inline]
    fn neighbour_word(&self, t: TetId) -> u32 {
        let mesh = &self.cdt.dt.mesh;
        let mut word = 0u32;
        for i in 0..4 {
            let g = mesh.adj(FaceRef::new(t, i));
            let apex = mesh.verts(g.tet())[g.face()] as usize;
            word ^= self.gens.of(g.tet()) ^ self.marks.vert.get(apex).map_or(0, |m| m.stamp);
            word ^= self
                .cdt
                .dt
                .points
                .get(apex)
                .map_or(0, |p| p[0].to_bits() as u32);
        }
        word
    }

    /// A word of everything popping entry `n` reads (its event and its tets with their
    /// generations), read only to bring it into the cache (see [`Flipper::pop`]).
    #[inline]
    fn entry_word(&self, n: &Entry) -> u32 {
        let mesh = &self.cdt.dt.mesh;
        let event = self
            .events
            .get(n.event() as usize)
            .map_or(0, |ev| ev.verts[0]);
        event ^ self.gens.of(n.t1) ^ self.gens.of(n.t2) ^ mesh.touch(n.t1) ^ mesh.touch(n.t2)
    }

    /// The side of vertex `v` (0 on the polygon, and for the ghost), marked now if it
    /// was not: a neighbour of R may have a vertex that no crossing tet had.
    fn side_marked(&mut self, v: VertexId) -> i8 {
        if v == GHOST {
            return 0;
        }
        let p = &self.cdt.dt.points[v as usize];
        let region = self.region;
        self.marks
            .mark(v, p, || region.verts.contains(&v), &self.lift)
    }

    /// Is tet `t` in R?
    #[inline]
    fn in_r(&self, t: TetId) -> bool {
        self.gens.in_r(t)
    }

    /// The tets of R now, without repeats, in increasing order.
    fn tets_of_r(&mut self) -> Vec<TetId> {
        let slots = self.cdt.dt.mesh.num_slots();
        // In increasing order. Where R is a large part of the mesh (as in Figure 9), a
        // pass over the slots costs less than sorting the list of R, which every flip
        // lengthens.
        let r: Vec<TetId> = if 8 * self.r_list.len() >= slots {
            (0..slots as TetId).filter(|&t| self.in_r(t)).collect()
        } else {
            let mut r: Vec<TetId> = self
                .r_list
                .iter()
                .copied()
                .filter(|&t| self.in_r(t))
                .collect();
            r.sort_unstable();
            r.dedup();
            r
        };
        self.r_list.clone_from(&r);
        r
    }

    fn is_crossing(&self, verts: &[VertexId]) -> bool {
        let mut l = false;
        let mut r = false;
        for v in verts {
            match self.marks.side(*v) {
                Some((1, _)) => l = true,
                Some((-1, _)) => r = true,
                _ => {}
            }
        }
        l && r
    }

    /// The certificate's five vertices: face `f` seen from its tet, then the apices of
    /// its tet and of the other.
    fn certificate_verts(&self, f: FaceRef) -> [VertexId; 5] {
        let mesh = &self.cdt.dt.mesh;
        let g = mesh.adj(f);
        let s = mesh.face_verts(f.tet(), f.face());
        let v = mesh.verts(f.tet())[f.face()];
        let w = mesh.verts(g.tet())[g.face()];
        [s[0], s[1], s[2], v, w]
    }

    /// What the flip certificate of five vertices in certificate order needs: their
    /// points, perturbation indices, which are left, and their heights.
    #[inline(always)]
    fn certificate_of(&self, ids: [VertexId; 5]) -> ([Point; 5], [u32; 5], [bool; 5], [Approx; 5]) {
        let (pts, heights) = self.points_and_heights(ids);
        let (orig, left) = self.ids_and_sides(ids);
        (pts, orig, left, heights)
    }

    /// The five vertices' points and heights: all a certificate needs unless the sign
    /// of its `J` needs exact arithmetic. (One plain loop: five `array::map`s cost
    /// several times more here, where every flip certifies about five faces.)
    #[inline(always)]
    fn points_and_heights(&self, ids: [VertexId; 5]) -> ([Point; 5], [Approx; 5]) {
        let zero = Approx { v: 0.0, p: 0.0 };
        let (mut pts, mut heights) = ([[0.0; 3]; 5], [zero; 5]);
        for (k, &x) in ids.iter().enumerate() {
            pts[k] = self.cdt.dt.points[x as usize];
            if let Some((_, h)) = self.marks.side(x) {
                heights[k] = h;
            }
        }
        (pts, heights)
    }

    /// The five vertices' perturbation indices and which are left (rarely needed: kept
    /// out of line, so that the certificates' hot path inlines as before).
    #[cold]
    #[inline(never)]
    fn ids_and_sides(&self, ids: [VertexId; 5]) -> ([u32; 5], [bool; 5]) {
        let (mut orig, mut left) = ([0; 5], [false; 5]);
        for (k, &x) in ids.iter().enumerate() {
            orig[k] = self.cdt.dt.orig[x as usize];
            left[k] = matches!(self.marks.side(x), Some((1, _)));
        }
        (orig, left)
    }

    /// The flip certificate of five vertices in certificate order.
    fn time_from(&self, verts: [VertexId; 5]) -> FlipTime {
        let (pts, orig, left, heights) = self.certificate_of(verts);
        FlipTime::new(pts, orig, left, heights)
    }

    /// The flip time of an event with J > 0 whose five vertices, sorted, are `five`
    /// (`verts` in certificate order), as an index into [`Flipper::times`].
    fn kept_time(&mut self, five: [VertexId; 5], verts: [VertexId; 5]) -> usize {
        if let Some(i) = self.times.iter().position(|(v, _)| *v == five) {
            return i;
        }
        let t = self.time_from(verts);
        self.times.push((five, t));
        self.times.len() - 1
    }

    /// Queues the flip of crossing face `f` if it ever happens.
    fn certify(&mut self, f: FaceRef) {
        let verts = self.certificate_verts(f);
        let (pts, heights) = self.points_and_heights(verts);
        let interval =
            FlipTime::interval_if_flips(&self.lift, &pts, &heights, || self.ids_and_sides(verts));
        if let Some(interval) = interval {
            self.push_event(f, verts, interval, false);
        }
    }

    /// Queues the flip of face `f`, certified with the five `verts`, due within `[lo, hi]`;
    /// or, if an event of the same five was queued in this batch, lets it ride on that
    /// event (`ride`: not for forced events, nor for covers coming back).
    fn push_event(&mut self, f: FaceRef, verts: [VertexId; 5], (lo, hi): (f64, f64), forced: bool) {
        self.push_entry(f, verts, (lo, hi), forced, !forced);
    }

    /// [`Flipper::push_event`], with riding allowed or not.
    fn push_entry(
        &mut self,
        f: FaceRef,
        verts: [VertexId; 5],
        (lo, hi): (f64, f64),
        forced: bool,
        ride: bool,
    ) {
        let t2 = self.cdt.dt.mesh.adj(f).tet();
        let tets = [f.tet(), t2, self.gens.of(f.tet()), self.gens.of(t2)];
        let mut five = verts;
        if ride {
            five.sort_unstable();
            if let Some(&(_, e)) = self.batch.iter().find(|(x, _)| *x == five) {
                let c = Cover {
                    next: self.cover_head[e as usize],
                    face: f,
                    verts,
                    lo,
                    hi,
                    tets,
                };
                self.cover_head[e as usize] = put(&mut self.covers, &mut self.free_covers, c);
                return;
            }
        }
        let idx = put(
            &mut self.events,
            &mut self.free_events,
            Event { face: f, verts },
        );
        self.cover_head.resize(self.events.len(), NO_COVER);
        self.cover_head[idx as usize] = NO_COVER;
        debug_assert!(idx < FORCED);
        if ride {
            self.batch.push((five, idx));
        }
        let entry = Entry::new(lo, hi, idx, forced, tets);
        self.with_queue(|q, fl| q.push(entry, fl));
    }

    /// Done with event `e`: the faces riding on it whose tets are all still there go
    /// into the queue. True if any did.
    fn release_covers(&mut self, e: u32) -> bool {
        let mut c = std::mem::replace(&mut self.cover_head[e as usize], NO_COVER);
        let mut any = false;
        while c != NO_COVER {
            let cv = self.covers[c as usize];
            self.free_covers.push(c);
            c = cv.next;
            let [t1, t2, g1, g2] = cv.tets;
            if self.gens.of(t1) == g1 && self.gens.of(t2) == g2 {
                self.push_entry(cv.face, cv.verts, (cv.lo, cv.hi), false, false);
                any = true;
            }
        }
        any
    }

    /// Runs `f` on the queue and the rest of the flipper (the queue's order needs it).
    #[inline]
    fn with_queue<R>(&mut self, f: impl FnOnce(&mut FlipQueue<Entry>, &mut Self) -> R) -> R {
        // Boxed, so that taking it out moves a pointer.
        let mut q = self.queue.take().expect("the queue is in place");
        let r = f(&mut q, self);
        self.queue = Some(q);
        r
    }

    /// Removes the earliest event.
    fn pop(&mut self) -> Option<Entry> {
        self.with_queue(|q, fl| {
            let x = q.pop(fl);
            // The next event is cold (it was certified long ago): reading it now
            // overlaps its misses with this event's flip.
            if let Some(n) = q.peek() {
                std::hint::black_box(fl.entry_word(n));
            }
            x
        })
    }

    /// Does queue entry `a` come strictly before queue entry `b`?
    #[inline]
    fn earlier(&mut self, a: Entry, b: Entry) -> bool {
        if a.hi < b.lo {
            return true;
        }
        if b.hi < a.lo {
            return false;
        }
        self.earlier_tied(a, b)
    }

    /// [`Flipper::earlier`] for entries whose intervals overlap.
    #[inline(never)]
    fn earlier_tied(&mut self, a: Entry, b: Entry) -> bool {
        if a.forced() || b.forced() {
            return if a.forced() == b.forced() {
                a.event() < b.event()
            } else {
                a.forced()
            };
        }
        self.earlier_close(a.event(), b.event())
    }

    /// [`Flipper::earlier`] for two events whose intervals overlap.
    #[cold]
    fn earlier_close(&mut self, a: u32, b: u32) -> bool {
        // Nearly all are faces of one coming flip (the three around an edge of a 3-2
        // flip): the same five points, the same event.
        let (fa, fb) = (
            self.events[a as usize].five(),
            self.events[b as usize].five(),
        );
        if fa == fb {
            return a < b;
        }
        let (va, vb) = (self.events[a as usize].verts, self.events[b as usize].verts);
        // Queued events have J > 0, so that the order of a certificate's rows cannot
        // change the sign of I or J: events of one five points (the faces of one coming
        // flip) share one flip time, and two events' order is one of their fives'. Orders
        // of tied events, which only the perturbation settles, are asked again and again
        // as the heap moves them, so both are kept.
        let known = self.orders.iter().find_map(|&(x, y, s)| {
            if (x, y) == (fa, fb) {
                Some(s)
            } else if (x, y) == (fb, fa) {
                Some(-s)
            } else {
                None
            }
        });
        let sign = match known {
            Some(s) => s,
            None => {
                // A few entries suffice; a linear search must stay cheap.
                if self.times.len() + 2 > KEPT_TIMES {
                    self.times.clear();
                }
                if self.orders.len() >= KEPT_TIMES {
                    self.orders.clear();
                }
                let (ia, ib) = (self.kept_time(fa, va), self.kept_time(fb, vb));
                let s = cross_sign(
                    &self.times[ia].1,
                    &self.times[ib].1,
                    &self.lift,
                    &mut self.cmp,
                );
                self.orders.push((fa, fb, s));
                s
            }
        };
        match sign {
            0 => a < b,
            s => s < 0,
        }
    }

    /// Are the entry's two tets still there, in R, unchanged since it was certified?
    /// (Then they are still glued at its face.) The generations alone tell: events are
    /// made only between two tets of R, and a tet leaves R only by a flip, which gives
    /// its slot a new generation.
    #[inline]
    fn valid(&self, c: &Entry) -> bool {
        let ok = self.gens.of(c.t1) == c.g1 && self.gens.of(c.t2) == c.g2;
        debug_assert!(!ok || (self.in_r(c.t1) && self.in_r(c.t2)));
        ok
    }

    /// Removes face `f` by a 2-3, 3-2 or 4-4 flip, if the tets around it allow one and
    /// it keeps the constraints; returns the new tets. `repair` allows flips outside the
    /// crossing set's logic (the weights are restored) but still only inside R.
    fn try_flip(
        &mut self,
        f: FaceRef,
        repair: bool,
    ) -> Result<Result<Few<TetId>, Refusal>, MeshError> {
        let Some(sh) = bistellar::shape(&self.cdt.dt.mesh, &self.cdt.dt.points, f) else {
            return Ok(Err(Refusal::NotFlippable));
        };
        let constrained = match &sh.edge {
            None => self.region_faces.contains(&face_key(sh.face)),
            Some(([e0, e1], apices)) => self.edge_is_constrained(*e0, *e1, apices),
        };
        if constrained {
            return Ok(Err(Refusal::Constrained));
        }
        if sh.old.iter().any(|&t| !self.in_r(t)) {
            return Ok(Err(Refusal::OutsideR));
        }
        let made = self.replace(&sh)?;
        if repair {
            self.counts.repair_flips += 1;
        } else {
            match sh.kind {
                Kind::T23 => self.counts.flips23 += 1,
                Kind::T32 => self.counts.flips32 += 1,
                Kind::T44 => self.counts.flips44 += 1,
            }
        }
        Ok(Ok(made))
    }

    /// Would removing edge `e0e1` (with the faces it spans with `apices`) lose a
    /// subsegment or a triangle of the region?
    fn edge_is_constrained(&self, e0: VertexId, e1: VertexId, apices: &[VertexId]) -> bool {
        self.cdt.subsegs.contains_key(&edge_key(e0, e1))
            || apices
                .iter()
                .any(|&x| self.region_faces.contains(&face_key([e0, e1, x])))
    }

    /// Replaces tets `old` by the positively oriented tets `new` (which fill the same
    /// volume), keeping R's membership and noting the subfaces at risk.
    fn replace(&mut self, sh: &bistellar::Shape) -> Result<Few<TetId>, MeshError> {
        if let Some(journal) = &mut self.journal {
            let mesh = &self.cdt.dt.mesh;
            journal.push(Change {
                old: sh.old.iter().map(|&t| (t, *mesh.tet(t))).collect(),
                new: Vec::new(),
            });
        }
        let subfaces = &self.cdt.subfaces;
        let at_risk = &mut self.at_risk;
        let made = bistellar::flip(&mut self.cdt.dt.mesh, sh, !subfaces.is_empty(), |key| {
            if subfaces.contains_key(&key) {
                at_risk.push(key);
            }
        })?;
        for &t in sh.old.iter() {
            self.gens.set_in_r(t, false);
            self.gens.renew(t);
        }
        for &t in made.iter() {
            self.gens.renew(t);
            self.gens.set_in_r(t, true);
            self.r_list.push(t);
        }
        if let Some(c) = self.journal.as_mut().and_then(|j| j.last_mut()) {
            c.new = made.to_vec();
        }
        Ok(made)
    }

    /// With the weights restored: flips the faces in R that are not locally Delaunay
    /// where a flip keeping the region can, and reports a shim or a face that remains.
    ///
    /// `flat`: the region's vertices are exactly on the lifting plane. Then, if every
    /// flip was done at its time (none deferred, no face found irregular out of turn),
    /// every face in R is locally regular now, and the weights are affine on each closed
    /// side: only faces whose five points include a left and a right vertex can be
    /// left not locally Delaunay, and only they are checked (checking all was 7% of the
    /// flips' instructions on Figure 9).
    fn repair(&mut self, flat: bool) -> Result<Option<Problem>, MeshError> {
        let mut work: Vec<FaceRef> = Vec::new();
        let r = self.tets_of_r();
        let all = !flat || self.counts.deferred != 0 || self.counts.not_regular != 0;
        for &t in &r {
            let (mut left, mut right) = (false, false);
            if !all {
                for v in self.cdt.dt.mesh.verts(t) {
                    match self.marks.side(v) {
                        Some((1, _)) => left = true,
                        Some((-1, _)) => right = true,
                        _ => {}
                    }
                }
            }
            for i in 0..4 {
                let f = FaceRef::new(t, i);
                if !(all || left && right) {
                    // A tet on one closed side: only an apex on the other side makes a
                    // mix (a tet of polygon vertices alone is flat: there is none).
                    let g = self.cdt.dt.mesh.adj(f);
                    let apex = self.cdt.dt.mesh.verts(g.tet())[g.face()];
                    let wanted = if left { -1 } else { 1 };
                    if !(left || right) || self.side_marked(apex) != wanted {
                        continue;
                    }
                }
                work.push(f);
            }
        }
        let mut budget = 20 * r.len() + 100;
        let mut stuck: Vec<FaceRef> = Vec::new();
        while let Some(f) = work.pop() {
            if !self.not_delaunay(f) {
                continue;
            }
            if budget == 0 {
                stuck.push(f);
                continue;
            }
            budget -= 1;
            match self.try_flip(f, true)? {
                Ok(new) => {
                    for &t in new.iter() {
                        for i in 0..4 {
                            work.push(FaceRef::new(t, i));
                        }
                    }
                }
                Err(_) => stuck.push(f),
            }
        }
        for f in stuck {
            if self.not_delaunay(f) {
                return Ok(Some(Problem::NotDelaunay(
                    self.cdt.dt.mesh.face_verts(f.tet(), f.face()),
                )));
            }
        }
        let r = self.tets_of_r();
        for t in r {
            let v = self.cdt.dt.mesh.verts(t);
            if v.iter().all(|x| self.region.verts.contains(x)) {
                return Ok(Some(Problem::Shim([v[0], v[1], v[2]])));
            }
        }
        Ok(None)
    }

    /// Is face `f` (of a live tet of R, not a constraint, not on the hull) not locally
    /// Delaunay?
    fn not_delaunay(&mut self, f: FaceRef) -> bool {
        let mesh = &self.cdt.dt.mesh;
        let t = f.tet();
        if !mesh.is_alive(t) || !self.in_r(t) {
            return false;
        }
        let g = mesh.adj(f);
        // Faces on R's boundary count too: flips there are refused (safeguard 1), so
        // such a face becomes a problem for the region instead of passing silently.
        if mesh.is_ghost(g.tet()) {
            return false;
        }
        let tv = mesh.verts(t);
        let w = mesh.verts(g.tet())[g.face()];
        let ids = [tv[0], tv[1], tv[2], tv[3], w];
        let p = ids.map(|x| &self.cdt.dt.points[x as usize]);
        let orig = ids.map(|x| self.cdt.dt.orig[x as usize]);
        // Nearly every face is locally Delaunay: the constraints, two hash lookups, are
        // looked up only for the few that are not.
        if insphere_sos(p, orig) != Sign::Positive {
            return false;
        }
        let s = mesh.face_verts(t, f.face());
        !(self.region_faces.contains(&face_key(s)) || self.cdt.is_subface(t, f.face()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::delaunay::Delaunay;
    use crate::geom::orient3d;

    use crate::geom::lcg;

    /// A big triangle in the plane z = 0 (far enough out that its edges are hull edges,
    /// which the driver would recover) and random points near that plane, as in the
    /// Figure 9 experiment; the CDT of them all and the triangle's vertex ids.
    fn triangle_in_points(seed: u64, count: usize) -> (Cdt, [VertexId; 3]) {
        let mut s = seed;
        let mut pts: Vec<Point> = vec![[-4.0, -4.0, 0.0], [5.0, -3.0, 0.0], [0.0, 5.0, 0.0]];
        while pts.len() < count {
            let z = 0.2 * lcg(&mut s) - 0.1;
            if z != 0.0 {
                pts.push([2.0 * lcg(&mut s) - 1.0, 2.0 * lcg(&mut s) - 1.0, z]);
            }
        }
        let dt = Delaunay::build(&pts).unwrap().dt;
        let inv = dt.internal_ids(pts.len());
        (Cdt::new(dt), [inv[0], inv[1], inv[2]])
    }

    /// Points near the plane z = 0 and a big triangle in it, as the Figure 9 experiment:
    /// inserted by flips, the result is a valid arena, keeps every vertex, has the
    /// triangle as a face, and every other face is locally Delaunay (a CDT).
    #[test]
    fn flips_insert_a_triangle_into_random_points() {
        for seed in 0..6u64 {
            let (mut cdt, tri) = triangle_in_points(seed * 7919 + 1, 150);
            for k in 0..3 {
                assert!(cdt.has_edge(tri[k], tri[(k + 1) % 3]));
            }
            let mut counts = FlipCounts::default();
            let out = insert_region(&mut cdt, &[tri], 0, [0.0, 0.0, 1.0], &mut counts).unwrap();
            let Outcome::Inserted(rs) = out else {
                panic!("seed {seed}: {out:?}");
            };
            assert_eq!(counts.fallbacks, 0, "seed {seed}");
            assert!(counts.total() > 0 && rs.crossing_tets > 10, "seed {seed}");
            cdt.dt.mesh.check_links().unwrap();
            assert!(cdt.find_face(tri[0], tri[1], tri[2]).is_some());
            let mut used = vec![false; cdt.dt.points.len()];
            let key = face_key(tri);
            for t in cdt.dt.mesh.real_tets().collect::<Vec<_>>() {
                let v = cdt.dt.mesh.verts(t);
                let p = v.map(|x| &cdt.dt.points[x as usize]);
                assert!(orient3d(p[0], p[1], p[2], p[3]) > 0.0);
                for &x in &v {
                    used[x as usize] = true;
                }
                for i in 0..4 {
                    let g = cdt.dt.mesh.adj(FaceRef::new(t, i));
                    if cdt.dt.mesh.is_ghost(g.tet())
                        || face_key(cdt.dt.mesh.face_verts(t, i)) == key
                    {
                        continue;
                    }
                    let w = cdt.dt.mesh.verts(g.tet())[g.face()];
                    let ids = [v[0], v[1], v[2], v[3], w];
                    let q = ids.map(|x| &cdt.dt.points[x as usize]);
                    let o = ids.map(|x| cdt.dt.orig[x as usize]);
                    assert_ne!(insphere_sos(q, o), Sign::Positive, "seed {seed}");
                }
            }
            assert!(used.iter().all(|&u| u), "seed {seed}: a vertex was lost");
        }
    }

    /// The tets of the mesh (ghosts included), as sorted vertex quadruples.
    fn tet_set(cdt: &Cdt) -> Vec<[VertexId; 4]> {
        let mesh = &cdt.dt.mesh;
        let mut v: Vec<[VertexId; 4]> = (0..mesh.num_slots() as TetId)
            .filter(|&t| mesh.is_alive(t))
            .map(|t| {
                let mut k = mesh.verts(t);
                k.sort_unstable();
                k
            })
            .collect();
        v.sort_unstable();
        v
    }

    /// The flips of a region, recorded, are taken back exactly: the same tets, glued
    /// as before (what a stuck polygon that is not flat relies on).
    #[test]
    fn recorded_flips_are_taken_back_exactly() {
        let (mut cdt, tri) = triangle_in_points(12345, 200);
        let before = tet_set(&cdt);
        let tris = [tri];
        let region = Region::new(&cdt, &tris);
        let crossing = crossing_tets(&mut cdt, &region).unwrap();
        let lift = Lifting {
            abc: largest_triangle(&cdt, &region),
        };
        let mut fl = Flipper::new(&mut cdt, &region, lift, &crossing, true);
        assert!(fl.run().unwrap());
        let flips = fl.counts.total();
        let journal = fl.journal.take().unwrap();
        drop(fl);
        assert!(
            flips > 50 && journal.len() == flips,
            "{flips} flips, {} recorded",
            journal.len()
        );
        assert_ne!(tet_set(&cdt), before);
        cdt.dt.undo_changes(&journal);
        cdt.dt.mesh.check_links().unwrap();
        assert_eq!(tet_set(&cdt), before);
    }
}
