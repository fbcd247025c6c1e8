//! Flat tets whose four vertices all lie on one facet yet survive carving. They span a
//! step or a dent of a facet that is not flat (a merged group of nearly coplanar
//! polygons, or a thin wedge between two of them), where both sides agree on the
//! polygon's triangles, so [`super::construction::resolve_shims`] has nothing to swap.
//! A Steiner point on the facet cannot help: whatever it forms with the facet's vertices
//! is as flat. A free vertex inside the tet's circumsphere, well off the facet and inside
//! the domain, removes the tet from the CDT instead.

use super::cdt::Cdt;
use super::domain::{containing_tet_near, domain, Domain};
use crate::geom::bvh::{Aabb, Bvh};
use crate::geom::polygon::newell_normal;
use crate::geom::predicates::{insphere, orient3d};
use crate::geom::{cross, diagonal, dot, longest_edge2, norm, sub, Point};
use crate::mesh::VertexId;
use crate::plc::prepare::PreparedPlc;
use crate::plc::Region;
use std::cell::OnceCell;

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

/// What a CDT's domain is made of besides its subfaces, as [`domain`] needs it.
pub(crate) struct DomainOf<'a> {
    pub holes: &'a [Point],
    pub regions: &'a [Region],
    pub keep_hull: bool,
}

/// What the search for tets on facets needs besides the CDT: the facets as merged
/// (`prep`), the input points, and the domain.
pub(crate) struct Search<'a> {
    pub prep: &'a PreparedPlc,
    pub input: &'a [Point],
    pub domain: DomainOf<'a>,
    /// Which facets each input vertex is on, and the facets' slabs: made when first
    /// needed (a model without Steiner points never needs them), unless `shared` gives
    /// them.
    pub index: OnceCell<FacetIndex>,
    /// The index made by the caller, who keeps it across searches.
    pub shared: Option<&'a FacetIndex>,
}

/// Which facets each input vertex is on, and the facets' slabs.
pub(crate) struct FacetIndex {
    on_facets: crate::mesh::VertexLists<u32>,
    slabs: Vec<Option<Slab>>,
    /// The thickest slab's half-thickness: a tet thicker than twice it lies in none.
    tol_max: f64,
    /// Each facet's slab as a box (empty without a slab), and a hierarchy over them.
    boxes: Vec<Aabb>,
    bvh: Bvh,
    /// Vertices with input indices below this are input vertices.
    n_input: usize,
}

impl FacetIndex {
    /// The index of `prep`'s facets over the points `input`, of which the first
    /// `n_input` are input vertices (the others, such as corners of polygons added to a
    /// live CDT, count as Steiner points: on a facet when its slab holds them).
    pub(crate) fn new(prep: &PreparedPlc, input: &[Point], n_input: usize) -> FacetIndex {
        let diag = diagonal(input);
        let slabs: Vec<Option<Slab>> = (0..prep.facets.len())
            .map(|fi| slab_of(prep, input, diag, fi))
            .collect();
        let boxes: Vec<Aabb> = slabs
            .iter()
            .map(|s| match s {
                Some(s) => [s.lo.map(|x| x - s.tol), s.hi.map(|x| x + s.tol)],
                None => [[f64::INFINITY; 3], [f64::NEG_INFINITY; 3]],
            })
            .collect();
        FacetIndex {
            bvh: Bvh::build(&boxes),
            boxes,
            on_facets: crate::mesh::VertexLists::new(
                input.len(),
                prep.facets
                    .iter()
                    .enumerate()
                    .filter(|(_, f)| f.normal != [0.0; 3])
                    .flat_map(|(fi, f)| ring_verts(f).into_iter().map(move |v| (v, fi as u32))),
            ),
            tol_max: slabs.iter().flatten().map(|s| s.tol).fold(0.0, f64::max),
            slabs,
            n_input,
        }
    }

    /// The facet of which the tet with points `p` and input indices `o` would be a
    /// shim: flat, with all four vertices on that facet (see [`Self::facet_holding`]).
    pub(crate) fn shim_facet(&self, p: &[Point; 4], o: [u32; 4]) -> Option<u32> {
        if !may_lie_in_slab(p, self.tol_max) || !is_flat(p) {
            return None;
        }
        self.facet_holding(p, o)
    }

