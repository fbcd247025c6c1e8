//! Flat tets whose four vertices all lie on one facet yet survive carving. They span a
//! step or a dent of a facet that is not flat (a merged group of nearly coplanar
//! polygons, or a thin wedge between two of them), where both sides agree on the
//! polygon's triangles, so [`super::resolve_shims`] has nothing to swap. A Steiner point
//! on the facet cannot help: whatever it forms with the facet's vertices is as flat. A
//! free vertex inside the tet's circumsphere, well off the facet and inside the domain,
//! removes the tet from the CDT instead.

use super::cdt::Cdt;
use super::prepare::PreparedPlc;
use crate::carve::{carve, containing_tet_near, Carved};
use crate::geom::predicates::{insphere, orient3d};
use crate::geom::{cross, dot, sub, Point};
use crate::mesh::VertexId;
use crate::plc::Region;
use rustc_hash::FxHashMap;

/// A tet is flat when its volume is at most this fraction of its longest edge cubed: the
/// referee's measure (1e-3) with a margin, so that what we remove is what it flags.
const FLAT: f64 = 1.5e-3;

/// A merged facet's plane, with the slab and box within which a Steiner point counts as
/// lying on it (four times the facet's own deviation from flat).
#[derive(Clone)]
struct Slab {
    normal: Point,
    mean: Point,
    tol: f64,
    lo: Point,
    hi: Point,
}

impl Slab {
    fn height(&self, p: &Point) -> f64 {
        (0..3).map(|k| (p[k] - self.mean[k]) * self.normal[k]).sum()
    }

    fn holds(&self, p: &Point) -> bool {
        self.height(p).abs() <= self.tol
            && (0..3).all(|k| p[k] >= self.lo[k] - self.tol && p[k] <= self.hi[k] + self.tol)
    }
}

/// The domain that carving leaves, as [`carve`] needs it.
pub(crate) struct Domain<'a> {
    pub holes: &'a [Point],
    pub regions: &'a [Region],
    pub keep_hull: bool,
}

/// What the search for flat tets on facets needs besides the CDT: the facets as merged
/// (`prep`), the input points, the input ends of the segment of each Steiner point on
/// one (which name the facets a flat tet of such points may lie on), and the domain.
pub(crate) struct Search<'a> {
    pub prep: &'a PreparedPlc,
    pub input: &'a [Point],
    pub seg_ends: FxHashMap<VertexId, [u32; 2]>,
    pub domain: Domain<'a>,
}

/// What [`free_points`] found.
#[derive(Default)]
pub(crate) struct FlatTets {
    /// Free vertices that remove flat tets: for each tet, the candidates in order of
    /// preference (a point that would break the CDT, by encroaching upon a subsegment,
    /// gives way to the next).
    pub points: Vec<Vec<Point>>,
    /// The kept flat tets for which no free vertex was found (their circumspheres lie
    /// within the facet's slab), by their vertices.
    pub stuck: Vec<[crate::mesh::VertexId; 4]>,
    /// How many flat tets on facets there are, and the facet of the first.
    pub found: (usize, Option<u32>),
}

/// What [`find_flat`] found, and what it built on the way that placing free points needs.
struct Found {
    /// The flat tets that carving keeps and that lie on one facet, each with that facet.
    flat: Vec<(crate::mesh::TetId, u32)>,
    /// The facets' slabs (`None` where not built yet).
    slabs: Vec<Option<Option<Slab>>>,
    /// Which tet slots carving keeps.
    kept: Vec<bool>,
    /// The input's bounding-box diagonal.
    diag: f64,
}

