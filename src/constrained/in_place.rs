//! Updates of a finished CDT in place of a restart (the paper's update of a CDT): points
//! put in with the subfaces of the facets in their way taken out, and subsegments split
//! in place, with the facets through them to be triangulated and recovered again by
//! the caller.

use super::cdt::{edge_key, face_key, Cdt};
use super::{debug, for_each_edge, free, segments, SegmentSplit};
use crate::error::MeshError;
use crate::geom::Point;
use crate::mesh::VertexId;
use crate::plc::prepare::PreparedPlc;
use rustc_hash::FxHashMap;

/// Inserts point `p` (perturbation index `pert`), on facet `fi`, into the CDT with the
/// facet's subfaces taken out, so that they do not wall its cavity in, and those of up to
/// [`MAX_UNRECOVERED`] more facets whose subfaces are in its way (see
/// [`insert_unrecovering`]). Its vertex and the facets taken out, to be triangulated and
/// recovered again; or, with the subfaces put back, the subsegment it would remove, if
/// that is why the CDT refuses it all the same.
pub(super) fn insert_unrecovered(
    cdt: &mut Cdt,
    p: Point,
    fi: usize,
    pert: u32,
) -> Result<Unrecovered, MeshError> {
    let mut facets = vec![fi];
    let mut removed = take_out_subfaces(cdt, |f| f as usize == fi);
    let limit = 1 + MAX_UNRECOVERED;
    let inserted = insert_unrecovering(cdt, (p, pert), (&mut facets, limit), &mut removed)?;
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

/// What [`insert_free_unrecovering`] did with a round's refused free points.
pub(super) enum FreeInPlace {
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
pub(super) fn insert_free_unrecovering(
    cdt: &mut Cdt,
    ps: &[Point],
    pert: u32,
) -> Result<FreeInPlace, MeshError> {
    let mut done: Vec<(free::Inserted, TakenOut)> = Vec::new();
    let mut facets = Vec::new();
    let mut lost = Vec::new();
    let mut left_out = false;
    for (k, &p) in ps.iter().enumerate() {
        let (mut through, mut removed) = (Vec::new(), Vec::new());
        let limit = MAX_UNRECOVERED;
        let pk = (p, pert + k as u32);
        let inserted = insert_unrecovering(cdt, pk, (&mut through, limit), &mut removed)?;
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
pub(super) type TakenOut = Vec<([VertexId; 3], u32)>;

/// Takes the subfaces of the facets that `of` picks out of the CDT (unrecovering those
/// facets), and returns them, to be put back with their facets.
pub(super) fn take_out_subfaces(cdt: &mut Cdt, of: impl Fn(u32) -> bool) -> TakenOut {
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
pub(super) fn for_each_facet_segment(
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
pub(super) type Unrecovered = Result<(VertexId, Vec<usize>), Option<(VertexId, VertexId)>>;

/// The most facets besides its own that [`insert_unrecovered`] takes out for a point.
const MAX_UNRECOVERED: usize = 4;

/// The most updates of the CDT in place of a restart in one construction: each makes
/// facets recovered again, and where they keep needing more (polygons far from flat)
/// a restart, with the points as input vertices, settles it sooner.
pub(super) const MAX_IN_PLACE: usize = 64;

/// The most updates in place for one Steiner point: past them, its splits have been
/// closing in on it without settling it.
pub(super) const MAX_IN_PLACE_EACH: usize = 8;

/// How many subsegments [`split_encroached`] passes the split on to, one after another.
const MAX_SPLIT_DEPTH: usize = 4;

/// The segments' state that splitting a subsegment in place updates.
pub(super) struct Segs<'a> {
    pub subsegs: &'a mut segments::Subsegments,
    pub seg_of: &'a mut FxHashMap<(VertexId, VertexId), usize>,
    pub markers: &'a mut FxHashMap<(VertexId, VertexId), i32>,
    /// The facets through each segment, made when first needed.
    pub facets_of: &'a mut Option<Vec<Vec<usize>>>,
    /// The PLC as meshed, and the index of each of its segments by its input ends.
    pub prep: &'a PreparedPlc,
    pub seg_index: &'a FxHashMap<(u32, u32), usize>,
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
pub(super) fn split_encroached(
    cdt: &mut Cdt,
    p: Point,
    lost: Option<(VertexId, VertexId)>,
    segs: &mut Segs<'_>,
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
    let e = match split_at(cdt, &[((u, v), seg, s)], segs, pert)? {
        Ok(done) => return Ok(Some(done)),
        Err(Some(e)) if e != (u, v) && depth < MAX_SPLIT_DEPTH => e,
        Err(_) => return Ok(None),
    };
    // Two subsegments at a sharp corner encroach upon each other's middles: both are
    // split at once, at one distance from the corner (with those their split points
    // would remove).
    if let Some(done) = split_group(cdt, (u, v), e, segs, pert)? {
        return Ok(Some(done));
    }
    // A split point that would remove another subsegment splits that one instead, a few
    // levels deep (a chain of encroachments, as in Ruppert's refinement).
    split_encroached(cdt, m, Some(e), segs, pert, depth + 1)
}

/// Inserts point `m` (perturbation index `pert`) with [`free::insert_point`]; where a
/// subface of another facet is in its way, that facet is unrecovered too (its subfaces
/// go to `removed`, the facet to `through`, up to `limit` facets there) and the point
/// tried again.
fn insert_unrecovering(
    cdt: &mut Cdt,
    (m, pert): (Point, u32),
    (through, limit): (&mut Vec<usize>, usize),
    removed: &mut TakenOut,
) -> Result<free::Inserted, MeshError> {
    loop {
        let inserted = free::insert_point(cdt, m, pert, true)?;
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
pub(super) type InPlaceSplit = (Vec<usize>, Vec<SegmentSplit>);

/// The facets through the segments `of` (their lists made when first needed).
fn facets_through(segs: &mut Segs<'_>, of: &[usize]) -> Vec<usize> {
    let (prep, seg_index) = (segs.prep, segs.seg_index);
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
        match split_at(cdt, &cut, segs, pert)? {
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
    let mut through = facets_through(segs, &segments);
    let mut removed = take_out_subfaces(cdt, |f| through.contains(&(f as usize)));
    let markers: Vec<i32> = cut.iter().map(|&(e, ..)| segs.take_out(cdt, e)).collect();
    let limit = through.len() + MAX_UNRECOVERED;
    // All points go in, or none: each may remove the others' subsegments alone.
    let mut done: Vec<(VertexId, free::Inserted)> = Vec::with_capacity(at_r.len());
    let mut lost = None;
    for (k, &(.., m)) in at_r.iter().enumerate() {
        let inserted = insert_unrecovering(
            cdt,
            (m, pert + k as u32),
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
pub(super) fn parameter(cdt: &Cdt, chain: &[VertexId], x: VertexId) -> f64 {
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
pub(super) fn midpoint_parameter(cdt: &Cdt, chain: &[VertexId], u: VertexId, v: VertexId) -> f64 {
    0.5 * (parameter(cdt, chain, u) + parameter(cdt, chain, v))
}