    /// The facet that the tet with points `p` whose input indices are `o` (Steiner
    /// points have indices past the input's) has all four vertices on, if any: input
    /// vertices by the facets' rings, Steiner points by the facets' slabs. The lowest
    /// such facet is named.
    fn facet_holding(&self, p: &[Point; 4], o: [u32; 4]) -> Option<u32> {
        let on = |i: usize, f: u32| -> bool {
            if (o[i] as usize) < self.n_input {
                self.on_facets.of(o[i]).contains(&f)
            } else {
                self.slabs[f as usize]
                    .as_ref()
                    .is_some_and(|s| s.holds(&p[i]))
            }
        };
        // With an input vertex, the facets the tet can lie on are among that vertex's
        // (the shortest such list is tried, in increasing order). Most tets go this way.
        if let Some(x) = (0..4)
            .filter(|&i| (o[i] as usize) < self.n_input)
            .min_by_key(|&i| self.on_facets.of(o[i]).len())
        {
            return self
                .on_facets
                .of(o[x])
                .iter()
                .copied()
                .find(|&f| (0..4).all(|i| on(i, f)));
        }
        // A tet of Steiner points has no input vertex to name its facet: any facet whose
        // slab holds all four may, even one none of their segments touches (a bent
        // group's slab can hold the split points of a neighbouring fan). The lowest is
        // named.
        let bbox: Aabb = [
            std::array::from_fn(|k| p.iter().map(|q| q[k]).fold(f64::INFINITY, f64::min)),
            std::array::from_fn(|k| p.iter().map(|q| q[k]).fold(f64::NEG_INFINITY, f64::max)),
        ];
        let mut best: Option<u32> = None;
        self.bvh.query(&self.boxes, &bbox, |f| {
            let f = f as u32;
            if best.is_none_or(|b| f < b) && (0..4).all(|i| on(i, f)) {
                best = Some(f);
            }
        });
        best
    }
}