/// Finds the flat tets that carving keeps and that lie on one facet (see [`Found`]);
/// `None` if there are none. `carved` is the CDT's carving if known, and is set if made.
fn find_flat(cdt: &mut Cdt, search: &Search<'_>, carved: &mut Option<Carved>) -> Option<Found> {
    let Search {
        prep,
        input,
        seg_ends,
        domain,
    } = search;
    // A tet can lie on one facet only if it has a Steiner point (which may lie in a
    // slab), or if its four input vertices share a facet, which then has four or more:
    // that rules out most tets before any geometry.
    let n_input = input.len();
    let mut on_big = vec![false; n_input];
    for f in &prep.facets {
        if f.rings.iter().map(|r| r.len()).sum::<usize>() >= 4 {
            for &v in f.rings.iter().flatten() {
                on_big[v as usize] = true;
            }
        }
    }
    let candidate = |v: [crate::mesh::VertexId; 4]| {
        let o = v.map(|x| cdt.dt.orig[x as usize] as usize);
        o.iter().any(|&x| x >= n_input) || o.iter().all(|&x| on_big[x])
    };
    // Flat tets are few: find them before building the facets' slabs.
    let flat_tets: Vec<crate::mesh::TetId> = cdt
        .dt
        .mesh
        .live_tets()
        .filter(|&t| !cdt.is_ghost(t) && candidate(cdt.dt.mesh.verts(t)))
        .filter(|&t| is_flat(&cdt.dt.mesh.verts(t).map(|x| cdt.dt.points[x as usize])))
        .collect();
    if flat_tets.is_empty() {
        return None;
    }
    // Only kept tets matter, and the carving is needed anyway (the output reuses it):
    // flat tets outside the domain, often many, are dropped before any facet is looked at.
    let kept = carved
        .get_or_insert_with(|| carve(cdt, domain.holes, domain.regions, domain.keep_hull))
        .kept_mask(cdt.dt.mesh.num_slots());
    let flat_tets: Vec<crate::mesh::TetId> = flat_tets
        .into_iter()
        .filter(|&t| kept[t as usize])
        .collect();
    if flat_tets.is_empty() {
        return None;
    }
    let diag = diagonal(input);
    // Which facets each input vertex is on, as lists per vertex (one flat array).
    let on_facets = crate::mesh::VertexLists::new(
        n_input,
        prep.facets
            .iter()
            .enumerate()
            .filter(|(_, f)| f.normal != [0.0; 3])
            .flat_map(|(fi, f)| ring_verts(f).into_iter().map(move |v| (v, fi as u32))),
    );
    let facets_of = |v: u32| on_facets.of(v);
    // Slabs are built on demand: most facets never hold a flat tet.
    let slab_of = |fi: usize| slab_of(prep, input, diag, fi);
    let mut slab_cache: Vec<Option<Option<Slab>>> = Vec::new();
    slab_cache.resize_with(prep.facets.len(), || None);
    let mut on = |orig: u32, p: &Point, f: u32| -> bool {
        if (orig as usize) < n_input {
            facets_of(orig).contains(&f)
        } else {
            slab_cache[f as usize]
                .get_or_insert_with(|| slab_of(f as usize))
                .as_ref()
                .is_some_and(|s| s.holds(p))
        }
    };
    let mut flat: Vec<(crate::mesh::TetId, u32)> = Vec::new();
    for t in flat_tets {
        let v = cdt.dt.mesh.verts(t);
        let p = v.map(|x| cdt.dt.points[x as usize]);
        let o = v.map(|x| cdt.dt.orig[x as usize]);
        // With an input vertex, the facets the tet can lie on are among that vertex's
        // (the shortest such list is tried, in increasing order: the first facet found
        // is the lowest of all candidates, as below). Most flat tets go this way.
        if let Some(x) = (0..4)
            .filter(|&i| (o[i] as usize) < n_input)
            .min_by_key(|&i| facets_of(o[i]).len())
        {
            if let Some(&f) = facets_of(o[x])
                .iter()
                .find(|&&f| (0..4).all(|i| on(o[i], &p[i], f)))
            {
                flat.push((t, f));
            }
            continue;
        }
        // A tet of Steiner points on segments (between nearly parallel segments) has no
        // input vertex to name its facet: the segments' ends do. The lowest facet of
        // theirs that holds all four is taken (each list is increasing).
        let mut best: Option<u32> = None;
        for x in v.iter().filter_map(|x| seg_ends.get(x)).flatten() {
            for &f in facets_of(*x) {
                if best.is_some_and(|b| b <= f) {
                    break;
                }
                if (0..4).all(|i| on(o[i], &p[i], f)) {
                    best = Some(f);
                }
            }
        }
        if let Some(f) = best {
            flat.push((t, f));
        }
    }
    (!flat.is_empty()).then_some(Found {
        flat,
        slabs: slab_cache,
        kept,
        diag,
    })
}

