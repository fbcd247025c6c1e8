//! Checks of a PLC before meshing: every defect that makes the PLC invalid is reported
//! with the file, the elements (numbered as in the file) and, where it helps, coordinates.
//!
//! * vertex indices out of range, non-finite coordinates (also of hole and region points);
//! * polygons that repeat a vertex, or whose vertices are all collinear;
//! * duplicate polygons (the same vertices in any order, coincident points merged);
//! * facets that intersect other than at shared vertices and edges ([`intersections`]).
//!
//! Exactly coincident points are not an error: they are merged, with a warning (as TetGen
//! does). An open surface is refused only once carving shows that nothing would remain
//! ([`empty_domain_message`]), since open facets inside a closed one, or `-c`, are fine.

pub mod detect;
pub mod surface;
pub mod tritri;

use crate::error::InputError;
use crate::geom::bvh::{Aabb, Bvh};
use crate::geom::polygon::{clean_ring, representatives};
use crate::plc::{more, Plc, SHOWN};
use rustc_hash::FxHashMap;
pub use tritri::Contact;

/// One pair of intersecting facets, at one pair of their triangles.
#[derive(Clone, Debug, PartialEq)]
pub struct Intersection {
    /// The two input facets (0-based), the lower first.
    pub facets: [usize; 2],
    /// A triangle of each facet where they meet (0-based representative vertex ids).
    pub tris: [[u32; 3]; 2],
    /// How they meet.
    pub kind: Contact,
}

/// A segment (2-vertex polygon) that meets a facet other than at a shared vertex.
#[derive(Clone, Debug, PartialEq)]
pub struct SegmentHit {
    /// The segment's vertices (0-based representatives).
    pub seg: [u32; 2],
    /// The facet the segment belongs to (0-based).
    pub seg_facet: usize,
    /// The facet it meets (0-based), at one of its triangles.
    pub facet: usize,
    /// That triangle.
    pub tri: [u32; 3],
    /// How they meet.
    pub kind: Contact,
}

/// Everything the intersection test found.
#[derive(Clone, Debug, Default)]
pub struct Findings {
    /// Pairs of facets that intersect, sorted by facets.
    pub pairs: Vec<Intersection>,
    /// Segments that meet facets.
    pub segments: Vec<SegmentHit>,
    /// Points lying on facets that do not list them.
    pub strays: Vec<StrayVertex>,
}

impl Findings {
    /// Whether nothing was found.
    pub fn is_empty(&self) -> bool {
        self.pairs.is_empty() && self.segments.is_empty() && self.strays.is_empty()
    }
}

/// A point that lies on a facet without being one of its vertices (nor a vertex of any
/// polygon with an area, which the triangle tests cover).
#[derive(Clone, Debug, PartialEq)]
pub struct StrayVertex {
    /// The point (0-based representative).
    pub point: u32,
    /// The facet it lies on (0-based).
    pub facet: usize,
    /// The facet's triangle it lies on.
    pub tri: [u32; 3],
}

/// A point's number as in the file, with its coordinates.
fn point_name(plc: &Plc, v: u32) -> String {
    let p = plc.points[v as usize];
    format!(
        "{} ({}, {}, {})",
        v as usize + plc.first_index,
        p[0],
        p[1],
        p[2]
    )
}

/// A triangle's vertices as numbered in the file.
fn tri_name(plc: &Plc, t: [u32; 3]) -> String {
    let b = plc.first_index;
    format!(
        "({}, {}, {})",
        t[0] as usize + b,
        t[1] as usize + b,
        t[2] as usize + b
    )
}

/// The largest coordinate magnitude accepted: the exact predicates multiply up to five
/// coordinate differences, which must not overflow.
pub const MAX_COORD: f64 = 1e40;
/// The smallest nonzero coordinate magnitude accepted: products of five rounding tails of
/// differences must not underflow, or the "exact" signs are not exact.
pub const MIN_COORD: f64 = 1e-40;