impl Search<'_> {
    fn index(&self) -> &FacetIndex {
        if let Some(index) = self.shared {
            return index;
        }
        self.index
            .get_or_init(|| FacetIndex::new(self.prep, self.input, self.input.len()))
    }

    /// Facet `fi`'s slab, if it has one.
    fn slab(&self, fi: usize) -> Option<&Slab> {
        self.index().slabs[fi].as_ref()
    }

    /// Whether the tet is thin enough to lie in some facet's slab (see
    /// [`may_lie_in_slab`]): most tets are not, and this is cheaper than asking each facet.
    fn may_lie_in_a_slab(&self, p: &[Point; 4]) -> bool {
        may_lie_in_slab(p, self.index().tol_max)
    }

    /// The facet that the tet's four vertices all lie on, if any: input vertices by the
    /// facets' rings, Steiner points by the facets' slabs. The lowest such facet is
    /// named.
    fn facet_of(&self, cdt: &Cdt, v: [VertexId; 4]) -> Option<u32> {
        self.facet_holding(
            &v.map(|x| cdt.dt.points[x as usize]),
            v.map(|x| cdt.dt.orig[x as usize]),
        )
    }

    /// [`FacetIndex::facet_holding`].
    fn facet_holding(&self, p: &[Point; 4], o: [u32; 4]) -> Option<u32> {
        self.index().facet_holding(p, o)
    }

    /// Whether the faces around vertex `v` (through it, or else opposite it in its tets)
    /// that are not subfaces but have their three vertices on one facet cover more than a
    /// trace of it (projected on the facet's normal, together over a millionth of its
    /// area, the referee's tolerance): they would lie on the facet beside its triangles.
    /// Only the faces of tets that `kept` accepts count (asked only for faces on a
    /// facet: the test may be costly).
    pub(crate) fn covering_face_around(
        &self,
        cdt: &Cdt,
        v: VertexId,
        through: bool,
        kept: impl Fn(crate::mesh::TetId) -> bool,
    ) -> bool {
        let mut star = Vec::new();
        cdt.dt.star(v, &mut star);
        self.covering_face_in(cdt, v, &star, through, kept)
    }

    /// [`Self::covering_face_around`] with the star of `v` given.
    pub(crate) fn covering_face_in(
        &self,
        cdt: &Cdt,
        v: VertexId,
        star: &[crate::mesh::TetId],
        through: bool,
        kept: impl Fn(crate::mesh::TetId) -> bool,
    ) -> bool {
        let mut covered: Vec<(u32, f64)> = Vec::new();
        for &t in star.iter().filter(|&&t| !cdt.is_ghost(t)) {
            for (i, &x) in cdt.dt.mesh.verts(t).iter().enumerate() {
                // The faces through `v` are those opposite its other vertices.
                if (x == v) == through || cdt.is_subface(t, i) {
                    continue;
                }
                let f = cdt.dt.mesh.face_verts(t, i);
                let Some(fi) = self.facet_of(cdt, [f[0], f[1], f[2], f[2]]) else {
                    continue;
                };
                let Some(slab) = self.slab(fi as usize) else {
                    continue;
                };
                let q = f.map(|x| cdt.dt.points[x as usize]);
                if !self.face_inside_facet(fi as usize, &q) || !kept(t) {
                    continue;
                }
                let n = cross(&sub(&q[1], &q[0]), &sub(&q[2], &q[0]));
                // A face through `v` is seen from both its tets around `v`: halved.
                let seen = if through { 0.25 } else { 0.5 };
                let area = seen * dot(&n, &slab.normal).abs();
                match covered.iter_mut().find(|(f, _)| *f == fi) {
                    Some((_, a)) => *a += area,
                    None => covered.push((fi, area)),
                }
            }
        }
        covered.iter().any(|&(fi, a)| {
            self.slab(fi as usize)
                .is_some_and(|s| a > 1e-6 * self.facet_area(fi as usize, &s.normal))
        })
    }

    /// A facet that a face of tet `t` which is not a subface lies on, inside one of the
    /// facet's polygons and covering more than a trace of it, if any.
    fn covered_by_face_of(&self, cdt: &Cdt, t: crate::mesh::TetId) -> Option<u32> {
        (0..4).filter(|&i| !cdt.is_subface(t, i)).find_map(|i| {
            let f = cdt.dt.mesh.face_verts(t, i);
            let fi = self.facet_of(cdt, [f[0], f[1], f[2], f[2]])?;
            let slab = self.slab(fi as usize)?;
            let q = f.map(|x| cdt.dt.points[x as usize]);
            // The referee's tolerance on a facet's coverage, as in
            // `covering_face_around`: a face standing across the slab covers nothing.
            let n = cross(&sub(&q[1], &q[0]), &sub(&q[2], &q[0]));
            let area = 0.5 * dot(&n, &slab.normal).abs();
            (area > 1e-6 * self.facet_area(fi as usize, &slab.normal)
                && self.face_on_a_polygon(fi as usize, &q))
            .then_some(fi)
        })
    }

    /// Whether triangle `q` lies on one of merged facet `fi`'s polygons as the referee
    /// measures it: a sample point (its centroid, or halfway from it to a corner) near
    /// the polygon's own plane and inside it seen along the polygon's own normal. Nearness
    /// is the polygon's own flatness four times, and a five-hundredth of its size, for
    /// a diagonal flipped across a merged neighbour.
    fn face_on_a_polygon(&self, fi: usize, q: &[Point; 3]) -> bool {
        let f = &self.prep.facets[fi];
        if !f.holes.is_empty() {
            return false;
        }
        let tiny = 1e-10 * diagonal(self.input);
        let samples = face_samples(q);
        f.rings.iter().any(|ring| {
            let n = newell_normal(self.input, ring);
            let len = norm(&n);
            if len == 0.0 {
                return false;
            }
            let n = n.map(|x| x / len);
            let pts = || ring.iter().map(|&v| self.input[v as usize]);
            let k = ring.len() as f64;
            let mean: Point = std::array::from_fn(|c| pts().map(|p| p[c]).sum::<f64>() / k);
            let flat = pts()
                .map(|p| dot(&sub(&p, &mean), &n).abs())
                .fold(0.0, f64::max);
            let lo: Point =
                std::array::from_fn(|c| pts().map(|p| p[c]).fold(f64::INFINITY, f64::min));
            let hi: Point =
                std::array::from_fn(|c| pts().map(|p| p[c]).fold(f64::NEG_INFINITY, f64::max));
            let t = tiny + 4.0 * flat + 0.002 * norm(&sub(&hi, &lo));
            let axes = projection_axes(&n);
            samples.iter().any(|w| {
                (0..3).all(|c| w[c] >= lo[c] - t && w[c] <= hi[c] + t)
                    && dot(&sub(w, &mean), &n).abs() <= t
                    && inside_ring(self.input, ring, axes, w)
            })
        })
    }

    /// Whether triangle `q`, near merged facet `fi`'s plane, lies inside one of its
    /// polygons, as the referee asks: its centroid or a point halfway from it to a corner
    /// inside one, seen along the facet's normal. The referee does not measure the
    /// coverage of a facet with holes: never for those.
    fn face_inside_facet(&self, fi: usize, q: &[Point; 3]) -> bool {
        let f = &self.prep.facets[fi];
        if !f.holes.is_empty() {
            return false;
        }
        let axes = projection_axes(&f.normal);
        face_samples(q).iter().any(|w| {
            f.rings
                .iter()
                .any(|ring| inside_ring(self.input, ring, axes, w))
        })
    }

    /// The area of merged facet `fi` projected on `normal`.
    fn facet_area(&self, fi: usize, normal: &Point) -> f64 {
        self.prep.facets[fi]
            .rings
            .iter()
            .map(|ring| 0.5 * dot(&newell_normal(self.input, ring), normal).abs())
            .sum()
    }

    /// Whether some tet around vertex `v` has all four vertices on one facet, or is flat
    /// and covers one with a face (see [`Self::covered_by_face_of`]).
    pub(crate) fn on_facet_around(&self, cdt: &Cdt, v: VertexId) -> bool {
        let mut star = Vec::new();
        cdt.dt.star(v, &mut star);
        star.iter().filter(|&&t| !cdt.is_ghost(t)).any(|&t| {
            let f = self.facet_of(cdt, cdt.dt.mesh.verts(t));
            if super::debug() && f.is_some() {
                eprintln!(
                    "  around: {:?} on {f:?} flat {}",
                    cdt.dt.mesh.verts(t),
                    is_flat(&cdt.dt.mesh.verts(t).map(|x| cdt.dt.points[x as usize]))
                );
            }
            f.is_some()
                || (is_flat(&cdt.dt.mesh.verts(t).map(|x| cdt.dt.points[x as usize]))
                    && self.covered_by_face_of(cdt, t).is_some())
        })
    }
}