/// How many flat tets that carving keeps lie on one facet, and the facet of the first:
/// what is left once no free point removes any more. `carved` as in [`free_points`].
pub(crate) fn flat_left(
    cdt: &mut Cdt,
    search: &Search<'_>,
    carved: &mut Option<Carved>,
) -> (usize, Option<u32>) {
    find_flat(cdt, search, carved)
        .map_or((0, None), |f| (f.flat.len(), f.flat.first().map(|x| x.1)))
}

/// Free vertices that remove the flat tets lying on one facet, one per such tet, and
/// the flat tets they cannot remove. `carved` is the CDT's carving if known, and is set
/// if made.
pub(crate) fn free_points(
    cdt: &mut Cdt,
    search: &Search<'_>,
    carved: &mut Option<Carved>,
) -> FlatTets {
    let Some(Found {
        flat,
        slabs,
        kept,
        diag,
    }) = find_flat(cdt, search, carved)
    else {
        return FlatTets::default();
    };
    // A free point must leave every facet's slab: all are needed from here on.
    let slabs: Vec<Option<Slab>> = slabs
        .into_iter()
        .enumerate()
        .map(|(fi, s)| s.unwrap_or_else(|| slab_of(search.prep, search.input, diag, fi)))
        .collect();
    let mut out = FlatTets {
        found: (flat.len(), flat.first().map(|x| x.1)),
        ..Default::default()
    };
    for (t, f) in flat {
        let Some(slab) = slabs[f as usize].as_ref() else {
            continue;
        };
        let p = cdt.dt.mesh.verts(t).map(|x| cdt.dt.points[x as usize]);
        let ws = remover(cdt, &kept, t, &p, slab, &slabs);
        if ws.is_empty() {
            out.stuck.push(cdt.dt.mesh.verts(t));
        } else if !out.points.iter().any(|x| x[0] == ws[0]) {
            out.points.push(ws);
        }
    }
    out
}

/// The sorted vertices of a merged facet's rings.
fn ring_verts(f: &super::prepare::MergedFacet) -> Vec<u32> {
    let mut verts: Vec<u32> = f.rings.iter().flatten().copied().collect();
    verts.sort_unstable();
    verts.dedup();
    verts
}

/// Facet `fi`'s slab (`diag` the input's diagonal), or `None` for a facet without
/// rings or plane.
fn slab_of(prep: &PreparedPlc, input: &[Point], diag: f64, fi: usize) -> Option<Slab> {
    let f = &prep.facets[fi];
    let verts = ring_verts(f);
    if verts.is_empty() || f.normal == [0.0; 3] {
        return None;
    }
    let k = verts.len() as f64;
    let mean: Point =
        std::array::from_fn(|a| verts.iter().map(|&v| input[v as usize][a]).sum::<f64>() / k);
    let mut slab = Slab {
        normal: f.normal,
        mean,
        tol: 0.0,
        lo: [f64::INFINITY; 3],
        hi: [f64::NEG_INFINITY; 3],
    };
    let mut dev = 0.0f64;
    for &v in &verts {
        let p = &input[v as usize];
        dev = dev.max(slab.height(p).abs());
        for (a, &x) in p.iter().enumerate() {
            slab.lo[a] = slab.lo[a].min(x);
            slab.hi[a] = slab.hi[a].max(x);
        }
    }
    slab.tol = (1e-10 * diag).max(4.0 * dev);
    Some(slab)
}

/// Whether the tet is flat by the [`FLAT`] measure.
fn is_flat(p: &[Point; 4]) -> bool {
    let l2 = longest_edge2(p);
    // A measure with a margin, not a sign: plain floating point does.
    let d: [Point; 3] = std::array::from_fn(|i| std::array::from_fn(|k| p[i + 1][k] - p[0][k]));
    let det = d[0][0] * (d[1][1] * d[2][2] - d[1][2] * d[2][1])
        - d[0][1] * (d[1][0] * d[2][2] - d[1][2] * d[2][0])
        + d[0][2] * (d[1][0] * d[2][1] - d[1][1] * d[2][0]);
    det.abs() / 6.0 <= FLAT * l2 * l2.sqrt()
}

/// The number of places [`remover`] offers for one flat tet.
const CANDIDATES: usize = 6;