/// Checks that every point's coordinates are finite and within the range the exact
/// predicates handle ([`MIN_COORD`] ≤ |c| ≤ [`MAX_COORD`], or 0). Runs before any meshing.
pub fn check_coordinates(plc: &Plc) -> Result<(), InputError> {
    let Some((i, p)) = plc
        .points
        .iter()
        .enumerate()
        .find(|(_, p)| p.iter().any(|&c| out_of_range(c)))
    else {
        return Ok(());
    };
    let what = if p.iter().all(|c| c.is_finite()) {
        format!(
            "a coordinate out of the supported range (0 or {MIN_COORD:e} to {MAX_COORD:e} in \
             magnitude, where the exact predicates neither overflow nor underflow; scale the model)"
        )
    } else {
        "a non-finite coordinate".to_string()
    };
    Err(invalid(
        plc,
        format!(
            "point {} has {what}: ({:?}, {:?}, {:?})",
            i + plc.first_index,
            p[0],
            p[1],
            p[2]
        ),
    ))
}

/// Whether a coordinate is non-finite or out of the supported range.
fn out_of_range(c: f64) -> bool {
    !c.is_finite() || c.abs() > MAX_COORD || (c != 0.0 && c.abs() < MIN_COORD)
}

/// Runs every check (the intersection test too) and returns the warnings to show; the
/// first defect found is the error.
pub fn check(plc: &Plc) -> Result<Vec<String>, InputError> {
    let rep = check_elements(plc)?;
    check_surface(plc, &rep)
}

/// The checks of the surface as a whole (duplicate and intersecting facets), once
/// [`check_elements`] has passed and given the representatives `rep`.
pub fn check_surface(plc: &Plc, rep: &[u32]) -> Result<Vec<String>, InputError> {
    check_duplicates(plc, rep)?;
    let mut warnings = Vec::new();
    let found = intersections(plc, rep, &mut warnings);
    if !found.pairs.is_empty() {
        return Err(invalid(plc, intersection_message(plc, &found.pairs)));
    }
    if !found.segments.is_empty() {
        return Err(invalid(plc, segment_message(plc, &found.segments)));
    }
    if !found.strays.is_empty() {
        return Err(invalid(plc, stray_message(plc, &found.strays)));
    }
    Ok(warnings)
}

fn invalid(plc: &Plc, msg: String) -> InputError {
    InputError::Invalid {
        file: plc.source.clone(),
        msg,
    }
}

/// The checks of single elements (ranges, finite coordinates, repeated and collinear
/// vertices); returns the representatives of coincident points.
pub fn check_elements(plc: &Plc) -> Result<Vec<u32>, InputError> {
    let n = plc.points.len();
    check_coordinates(plc)?;
    let seeds = plc
        .holes
        .iter()
        .enumerate()
        .map(|(i, h)| (format!("hole {}", i + 1), *h))
        .chain(
            plc.regions
                .iter()
                .enumerate()
                .map(|(i, r)| (format!("region {}", i + 1), r.point)),
        )
        .chain(plc.facets.iter().enumerate().flat_map(|(fi, f)| {
            f.holes.iter().enumerate().map(move |(i, h)| {
                (
                    format!("hole {} of facet {}", i + 1, fi + plc.first_index),
                    *h,
                )
            })
        }));
    for (name, p) in seeds {
        if p.iter().any(|&c| out_of_range(c)) {
            return Err(invalid(
                plc,
                format!(
                    "{name} has a non-finite or out-of-range coordinate ({}, {}, {})",
                    p[0], p[1], p[2]
                ),
            ));
        }
    }
    for (fi, f) in plc.facets.iter().enumerate() {
        for (pi, poly) in f.polygons.iter().enumerate() {
            let at = || format!("{}, polygon {}", plc.facet_name(fi), pi + 1);
            if let Some(&v) = poly.iter().find(|&&v| v as usize >= n) {
                return Err(invalid(
                    plc,
                    format!(
                        "{}: vertex {} is out of range ({} points, numbered from {})",
                        at(),
                        v as usize + plc.first_index,
                        n,
                        plc.first_index
                    ),
                ));
            }
            if let Some((j, k)) = repeated(poly) {
                return Err(invalid(
                    plc,
                    format!(
                        "{}: vertex {} is repeated (positions {} and {} of {})",
                        at(),
                        poly[k] as usize + plc.first_index,
                        j + 1,
                        k + 1,
                        poly.len()
                    ),
                ));
            }
        }
    }
    let rep = representatives(&plc.points);
    // Polygons whose vertices are all collinear (after merging coincident points).
    for (fi, f) in plc.facets.iter().enumerate() {
        for (pi, poly) in f.polygons.iter().enumerate() {
            let ring = clean_ring(poly, &rep);
            if ring.len() >= 3 && crate::geom::polygon::all_collinear(&plc.points, &ring) {
                return Err(invalid(
                    plc,
                    format!(
                        "{}, polygon {}: its {} vertices are collinear: {}",
                        plc.facet_name(fi),
                        pi + 1,
                        ring.len(),
                        ring.iter()
                            .take(SHOWN)
                            .map(|&v| point_name(plc, v))
                            .collect::<Vec<_>>()
                            .join(", ")
                            + &more(ring.len())
                    ),
                ));
            }
        }
    }
    // Polygons far from flat: the mesher handles polygons whose vertices are slightly off
    // a plane (rounded coordinates), not twisted ones.
    for (fi, f) in plc.facets.iter().enumerate() {
        for (pi, poly) in f.polygons.iter().enumerate() {
            let ring = clean_ring(poly, &rep);
            if let Some((v, dev, size)) = unflat(&plc.points, &ring) {
                return Err(invalid(
                    plc,
                    format!(
                        "{}, polygon {} is not flat: vertex {} is {dev:.3e} off the polygon's \
                         plane, {:.2}% of its size {size:.3e} (at most {}% is accepted)",
                        plc.facet_name(fi),
                        pi + 1,
                        point_name(plc, v),
                        100.0 * dev / size,
                        100.0 * MAX_UNFLATNESS
                    ),
                ));
            }
        }
    }
    Ok(rep)
}