/// A free vertex that may remove a tet on a facet.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Candidate {
    pub at: Point,
    /// It lies in some facet's slab, or its tet is not flat: once in, it stays only if
    /// no tet around it has all four vertices on one facet.
    pub checked: bool,
}

/// The tets that carving keeps with all four vertices on one facet.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct OnFacets {
    /// How many there are.
    pub tets: usize,
    /// How many of them are flat; the others are thick but squashed within the slab of
    /// a facet that bends.
    pub flat: usize,
    /// The facet of the first.
    pub first: Option<u32>,
}

impl OnFacets {
    fn of(tets: &[(crate::mesh::TetId, u32, bool)]) -> Self {
        OnFacets {
            tets: tets.len(),
            flat: tets.iter().filter(|x| x.2).count(),
            first: tets.first().map(|x| x.1),
        }
    }
}

/// What [`free_points`] found.
#[derive(Default)]
pub(crate) struct FlatTets {
    /// Free vertices that remove tets on facets: for each tet, the candidates in order
    /// of preference (a point that would break the CDT, by encroaching upon a
    /// subsegment, or that a check refuses, gives way to the next).
    pub points: Vec<Vec<Candidate>>,
    /// The kept flat tets for which no free vertex was found (their circumspheres lie
    /// within the facet's slab), by their vertices.
    pub stuck: Vec<[crate::mesh::VertexId; 4]>,
    /// The tets on facets, as found before any of the points goes in.
    pub found: OnFacets,
}

/// The tets on facets that carving keeps: each with its facet and whether it is flat.
struct Found {
    tets: Vec<(crate::mesh::TetId, u32, bool)>,
    /// Which tet slots carving keeps.
    kept: Vec<bool>,
}

/// Finds the tets that carving keeps and whose four vertices lie on one facet: flat
/// ones, and thick ones squashed within the slab of a facet that bends (their faces
/// would lie on the facet beside its triangles); `None` if there are none. `carved` is
/// the CDT's carving if known, and is set if made.
fn find_flat(cdt: &mut Cdt, search: &Search<'_>, carved: &mut Option<Domain>) -> Option<Found> {
    let Search { prep, input, .. } = search;
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
    let tets: Vec<(crate::mesh::TetId, u32, bool)> = cdt
        .dt
        .mesh
        .live_tets()
        .filter(|&t| !cdt.is_ghost(t) && candidate(cdt.dt.mesh.verts(t)))
        .filter_map(|t| {
            let v = cdt.dt.mesh.verts(t);
            let p = v.map(|x| cdt.dt.points[x as usize]);
            if !search.may_lie_in_a_slab(&p) {
                return None;
            }
            let f = search.facet_of(cdt, v)?;
            Some((t, f, is_flat(&p)))
        })
        .collect();
    if tets.is_empty() {
        return None;
    }
    // Only kept tets matter, and the carving is needed anyway (the output reuses it):
    // tets outside the domain, often many, are dropped here.
    let kept = kept_mask(cdt, search, carved);
    let tets: Vec<_> = tets.into_iter().filter(|x| kept[x.0 as usize]).collect();
    if super::debug() {
        eprintln!("tets on facets {tets:?}");
    }
    (!tets.is_empty()).then_some(Found { tets, kept })
}

/// How many tets that carving keeps lie on one facet, and the facet of the first: what
/// is left once no free point removes any more; and, when at most `max_retry` are left,
/// the [`retry_points`] of the first thick one. One search for both. `carved` as in
/// [`free_points`].
pub(crate) fn flat_left(
    cdt: &mut Cdt,
    search: &Search<'_>,
    carved: &mut Option<Domain>,
    max_retry: usize,
) -> (OnFacets, Vec<Point>) {
    let Some(found) = find_flat(cdt, search, carved) else {
        return (OnFacets::default(), Vec::new());
    };
    let left = OnFacets::of(&found.tets);
    let retry = if left.tets <= max_retry {
        retry_points(cdt, search, &found)
    } else {
        Vec::new()
    };
    (left, retry)
}

/// Which tet slots carving keeps; `carved` is the CDT's carving if known, and is set if
/// made.
fn kept_mask(cdt: &mut Cdt, search: &Search<'_>, carved: &mut Option<Domain>) -> Vec<bool> {
    carved
        .get_or_insert_with(|| {
            domain(
                cdt,
                search.domain.holes,
                search.domain.regions,
                search.domain.keep_hull,
            )
        })
        .kept_mask(cdt.dt.mesh.num_slots())
}