/// Points inside the tet's circumsphere, off every facet's slab and inside a kept tet,
/// best first. They are sought on lines along the facet's normal through the tet's
/// centroid, its circumcenter and the point halfway, farthest from the facet first: a
/// flat tet along an edge where two facets meet has its sphere off to one side.
fn remover(
    cdt: &mut Cdt,
    kept: &[bool],
    tet: crate::mesh::TetId,
    p: &[Point; 4],
    slab: &Slab,
    slabs: &[Option<Slab>],
) -> Vec<Point> {
    let mut found = Vec::new();
    let o = orient3d(&p[0], &p[1], &p[2], &p[3]);
    if o == 0.0 {
        return found;
    }
    let l2 = longest_edge2(p);
    let m: Point = std::array::from_fn(|k| (p[0][k] + p[1][k] + p[2][k] + p[3][k]) / 4.0);
    let l = l2.sqrt();
    let mut bases = vec![(m, l)];
    // A flat tet's circumcenter can lie arbitrarily far away; the point must stay near the
    // tet, where it removes the tet and nothing far off.
    if let Some((c, r)) = circumsphere(p).filter(|&(_, r)| r <= 50.0 * l) {
        let h: Point = std::array::from_fn(|k| (c[k] + m[k]) / 2.0);
        bases.push((c, r));
        bases.push((h, r));
    }
    // Along an edge where facets meet, the point must leave all their slabs at once:
    // the facet's normal, each other facet's there, and their sums and differences.
    let mut dirs: Vec<Point> = vec![slab.normal];
    for n in slabs
        .iter()
        .flatten()
        .filter(|s| s.holds(&m))
        .map(|s| s.normal)
        .take(6)
    {
        for sg in [1.0, -1.0] {
            let sum: Point = std::array::from_fn(|k| slab.normal[k] + sg * n[k]);
            let len = (0..3).map(|k| sum[k] * sum[k]).sum::<f64>().sqrt();
            if len > 1e-3 {
                dirs.push(sum.map(|x| x / len));
            }
        }
        dirs.push(n);
    }
    let inside = |w: &Point| insphere(&p[0], &p[1], &p[2], &p[3], w) * o.signum() > 0.0;
    for frac in [0.5, 0.3, 0.15, 0.05, 0.0] {
        for &(b, scale) in &bases {
            for (d, s) in dirs.iter().flat_map(|d| [(d, 1.0), (d, -1.0)]) {
                let w: Point = std::array::from_fn(|k| b[k] + s * frac * scale * d[k]);
                // Off every facet's slab: near one it could form flat tets there.
                if !inside(&w) || slabs.iter().flatten().any(|s| s.holds(&w)) {
                    continue;
                }
                if found.contains(&w) {
                    continue;
                }
                if containing_tet_near(cdt, tet, &w).is_some_and(|t| kept[t as usize]) {
                    found.push(w);
                    if found.len() == CANDIDATES {
                        return found;
                    }
                }
            }
        }
    }
    found
}

/// The tet's circumcenter and radius, when they are finite.
fn circumsphere(p: &[Point; 4]) -> Option<(Point, f64)> {
    let d: [Point; 3] = std::array::from_fn(|i| sub(&p[i + 1], &p[0]));
    let n: [f64; 3] = d.map(|x| dot(&x, &x));
    let (c12, c20, c01) = (
        cross(&d[1], &d[2]),
        cross(&d[2], &d[0]),
        cross(&d[0], &d[1]),
    );
    let det = 2.0 * dot(&d[0], &c12);
    let off: Point = std::array::from_fn(|k| (n[0] * c12[k] + n[1] * c20[k] + n[2] * c01[k]) / det);
    let r = dot(&off, &off).sqrt();
    (r.is_finite() && det != 0.0).then(|| (std::array::from_fn(|k| p[0][k] + off[k]), r))
}

/// The length of the bounding box's diagonal (1 for a single point).
fn diagonal(points: &[Point]) -> f64 {
    let [lo, hi] = crate::geom::bounding_box(points);
    let d = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
    if d > 0.0 {
        d
    } else {
        1.0
    }
}

/// The square of the tet's longest edge.
fn longest_edge2(p: &[Point; 4]) -> f64 {
    crate::mesh::EDGE_VERTS
        .iter()
        .map(|&(i, j)| (0..3).map(|k| (p[i][k] - p[j][k]).powi(2)).sum::<f64>())
        .fold(0.0, f64::max)
}