/// The largest distance of a polygon's vertices from its plane, relative to its size,
/// that is accepted.
pub const MAX_UNFLATNESS: f64 = 0.01;

/// For a ring farther from flat than [`MAX_UNFLATNESS`]: its farthest vertex, that
/// vertex's distance from the plane (Newell normal through the centroid) and the ring's
/// size (bounding-box diagonal).
fn unflat(points: &[[f64; 3]], ring: &[u32]) -> Option<(u32, f64, f64)> {
    if ring.len() < 4 {
        return None;
    }
    let n = crate::geom::polygon::newell_normal(points, ring);
    let len = n.iter().map(|x| x * x).sum::<f64>().sqrt();
    if len == 0.0 || !len.is_finite() {
        return None;
    }
    let n = n.map(|x| x / len);
    let m = ring.len() as f64;
    let c: [f64; 3] =
        std::array::from_fn(|k| ring.iter().map(|&v| points[v as usize][k]).sum::<f64>() / m);
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    let mut far = (ring[0], 0.0f64);
    for &v in ring {
        let p = points[v as usize];
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
        let d = (0..3).map(|k| (p[k] - c[k]) * n[k]).sum::<f64>().abs();
        if d > far.1 {
            far = (v, d);
        }
    }
    let size = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
    (far.1 > MAX_UNFLATNESS * size).then_some((far.0, far.1, size))
}

/// The polygons (facet, polygon) that bound a hole of their own facet: for each hole
/// point, the smallest ring of its facet around it. Such a polygon covers no area, so
/// another facet may fill it (a window in a wall, with a marker of its own).
fn hole_rings(plc: &Plc, rep: &[u32]) -> rustc_hash::FxHashSet<(usize, usize)> {
    use crate::geom::polygon::{newell_normal, Projection};
    let mut out = rustc_hash::FxHashSet::default();
    for (fi, f) in plc.facets.iter().enumerate() {
        if f.holes.is_empty() {
            continue;
        }
        let rings: Vec<Vec<u32>> = f.polygons.iter().map(|p| clean_ring(p, rep)).collect();
        // Seen along the largest ring's normal, as the facet is prepared for meshing.
        let Some(normal) = rings
            .iter()
            .filter(|r| r.len() >= 3)
            .map(|r| newell_normal(&plc.points, r))
            .max_by(|a, b| crate::geom::norm(a).total_cmp(&crate::geom::norm(b)))
        else {
            continue;
        };
        let proj = Projection::along(&normal);
        let hole = crate::geom::polygon::hole_rings(&plc.points, &rings, &f.holes, &proj);
        out.extend((0..rings.len()).filter(|&pi| hole[pi]).map(|pi| (fi, pi)));
    }
    out
}