/// The flat tets that carving keeps which lie on no facet but have a face, not a
/// subface, on one (see [`Search::covered_by_face_of`]): a facet's triangles and that
/// face both cover it. Most hug a crease between nearly coplanar facets, with one
/// vertex just off the facet's box or slab, so that they are no shims and the
/// free-point search does not look at them. `carved` as in [`free_points`].
pub(crate) fn covering_flat_tets(
    cdt: &mut Cdt,
    search: &Search<'_>,
    carved: &mut Option<Domain>,
) -> Vec<[VertexId; 4]> {
    let kept = kept_mask(cdt, search, carved);
    let n_input = search.input.len();
    cdt.dt
        .mesh
        .live_tets()
        .filter(|&t| kept[t as usize] && !cdt.is_ghost(t))
        .filter_map(|t| {
            let v = cdt.dt.mesh.verts(t);
            if v.iter()
                .all(|&x| (cdt.dt.orig[x as usize] as usize) < n_input)
            {
                return None;
            }
            let p = v.map(|x| cdt.dt.points[x as usize]);
            if !is_flat(&p) || !search.may_lie_in_a_slab(&p) || search.facet_of(cdt, v).is_some() {
                return None;
            }
            search.covered_by_face_of(cdt, t).map(|_| v)
        })
        .collect()
}

/// Free vertices that remove the tets lying on one facet, a list for each such tet, and
/// the flat tets they cannot remove. `carved` is the CDT's carving if known, and is set
/// if made. The search stops once it has spent `budget`: a unit for each step of its
/// point-location walks ([`Delaunay::walk_steps`](crate::delaunay::Delaunay::walk_steps))
/// and for each slab a candidate place is tested against.
pub(crate) fn free_points(
    cdt: &mut Cdt,
    search: &Search<'_>,
    carved: &mut Option<Domain>,
    budget: &mut u64,
) -> FlatTets {
    let Some(Found { tets, kept }) = find_flat(cdt, search, carved) else {
        return FlatTets::default();
    };
    // A free point is sought off every facet's slab first: all are needed from here on.
    let slabs = &search.index().slabs;
    let mut out = FlatTets {
        found: OnFacets::of(&tets),
        ..Default::default()
    };
    for (t, f, flat) in tets {
        if *budget == 0 {
            break;
        }
        let Some(slab) = slabs[f as usize].as_ref() else {
            continue;
        };
        let p = cdt.dt.mesh.verts(t).map(|x| cdt.dt.points[x as usize]);
        let ws = remover(cdt, &kept, (t, &p), flat, slab, slabs, budget);
        // A flat tet with no point off every slab may still be split (see `mod.rs`)
        // if the checked points fail.
        if flat && ws.first().is_none_or(|c| c.checked) {
            out.stuck.push(cdt.dt.mesh.verts(t));
        }
        // A thick tet whose sphere holds an earlier tet's first point goes with it: two
        // points close together would make tets as bad.
        let o = orient3d(&p[0], &p[1], &p[2], &p[3]).signum();
        let taken = |w: &Candidate| {
            out.points.iter().any(|x| {
                x[0] == *w || (!flat && insphere(&p[0], &p[1], &p[2], &p[3], &x[0].at) * o > 0.0)
            })
        };
        if ws.first().is_some_and(|w| !taken(w)) {
            out.points.push(ws);
        }
    }
    out
}

/// Points for another construction when a few thick tets are left on facets (see
/// `mod.rs`): just off the first such tet's facet's slab, on lines along the facet's
/// normal through points a quarter of the way from its circumcenter to each of its
/// vertices, then through the circumcenter; inside the domain. Such a tet sits where
/// facets meet at a step, the CDT lets no point into its sphere in place, and which of
/// these places leaves no tet on any facet only a construction tells.
fn retry_points(cdt: &mut Cdt, search: &Search<'_>, found: &Found) -> Vec<Point> {
    let Found { tets, kept } = found;
    let Some(&(t, f, _)) = tets.iter().find(|x| !x.2) else {
        return Vec::new();
    };
    let Some(slab) = search.slab(f as usize) else {
        return Vec::new();
    };
    let p = cdt.dt.mesh.verts(t).map(|x| cdt.dt.points[x as usize]);
    let Some((c, _)) = circumsphere(&p) else {
        return Vec::new();
    };
    let mut out: Vec<Point> = Vec::new();
    let bases = p
        .iter()
        .map(|v| std::array::from_fn(|k| c[k] + 0.25 * (v[k] - c[k])))
        .chain(std::iter::once(c));
    for b in bases {
        for side in [-1.0, 1.0] {
            let lift = side * slab.tol * 1.03 - slab.height(&b);
            let w: Point = std::array::from_fn(|k| b[k] + lift * slab.normal[k]);
            if out.contains(&w) {
                continue;
            }
            if containing_tet_near(cdt, t, &w).is_some_and(|x| kept[x as usize]) {
                out.push(w);
            }
        }
    }
    out
}

/// The sorted vertices of a merged facet's rings.
fn ring_verts(f: &crate::plc::prepare::MergedFacet) -> Vec<u32> {
    let mut verts: Vec<u32> = f.rings.iter().flatten().copied().collect();
    verts.sort_unstable();
    verts.dedup();
    verts
}