/// Duplicate polygons: the same set of (representative) vertices, both covering area (a
/// polygon that bounds a hole of its own facet and is also a facet is a filled window).
pub fn check_duplicates(plc: &Plc, rep: &[u32]) -> Result<(), InputError> {
    let holes = hole_rings(plc, rep);
    // Triangles (most polygons) are keyed without allocating; a triangle can only
    // duplicate a triangle.
    let mut triangles: FxHashMap<[u32; 3], (usize, usize)> = FxHashMap::default();
    let mut by_set: FxHashMap<Vec<u32>, (usize, usize)> = FxHashMap::default();
    let mut dups: Vec<((usize, usize), (usize, usize))> = Vec::new();
    for (fi, f) in plc.facets.iter().enumerate() {
        for (pi, poly) in f.polygons.iter().enumerate() {
            if holes.contains(&(fi, pi)) {
                continue;
            }
            let first = if let [a, b, c] = poly[..] {
                let mut key = [a, b, c].map(|v| rep.get(v as usize).copied().unwrap_or(v));
                if key[0] == key[1] || key[1] == key[2] || key[0] == key[2] {
                    continue;
                }
                key.sort_unstable();
                *triangles.entry(key).or_insert((fi, pi))
            } else {
                let mut key = clean_ring(poly, rep);
                if key.len() < 3 {
                    continue;
                }
                key.sort_unstable();
                if key.len() == 3 {
                    *triangles
                        .entry([key[0], key[1], key[2]])
                        .or_insert((fi, pi))
                } else {
                    *by_set.entry(key).or_insert((fi, pi))
                }
            };
            if first != (fi, pi) {
                dups.push((first, (fi, pi)));
            }
        }
    }
    if !dups.is_empty() {
        let list: Vec<String> = dups
            .iter()
            .take(SHOWN)
            .map(|&((fa, pa), (fb, pb))| {
                format!(
                    "{}, polygon {} and {}, polygon {}",
                    plc.facet_name(fa),
                    pa + 1,
                    plc.facet_name(fb),
                    pb + 1
                )
            })
            .collect();
        return Err(invalid(
            plc,
            format!(
                "{} duplicate polygon(s) (the same vertices as an earlier one): {}{}",
                dups.len(),
                list.join("; "),
                more(dups.len())
            ),
        ));
    }
    Ok(())
}

/// The first repeated vertex of a polygon of 3 or more vertices, as the positions
/// `(first, repeat)`; a 2-vertex polygon `[v, v]` is a degenerate segment, not a repeat.
fn repeated(poly: &[u32]) -> Option<(usize, usize)> {
    if poly.len() < 3 {
        return None;
    }
    if poly.len() <= 16 {
        // Small polygons (nearly all): no allocation.
        return (1..poly.len())
            .find_map(|k| poly[..k].iter().position(|&v| v == poly[k]).map(|j| (j, k)));
    }
    let mut seen: FxHashMap<u32, usize> = FxHashMap::default();
    poly.iter()
        .enumerate()
        .find_map(|(k, &v)| seen.insert(v, k).map(|j| (j, k)))
}

/// Every pair of input facets that meet other than at shared vertices and edges, at the
/// first pair of their triangles found, sorted by facets; every segment (2-vertex polygon)
/// that meets another facet other than at a shared vertex; and every point that is no
/// vertex of a triangle but lies on a facet whose polygons do not list it. Facets that
/// cannot be triangulated are left out, with a warning pushed to `warnings`.
pub fn intersections(plc: &Plc, rep: &[u32], warnings: &mut Vec<String>) -> Findings {
    let surf = surface::triangulate(plc, rep);
    if !surf.skipped.is_empty() {
        let list: Vec<String> = surf
            .skipped
            .iter()
            .take(SHOWN)
            .map(|(fi, why)| format!("{} ({why})", plc.facet_name(*fi)))
            .collect();
        warnings.push(format!(
            "{} facet(s) could not be triangulated and were left out of the intersection check: {}{}",
            surf.skipped.len(),
            list.join("; "),
            more(surf.skipped.len())
        ));
    }
    let pts = &plc.points;
    let corners = |t: [u32; 3]| t.map(|v| pts[v as usize]);
    let boxes: Vec<Aabb> = surf
        .tris
        .iter()
        .map(|t| {
            let c = corners(t.v);
            [
                std::array::from_fn(|k| c[0][k].min(c[1][k]).min(c[2][k])),
                std::array::from_fn(|k| c[0][k].max(c[1][k]).max(c[2][k])),
            ]
        })
        .collect();
    let bvh = Bvh::build(&boxes);
    let mut found: FxHashMap<(usize, usize), Intersection> = FxHashMap::default();
    bvh.overlapping_pairs(&boxes, |i, j| {
        let (a, b) = (&surf.tris[i], &surf.tris[j]);
        if a.facet == b.facet {
            return;
        }
        let (fa, fb) = (a.facet as usize, b.facet as usize);
        let key = (fa.min(fb), fa.max(fb));
        if found.contains_key(&key) {
            return;
        }
        if let Some(kind) = tritri::contact(a.v, corners(a.v), b.v, corners(b.v)) {
            let tris = if fa < fb { [a.v, b.v] } else { [b.v, a.v] };
            found.insert(
                key,
                Intersection {
                    facets: [key.0, key.1],
                    tris,
                    kind,
                },
            );
        }
    });
    let mut pairs: Vec<Intersection> = found.into_values().collect();
    pairs.sort_by_key(|x| x.facets);
    let mut segments = Vec::new();
    for &(s, sf) in &surf.segments {
        let sp = s.map(|v| pts[v as usize]);
        let bb: Aabb = [
            std::array::from_fn(|k| sp[0][k].min(sp[1][k])),
            std::array::from_fn(|k| sp[0][k].max(sp[1][k])),
        ];
        let mut hit: Option<SegmentHit> = None;
        bvh.query(&boxes, &bb, |i| {
            let t = &surf.tris[i];
            if t.facet == sf || hit.as_ref().is_some_and(|h| h.facet <= t.facet as usize) {
                return;
            }
            if let Some(kind) = tritri::seg_contact(s, sp, t.v, corners(t.v)) {
                hit = Some(SegmentHit {
                    seg: s,
                    seg_facet: sf as usize,
                    facet: t.facet as usize,
                    tri: t.v,
                    kind,
                });
            }
        });
        segments.extend(hit);
    }
    Findings {
        pairs,
        segments,
        strays: stray_vertices(plc, rep, &surf, &boxes, &bvh),
    }
}

/// The error text for segments meeting facets.
pub fn segment_message(plc: &Plc, hits: &[SegmentHit]) -> String {
    let list: Vec<String> = hits
        .iter()
        .take(SHOWN)
        .map(|h| segment_line(plc, h))
        .collect();
    format!(
        "{} segment(s) meet a facet other than at a shared vertex:\n  {}{}",
        hits.len(),
        list.join("\n  "),
        more(hits.len())
    )
}

/// One line per segment meeting a facet, for reports.
pub fn segment_line(plc: &Plc, h: &SegmentHit) -> String {
    let b = plc.first_index;
    format!(
        "segment ({}, {}) of {} and {} ({}) at triangle {}",
        h.seg[0] as usize + b,
        h.seg[1] as usize + b,
        plc.facet_name(h.seg_facet),
        plc.facet_name(h.facet),
        h.kind.name(),
        tri_name(plc, h.tri)
    )
}

/// The points that are no triangle's vertex (loose points, and vertices of segments and
/// isolated vertices only) and lie on a triangle of a facet that does not list them.
fn stray_vertices(
    plc: &Plc,
    rep: &[u32],
    surf: &surface::Surface,
    boxes: &[Aabb],
    bvh: &Bvh,
) -> Vec<StrayVertex> {
    let mut on_triangle = vec![false; plc.points.len()];
    for t in &surf.tris {
        for &v in &t.v {
            on_triangle[v as usize] = true;
        }
    }
    // The facets that list each point (as a vertex of any polygon); only points off the
    // triangles are looked up, so only they are recorded.
    let mut listed: FxHashMap<u32, Vec<usize>> = FxHashMap::default();
    for (fi, f) in plc.facets.iter().enumerate() {
        for p in &f.polygons {
            for &v in p {
                let r = rep[v as usize];
                if !on_triangle[r as usize] {
                    listed.entry(r).or_default().push(fi);
                }
            }
        }
    }
    let mut out = Vec::new();
    for (v, &r) in rep.iter().enumerate() {
        if r as usize != v || on_triangle[v] {
            continue;
        }
        let p = plc.points[v];
        let own = listed.get(&r).map(|x| x.as_slice()).unwrap_or(&[]);
        let mut hit: Option<usize> = None;
        bvh.query(boxes, &[p, p], |i| {
            let t = &surf.tris[i];
            if hit.is_some_and(|h| surf.tris[h].facet <= t.facet)
                || own.contains(&(t.facet as usize))
            {
                return;
            }
            if tritri::point_on(&p, &t.v.map(|x| plc.points[x as usize])) {
                hit = Some(i);
            }
        });
        if let Some(i) = hit {
            out.push(StrayVertex {
                point: r,
                facet: surf.tris[i].facet as usize,
                tri: surf.tris[i].v,
            });
        }
    }
    out
}