/// The two coordinate axes a plane with normal `n` is seen along its normal in (those
/// other than `n`'s largest component).
fn projection_axes(n: &Point) -> (usize, usize) {
    let ax = (0..3)
        .max_by(|&a, &b| n[a].abs().total_cmp(&n[b].abs()))
        .unwrap_or(2);
    ((ax + 1) % 3, (ax + 2) % 3)
}

/// Whether point `w`, seen along axes `(i, j)`, lies inside the ring of input points
/// `ring` (even-odd rule).
fn inside_ring(input: &[Point], ring: &[u32], (i, j): (usize, usize), w: &Point) -> bool {
    let mut odd = false;
    for (k, &x) in ring.iter().enumerate() {
        let a = input[x as usize];
        let b = input[ring[(k + 1) % ring.len()] as usize];
        if (a[j] > w[j]) != (b[j] > w[j])
            && w[i] < a[i] + (w[j] - a[j]) * (b[i] - a[i]) / (b[j] - a[j])
        {
            odd = !odd;
        }
    }
    odd
}

/// The points of triangle `q` the referee samples for coverage: its centroid, and the
/// points halfway from it to each corner.
fn face_samples(q: &[Point; 3]) -> [Point; 4] {
    let third = 1.0 / 3.0;
    [
        [third, third, third],
        [0.5, 0.25, 0.25],
        [0.25, 0.5, 0.25],
        [0.25, 0.25, 0.5],
    ]
    .map(|w| std::array::from_fn(|c| w[0] * q[0][c] + w[1] * q[1][c] + w[2] * q[2][c]))
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

/// Whether the tet may lie in a slab of half-thickness `tol`. A tet between two planes
/// `w` apart has at most `2 w` times its largest face's area as volume (its
/// cross-sections are no larger than its shadow, which its faces cover twice), so within
/// the slab `|det| <= 24 tol A_max`; twice that allows for rounding.
fn may_lie_in_slab(p: &[Point; 4], tol: f64) -> bool {
    let d: [Point; 3] = std::array::from_fn(|i| sub(&p[i + 1], &p[0]));
    let det = dot(&d[0], &cross(&d[1], &d[2]));
    let (e, f) = (sub(&p[2], &p[1]), sub(&p[3], &p[1]));
    // Each |cross| is twice a face's area.
    let largest2 = [
        cross(&d[0], &d[1]),
        cross(&d[1], &d[2]),
        cross(&d[2], &d[0]),
        cross(&e, &f),
    ]
    .iter()
    .map(|n| dot(n, n))
    .fold(0.0, f64::max);
    let bound = 24.0 * tol;
    det * det <= bound * bound * largest2 || !det.is_finite()
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

/// The number of places [`remover`] offers for one tet.
const CANDIDATES: usize = 6;

/// Points inside the tet's circumsphere and inside a kept tet, best first. They are
/// sought on lines along the facet's normal through the tet's centroid, its
/// circumcenter and the point halfway, farthest from the facet first: a flat tet along
/// an edge where two facets meet has its sphere off to one side.
///
/// Points off every facet's slab come first. A thick tet's sphere is small, and where
/// facets meet at a step it may lie within another facet's slab: then points off its
/// own facet's slab follow, near the far side of the sphere too, and each must pass a
/// check once in (see [`Candidate`]).
fn remover(
    cdt: &mut Cdt,
    kept: &[bool],
    (tet, p): (crate::mesh::TetId, &[Point; 4]),
    flat: bool,
    slab: &Slab,
    slabs: &[Option<Slab>],
    budget: &mut u64,
) -> Vec<Candidate> {
    let mut found: Vec<Candidate> = Vec::new();
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
    let fracs: &[f64] = if flat {
        &[0.5, 0.3, 0.15, 0.05, 0.0]
    } else {
        &[0.95, 0.8, 0.5, 0.3, 0.15, 0.05, 0.0]
    };
    // Every candidate lies within this box (the directions are unit vectors, with room
    // for rounding), and so does the centroid: only the slabs whose boxes meet it can
    // hold one. A model has thousands of facets, and a tet hundreds of candidates.
    let reach = 1.001 * fracs[0] * bases.iter().map(|&(_, s)| s).fold(0.0, f64::max);
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for (b, _) in &bases {
        for k in 0..3 {
            lo[k] = lo[k].min(b[k] - reach);
            hi[k] = hi[k].max(b[k] + reach);
        }
    }
    let near: Vec<&Slab> = slabs
        .iter()
        .flatten()
        .filter(|s| (0..3).all(|k| s.lo[k] - s.tol <= hi[k] && s.hi[k] + s.tol >= lo[k]))
        .collect();
    // Along an edge where facets meet, the point must leave all their slabs at once:
    // the facet's normal, each other facet's there, and their sums and differences.
    let mut dirs: Vec<Point> = vec![slab.normal];
    for n in near
        .iter()
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
    for strict in [true, false] {
        for &frac in fracs {
            for &(b, scale) in &bases {
                for (d, s) in dirs.iter().flat_map(|d| [(d, 1.0), (d, -1.0)]) {
                    let w: Point = std::array::from_fn(|k| b[k] + s * frac * scale * d[k]);
                    // Off every facet's slab (near one it could form flat tets there),
                    // or, failing that, off the tet's own.
                    let off = off_slabs(&w, &near, slab, strict, budget);
                    if !off || !inside(&w) || found.iter().any(|c| c.at == w) {
                        continue;
                    }
                    if *budget == 0 {
                        return found;
                    }
                    let steps = cdt.dt.walk_steps();
                    let holder = containing_tet_near(cdt, tet, &w);
                    *budget = budget.saturating_sub(cdt.dt.walk_steps() - steps);
                    if holder.is_some_and(|t| kept[t as usize]) {
                        found.push(Candidate {
                            at: w,
                            checked: !strict || !flat,
                        });
                        if found.len() == CANDIDATES {
                            return found;
                        }
                    }
                }
            }
        }
        if !found.is_empty() {
            break;
        }
    }
    found
}

/// Whether `w` lies off every slab of `near` (if `strict`; near one it could form flat
/// tets there) or else off `own`, charging `budget` a unit for each slab it could test:
/// around a far vertex every slab's box is near, and these tests alone took seconds.
fn off_slabs(w: &Point, near: &[&Slab], own: &Slab, strict: bool, budget: &mut u64) -> bool {
    let (off, tests) = if strict {
        (!near.iter().any(|s| s.holds(w)), near.len())
    } else {
        (!own.holds(w), 1)
    };
    *budget = budget.saturating_sub(tests as u64);
    off
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::lcg;

    #[test]
    fn a_face_covers_a_facet_only_inside_its_polygons() {
        // An L-shaped facet in z = 0 (the notch is [1, 2] x [1, 2]), and a square one in
        // z = 5 with a square hole in its middle, whose coverage the referee leaves
        // alone.
        let points: Vec<Point> = [
            [0.0, 0.0],
            [2.0, 0.0],
            [2.0, 1.0],
            [1.0, 1.0],
            [1.0, 2.0],
            [0.0, 2.0],
        ]
        .iter()
        .map(|&[x, y]| [x, y, 0.0])
        .chain(
            [[0.0, 0.0], [3.0, 0.0], [3.0, 3.0], [0.0, 3.0]]
                .iter()
                .chain(&[[1.0, 1.0], [2.0, 1.0], [2.0, 2.0], [1.0, 2.0]])
                .map(|&[x, y]| [x, y, 5.0]),
        )
        .collect();
        let plc = crate::plc::Plc {
            points,
            facets: vec![
                crate::plc::Facet {
                    polygons: vec![(0..6).collect()],
                    ..Default::default()
                },
                crate::plc::Facet {
                    polygons: vec![(6..10).collect(), (10..14).collect()],
                    holes: vec![[1.5, 1.5, 5.0]],
                    ..Default::default()
                },
            ],
            ..Default::default()
        };
        let prep = crate::plc::prepare::prepare(&plc, true).unwrap();
        let search = Search {
            prep: &prep,
            input: &plc.points,
            domain: DomainOf {
                holes: &[],
                regions: &[],
                keep_hull: false,
            },
            index: Default::default(),
            shared: None,
        };
        let tri = |x: f64, y: f64, z: f64| [[x, y, z], [x + 0.2, y, z], [x, y + 0.2, z]];
        let facet = |z: f64| {
            let f = prep
                .facets
                .iter()
                .position(|f| plc.points[f.rings[0][0] as usize][2] == z);
            f.unwrap()
        };
        let (l, holed) = (facet(0.0), facet(5.0));
        assert!(search.face_inside_facet(l, &tri(0.2, 0.2, 0.0)));
        assert!(search.face_inside_facet(l, &tri(0.2, 1.5, 1e-9)));
        assert!(!search.face_inside_facet(l, &tri(1.5, 1.5, 0.0)));
        assert!(!search.face_inside_facet(l, &tri(2.5, 0.2, 0.0)));
        for (x, y) in [(0.2, 0.2), (2.5, 2.5), (1.4, 1.4)] {
            assert!(!search.face_inside_facet(holed, &tri(x, y, 5.0)));
        }
    }

    #[test]
    fn a_tet_of_steiner_points_is_named_by_any_slab_that_holds_it() {
        // Two quads, each slightly bent (one corner 0.01 up), far apart: slabs 0.04 thick
        // at z = 0 and z = 10. No segment of either passes near the Steiner points below,
        // which only a slab can name.
        let quad = |z: f64| {
            [
                [0.0, 0.0, z],
                [4.0, 0.0, z],
                [4.0, 4.0, z + 0.01],
                [0.0, 4.0, z],
            ]
        };
        let plc = crate::plc::Plc {
            points: quad(0.0).into_iter().chain(quad(10.0)).collect(),
            facets: vec![
                crate::plc::Facet {
                    polygons: vec![(0..4).collect()],
                    ..Default::default()
                },
                crate::plc::Facet {
                    polygons: vec![(4..8).collect()],
                    ..Default::default()
                },
            ],
            ..Default::default()
        };
        let prep = crate::plc::prepare::prepare(&plc, true).unwrap();
        let search = Search {
            prep: &prep,
            input: &plc.points,
            domain: DomainOf {
                holes: &[],
                regions: &[],
                keep_hull: false,
            },
            index: Default::default(),
            shared: None,
        };
        let top = prep
            .facets
            .iter()
            .position(|f| plc.points[f.rings[0][0] as usize][2] == 10.0)
            .unwrap() as u32;
        let tet = |z: f64| {
            [
                [1.0, 1.0, z],
                [2.0, 1.0, z],
                [1.0, 2.0, z],
                [2.0, 2.0, z + 0.005],
            ]
        };
        let steiner = [8, 9, 10, 11];
        assert_eq!(search.facet_holding(&tet(10.0), steiner), Some(top));
        assert_eq!(search.facet_holding(&tet(10.5), steiner), None);
        assert_eq!(search.facet_holding(&tet(5.0), steiner), None);
        // With an input vertex, its own facets decide.
        assert_eq!(search.facet_holding(&tet(10.0), [8, 9, 10, 1]), None);
        assert_eq!(search.facet_holding(&tet(10.0), [8, 9, 10, 5]), Some(top));
        // A face covers the facet where it lies near the polygon's own plane (within a
        // five-hundredth of its size, here 0.011, plus its flatness) and inside it.
        let top = top as usize;
        let face = |x: f64, z: f64| [[x, 1.0, z], [x + 1.0, 1.0, z], [x, 2.0, z]];
        assert!(search.face_on_a_polygon(top, &face(1.0, 10.0)));
        assert!(search.face_on_a_polygon(top, &face(1.0, 10.012)));
        assert!(!search.face_on_a_polygon(top, &face(1.0, 10.2)));
        assert!(!search.face_on_a_polygon(top, &face(5.0, 10.0)));
    }

    #[test]
    fn slab_tests_are_charged_to_the_search_budget() {
        // Horizontal slabs 0.1 thick at heights 0, 1 and 2 over the unit square.
        let slab = |z: f64| Slab {
            normal: [0.0, 0.0, 1.0],
            mean: [0.5, 0.5, z],
            tol: 0.1,
            lo: [0.0, 0.0, z],
            hi: [1.0, 1.0, z],
        };
        let slabs = [slab(0.0), slab(1.0), slab(2.0)];
        let near: Vec<&Slab> = slabs.iter().collect();
        let mut budget = 10;
        assert!(!off_slabs(
            &[0.5, 0.5, 1.05],
            &near,
            &slabs[0],
            true,
            &mut budget
        ));
        assert_eq!(budget, 7);
        assert!(off_slabs(
            &[0.5, 0.5, 1.5],
            &near,
            &slabs[0],
            true,
            &mut budget
        ));
        assert_eq!(budget, 4);
        assert!(off_slabs(
            &[0.5, 0.5, 1.05],
            &near,
            &slabs[0],
            false,
            &mut budget
        ));
        assert_eq!(budget, 3);
        for _ in 0..2 {
            off_slabs(&[0.5, 0.5, 1.5], &near, &slabs[0], true, &mut budget);
        }
        assert_eq!(budget, 0);
    }

    #[test]
    fn tets_in_a_slab_pass_the_thinness_bound_and_thick_ones_do_not() {
        let mut st = 7u64;
        // A tilted slab: unit normal n, half-thickness tol, through the origin.
        let n = [0.36, 0.48, 0.8];
        let (u, v) = ([0.8, -0.6, 0.0], [0.48, 0.64, -0.6]);
        for tol in [1e-10, 1e-6, 1e-3] {
            for _ in 0..2000 {
                let p: [Point; 4] = std::array::from_fn(|_| {
                    let (a, b, h) = (lcg(&mut st) - 0.5, lcg(&mut st) - 0.5, lcg(&mut st));
                    // Heights at the slab's faces too, the worst case.
                    let h = tol
                        * if h < 0.2 {
                            -1.0
                        } else if h > 0.8 {
                            1.0
                        } else {
                            2.0 * h - 1.0
                        };
                    std::array::from_fn(|k| a * u[k] + b * v[k] + h * n[k])
                });
                assert!(may_lie_in_slab(&p, tol), "{p:?} {tol}");
            }
        }
        // A sliver across the slab, two vertices on each face: |det| is 4 tol |cross|.
        for tol in [1e-9, 1e-3] {
            let sliver = [
                [1.0, 0.0, tol],
                [-1.0, 0.0, tol],
                [0.0, 1.0, -tol],
                [0.0, -1.0, -tol],
            ];
            assert!(may_lie_in_slab(&sliver, tol));
        }
        let regular = [
            [1.0, 1.0, 1.0],
            [1.0, -1.0, -1.0],
            [-1.0, 1.0, -1.0],
            [-1.0, -1.0, 1.0],
        ];
        assert!(!may_lie_in_slab(&regular, 0.01));
        assert!(may_lie_in_slab(&regular, 1.0));
    }
}