/// The error text for points lying on facets that do not list them.
pub fn stray_message(plc: &Plc, strays: &[StrayVertex]) -> String {
    let list: Vec<String> = strays
        .iter()
        .take(SHOWN)
        .map(|s| stray_line(plc, s))
        .collect();
    format!(
        "{} point(s) lie on a facet without being among its vertices (add them to the \
         facet's polygons, or move them):\n  {}{}",
        strays.len(),
        list.join("\n  "),
        more(strays.len())
    )
}

/// One line per stray point, for reports.
pub fn stray_line(plc: &Plc, s: &StrayVertex) -> String {
    format!(
        "point {} lies on {} (triangle {})",
        point_name(plc, s.point),
        plc.facet_name(s.facet),
        tri_name(plc, s.tri)
    )
}

/// One line per intersecting pair, for reports.
pub fn intersection_line(plc: &Plc, x: &Intersection) -> String {
    format!(
        "{} and {} ({}) at triangles {} and {}",
        plc.facet_name(x.facets[0]),
        plc.facet_name(x.facets[1]),
        x.kind.name(),
        tri_name(plc, x.tris[0]),
        tri_name(plc, x.tris[1])
    )
}

/// The error text for intersecting facets: the count and the first pairs, and the
/// nearly coincident vertices that make them cross, if any.
pub fn intersection_message(plc: &Plc, found: &[Intersection]) -> String {
    let list: Vec<String> = found
        .iter()
        .take(SHOWN)
        .map(|x| intersection_line(plc, x))
        .collect();
    let near = near_coincident(plc, found);
    let cause = if near.is_empty() {
        String::new()
    } else {
        let pairs: Vec<String> = near
            .iter()
            .take(SHOWN)
            .map(|&(d, a, b)| {
                format!(
                    "vertices {} and {} are only {d:.2e} apart",
                    point_name(plc, a),
                    point_name(plc, b)
                )
            })
            .collect();
        format!(
            "\n  they meet at nearly coincident vertices, which are distinct points (only \
             exactly equal ones are merged): merging them in the model removes these \
             crossings\n  {}{}",
            pairs.join("\n  "),
            more(near.len())
        )
    };
    format!(
        "{} pair(s) of facets intersect (-d lists them all and writes their triangles):\n  {}{}{cause}",
        found.len(),
        list.join("\n  "),
        more(found.len())
    )
}

/// Distinct vertices of intersecting triangles, one from each, closer than a rounding
/// error of the model's size: (distance, lower id, higher id), closest first.
fn near_coincident(plc: &Plc, found: &[Intersection]) -> Vec<(f64, u32, u32)> {
    let size = plc
        .points
        .iter()
        .flatten()
        .fold(0.0f64, |m, c| m.max(c.abs()));
    let tol = 1e-12 * size;
    let mut near: Vec<(f64, u32, u32)> = Vec::new();
    for x in found {
        for &a in &x.tris[0] {
            for &b in &x.tris[1] {
                if a == b {
                    continue;
                }
                let (pa, pb) = (plc.points[a as usize], plc.points[b as usize]);
                let d = (0..3).map(|k| (pa[k] - pb[k]).powi(2)).sum::<f64>().sqrt();
                if d <= tol {
                    near.push((d, a.min(b), a.max(b)));
                }
            }
        }
    }
    near.sort_by(|x, y| x.0.total_cmp(&y.0).then((x.1, x.2).cmp(&(y.1, y.2))));
    near.dedup_by(|x, y| (x.1, x.2) == (y.1, y.2));
    near
}

/// The boundary edges of the surface (edges of exactly one polygon), in input order,
/// with the facet of that polygon.
fn boundary_edges(plc: &Plc) -> Vec<((u32, u32), usize)> {
    let rep = representatives(&plc.points);
    let mut uses: FxHashMap<(u32, u32), (u32, usize)> = FxHashMap::default();
    let mut order: Vec<(u32, u32)> = Vec::new();
    for (fi, f) in plc.facets.iter().enumerate() {
        for poly in &f.polygons {
            if poly.iter().any(|&v| v as usize >= rep.len()) {
                continue;
            }
            let r = clean_ring(poly, &rep);
            if r.len() < 3 {
                continue;
            }
            for k in 0..r.len() {
                let (a, b) = (r[k], r[(k + 1) % r.len()]);
                let e = (a.min(b), a.max(b));
                let c = uses.entry(e).or_insert((0, fi));
                if c.0 == 0 {
                    order.push(e);
                }
                c.0 += 1;
            }
        }
    }
    order
        .into_iter()
        .filter_map(|e| (uses[&e].0 == 1).then_some((e, uses[&e].1)))
        .collect()
}

/// The list of the first boundary edges, with their coordinates.
fn edge_list(plc: &Plc, open: &[((u32, u32), usize)], with_facet: bool) -> String {
    let list: Vec<String> = open
        .iter()
        .take(SHOWN)
        .map(|&((a, b), fi)| {
            let e = format!("{} – {}", point_name(plc, a), point_name(plc, b));
            if with_facet {
                format!("{e} of {}", plc.facet_name(fi))
            } else {
                e
            }
        })
        .collect();
    format!("{}{}", list.join("; "), more(open.len()))
}

/// The error text when carving leaves nothing: the boundary edges of an open surface
/// (edges of exactly one polygon), or why a closed one encloses nothing.
pub fn empty_domain_message(plc: &Plc) -> String {
    let open = boundary_edges(plc);
    let head =
        "the meshed domain would be empty: no tetrahedron remains after removing the exterior";
    if open.is_empty() {
        return format!(
            "{head}; the polygons leave no gap, so the hole points or the polygons' \
             arrangement remove everything (-c keeps the convex hull)"
        );
    }
    format!(
        "{head}, because the surface is not closed: {} boundary edge(s) (edges of only one \
         polygon): {} (-c keeps the convex hull)",
        open.len(),
        edge_list(plc, &open, false)
    )
}

/// The error text when polygon edges lie where carving removes the tets (outside the
/// enclosed volume or in a hole), so the mesh could not contain them; `lost` counts the
/// subsegments and names the first (output numbering).
pub fn exterior_polygon_message(plc: &Plc, lost: usize, first: (usize, usize)) -> String {
    let head = format!(
        "{lost} polygon edge(s) lie outside the meshed domain, first ({}, {}), so carving \
         would drop them and their polygons from the mesh",
        first.0, first.1
    );
    // Holes are carved with -c too: only the exterior is kept.
    let (place, fix) = if plc.holes.is_empty() {
        (
            "outside the enclosed volume",
            "remove them; -c keeps the convex hull",
        )
    } else {
        (
            "outside the enclosed volume or in a hole",
            "remove them, or the hole point; -c keeps the exterior, not the holes",
        )
    };
    let open = boundary_edges(plc);
    if open.is_empty() {
        return format!("{head}: the polygons with them lie {place} ({fix})");
    }
    format!(
        "{head}: the surface is not closed, and the polygons with its {} boundary edge(s) \
         (edges of only one polygon) dangle {place}: {} ({fix})",
        open.len(),
        edge_list(plc, &open, true)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn repeated_vertices_small_and_large() {
        assert_eq!(repeated(&[1, 2, 3]), None);
        assert_eq!(repeated(&[4, 4]), None);
        assert_eq!(repeated(&[1, 2, 3, 2]), Some((1, 3)));
        let mut big: Vec<u32> = (0..40).collect();
        assert_eq!(repeated(&big), None);
        big.push(17);
        assert_eq!(repeated(&big), Some((17, 40)));
    }

    #[test]
    fn representatives_merge_equal_points_and_signed_zeros() {
        let pts = [
            [0.0, 1.0, 2.0],
            [-0.0, 1.0, 2.0],
            [0.0, 1.0, 2.5],
            [0.0, 1.0, 2.5],
        ];
        assert_eq!(representatives(&pts), vec![0, 0, 2, 2]);
    }

    #[test]
    fn coordinate_range() {
        let mut plc = Plc::from_points(vec![[0.0, 1e-40, -1e40]], 1);
        assert!(check_coordinates(&plc).is_ok());
        plc.points[0][1] = 1e-41;
        let e = check_coordinates(&plc).unwrap_err().to_string();
        assert!(
            e.contains("point 1 has a coordinate out of the supported range"),
            "{e}"
        );
        plc.points[0][1] = f64::NAN;
        let e = check_coordinates(&plc).unwrap_err().to_string();
        assert!(e.contains("point 1 has a non-finite coordinate"), "{e}");
    }
}
