//! Delaunay refinement of the live CDT (`-q`, `-a`): the tets of the domain that are too
//! elongated, too flat or too large are split at their circumcentres, in place, until
//! none is left or the ones left are next to small input angles.
//!
//! A bad tet's circumcentre is found by a walk from the tet that stops at subfaces:
//! - inside the domain, where it encroaches upon no constraint, it is inserted (a walled
//!   cavity and flips, as every free point);
//! - where it lies in the diametral ball of a subsegment, or the equatorial ball of a
//!   subface, of its cavity, that constraint is split instead (Shewchuk's rule: middles
//!   of subsegments, or power-of-two shells around input vertices; circumcentres of
//!   subfaces, or their subsegments when those encroach);
//! - beyond a subface (outside the tet's side of it), that subface is split.
//!
//! Under `-Y` ([`RefineParameters::keep_boundary`]) no constraint is split: a tet whose
//! circumcentre encroaches upon a constraint or lies beyond a subface is left (its
//! circumcentre would make tets against the boundary that no split could mend).
//!
//! The point a bad tet asks for must lie at least half the tet's shortest edge from every
//! vertex of its cavity (never less than a fixed floor): a circumcentre always does, and a
//! split point closer than that comes from a small input angle, where splitting would
//! only make ever shorter edges; the tet is then left (counted). ARCHITECTURE.md gives
//! why refinement ends.

use super::{Cdt, InsertError};
use crate::constrained::cdt::face_key;
use crate::constrained::domain::NO_REGION;
use crate::geom::encroach::circumcenter as face_circumcenter;
use crate::geom::quality;
use crate::geom::{norm, orient3d, sub, Point};
use crate::mesh::{FaceRef, TetId, VertexId, FACE_VERTS};
use rustc_hash::FxHashSet;

/// What refinement aims for.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RefineParameters {
    /// The largest radius-edge ratio a tet may keep (`-q`).
    pub max_ratio: Option<f64>,
    /// The smallest dihedral angle a tet may keep, in degrees (`-q…/angle`).
    pub min_dihedral: Option<f64>,
    /// The largest volume a tet may keep (`-a<vol>`).
    pub max_volume: Option<f64>,
    /// Whether each region's volume bound from the PLC applies too (`-a`).
    pub region_volumes: bool,
    /// No split of a subsegment or subface (`-Y`): only circumcentres inside the domain
    /// that encroach upon nothing go in, and the tets that need more are left.
    pub keep_boundary: bool,
}

impl RefineParameters {
    /// Whether any bound is set.
    pub fn any(&self) -> bool {
        self.max_ratio.is_some()
            || self.min_dihedral.is_some_and(|a| a > 0.0)
            || self.max_volume.is_some()
            || self.region_volumes
    }
}

/// What refinement did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct RefineResult {
    /// Points added (circumcentres and constraint splits).
    pub points: usize,
    /// Bad tets left in the domain, each next to a vertex that a split would come
    /// closer to than its insertion radius floor allows (small input angles).
    pub left: usize,
    /// Passes over the domain.
    pub passes: usize,
    /// Whether the Steiner point budget (`-S`) ran out first.
    pub budget_spent: bool,
}

/// A bad tet of the domain.
struct Bad {
    /// How far over its bounds it is (above 1).
    over: f64,
    /// Its sorted vertices: its key across passes.
    key: [VertexId; 4],
    tet: TetId,
    /// The volume bound of its region, if any.
    volume_bound: Option<f64>,
}

/// Where the walk from a tet toward a point ends.
enum Walk {
    /// In a tet (or on its boundary) reached without crossing a subface.
    Inside(TetId),
    /// At this subface, which the point lies beyond.
    Wall([VertexId; 3]),
    /// At the hull, through a face that is no subface (the convex hull is kept).
    Hull,
}

/// A constraint a point encroaches upon.
#[derive(Clone, Copy)]
enum Encroached {
    Subsegment(VertexId, VertexId),
    Subface([VertexId; 3]),
}

impl Cdt {
    /// Refines the CDT's domain to `params` in place (see the module docs); every tet
    /// of the domain then meets the bounds, except the ones counted as left.
    pub fn refine(&mut self, params: &RefineParameters) -> RefineResult {
        if !params.any() {
            return RefineResult::default();
        }
        let floor = self.insertion_floor(params);
        self.refused_splits = Some(FxHashSet::default());
        self.keep_boundary = params.keep_boundary;
        // The splits a cascade makes below the first one keep an eighth of the floor:
        // away from small angles each step of Shewchuk's chain (tet, subface,
        // subsegment, its shell) shrinks the insertion radius by at most half, so
        // ordinary cascades stay above it, and a runaway one stops there.
        self.split_floor = floor / CASCADE_STEPS;
        let result = self.refine_passes(params, floor);
        self.refused_splits = None;
        self.keep_boundary = false;
        self.split_floor = 0.0;
        result
    }

    /// The passes of [`Cdt::refine`], with insertion floor `floor`.
    fn refine_passes(&mut self, params: &RefineParameters, floor: f64) -> RefineResult {
        let mut result = RefineResult::default();
        let mut left: FxHashSet<[VertexId; 4]> = FxHashSet::default();
        loop {
            result.passes += 1;
            let mut listed = self.bad_tets(params, &left).into_iter();
            // The bad tets around a new interior vertex are split next, before the pass
            // goes on down its list: most of a pass's tets are gone by the time the list
            // reaches them, and the tets that replaced them are these.
            let mut around: Vec<Bad> = Vec::new();
            let mut changed = false;
            while let Some(b) = around.pop().or_else(|| listed.next()) {
                let mesh = &self.tets.dt.mesh;
                // A tet an earlier split removed is judged again next pass.
                if !mesh.is_alive(b.tet) || sorted(mesh.verts(b.tet)) != b.key {
                    continue;
                }
                match self.split_bad_tet(b.tet, floor) {
                    Ok(Some((n, vertex))) => {
                        result.points += n;
                        changed = true;
                        if let Some(v) = vertex {
                            around.extend(self.bad_around(v, params, b.volume_bound, &left));
                        }
                    }
                    Ok(None) => {
                        left.insert(b.key);
                    }
                    Err(InsertError::Budget(_)) => {
                        result.budget_spent = true;
                        result.left = self.bad_tets(params, &FxHashSet::default()).len();
                        return result;
                    }
                    // The point could not go in here (the CDT is as valid as before):
                    // the tet is left.
                    Err(e) => {
                        if crate::constrained::debug() {
                            eprintln!("refine: tet {:?} left: {e}", b.key);
                        }
                        left.insert(b.key);
                    }
                }
            }
            if crate::constrained::debug() {
                eprintln!(
                    "refine: pass {} points {} left {}",
                    result.passes,
                    result.points,
                    left.len()
                );
            }
            if !changed {
                break;
            }
        }
        result.left = self.bad_tets(params, &FxHashSet::default()).len();
        result
    }

    /// The bad tets of the domain not in `left`, worst first.
    fn bad_tets(&mut self, params: &RefineParameters, left: &FxHashSet<[VertexId; 4]>) -> Vec<Bad> {
        let dom = crate::constrained::domain::domain(
            &mut self.tets,
            &self.plc.holes,
            &self.plc.regions,
            self.opts.keep_hull,
        );
        let mut bad = Vec::new();
        for (&t, &r) in dom.tets.iter().zip(&dom.regions) {
            let region_volume = (params.region_volumes && r != NO_REGION)
                .then(|| self.plc.regions[r as usize].max_volume)
                .filter(|&m| m > 0.0);
            let volume_bound = match (params.max_volume, region_volume) {
                (Some(a), Some(b)) => Some(a.min(b)),
                (a, b) => a.or(b),
            };
            bad.extend(self.judge(t, params, volume_bound, left));
        }
        bad.sort_by(|a, b| b.over.total_cmp(&a.over).then(a.key.cmp(&b.key)));
        bad
    }

    /// Tet `t` if it is bad (and not in `left`), with volume bound `volume_bound`.
    fn judge(
        &self,
        t: TetId,
        params: &RefineParameters,
        volume_bound: Option<f64>,
        left: &FxHashSet<[VertexId; 4]>,
    ) -> Option<Bad> {
        let p = self.corners(t);
        // How far over its bounds the tet is (1 and below: within them).
        let mut over = 0.0f64;
        if let Some(b) = params.max_ratio {
            over = over.max(quality::radius_edge_ratio(&p) / b);
        }
        if let Some(vb) = volume_bound {
            over = over.max(quality::volume(&p) / vb);
        }
        if let Some(a) = params.min_dihedral.filter(|&a| a > 0.0) {
            over = over.max(a / quality::dihedral_range(&p).0.max(1e-3));
        }
        let key = sorted(self.tets.dt.mesh.verts(t));
        (over > 1.0 && !left.contains(&key)).then_some(Bad {
            over,
            key,
            tet: t,
            volume_bound,
        })
    }

    /// The bad tets around vertex `v`, which went into a tet of the domain with volume
    /// bound `volume_bound`: none if a face around `v` is a subface (then its star
    /// may reach outside the domain or into another region), else its whole star, which
    /// lies in that tet's region (no subface separates its tets).
    fn bad_around(
        &mut self,
        v: VertexId,
        params: &RefineParameters,
        volume_bound: Option<f64>,
        left: &FxHashSet<[VertexId; 4]>,
    ) -> Vec<Bad> {
        let mut star = Vec::new();
        self.tets.dt.star(v, &mut star);
        let on_constraint = star.iter().any(|&t| {
            let w = self.tets.dt.mesh.verts(t);
            FACE_VERTS.iter().any(|fv| {
                let f = fv.map(|k| w[k]);
                f.contains(&v) && self.tets.subfaces.contains_key(&face_key(f))
            })
        });
        if on_constraint || star.iter().any(|&t| self.tets.is_ghost(t)) {
            return Vec::new();
        }
        star.iter()
            .filter_map(|&t| self.judge(t, params, volume_bound, left))
            .collect()
    }

    /// The distance below which no refinement point comes to a vertex: a quarter of the
    /// shortest edge of the domain's tets, or of the edge of a regular tet of the
    /// smallest volume bound if that is shorter. Halving is the most the insertion radii
    /// shrink along Shewchuk's chain away from small angles, and a vertex can lie nearer
    /// a facet than any of its edges are long: the second half. Only its being positive
    /// matters for termination (the packing bound of ARCHITECTURE.md).
    fn insertion_floor(&mut self, params: &RefineParameters) -> f64 {
        let dom = crate::constrained::domain::domain(
            &mut self.tets,
            &self.plc.holes,
            &self.plc.regions,
            self.opts.keep_hull,
        );
        let shortest = dom
            .tets
            .iter()
            .map(|&t| quality::shortest_edge(&self.corners(t)))
            .fold(f64::INFINITY, f64::min);
        let regions = self.plc.regions.iter().map(|r| r.max_volume);
        let smallest_volume = params
            .max_volume
            .into_iter()
            .chain(regions.filter(|_| params.region_volumes))
            .filter(|&v| v > 0.0)
            .fold(f64::INFINITY, f64::min);
        // A regular tet of edge a has volume a³ / (6√2).
        let edge_of_volume = (6.0 * 2f64.sqrt() * smallest_volume).cbrt();
        0.25 * shortest.min(edge_of_volume)
    }

    /// Splits bad tet `t` (see the module docs): the points added, with the vertex of
    /// its circumcentre if that went in itself; `None` if the tet is left.
    fn split_bad_tet(
        &mut self,
        t: TetId,
        floor: f64,
    ) -> Result<Option<(usize, Option<VertexId>)>, InsertError> {
        let p = self.corners(t);
        let Some(c) = quality::circumcenter(&p) else {
            return Ok(None);
        };
        let shortest = quality::shortest_edge(&p);
        // Half the shortest edge: a tet's circumradius is at least that, so a
        // circumcentre that encroaches upon nothing always goes in; a split point closer
        // to a vertex than that comes from a small input angle (Shewchuk's chain of
        // insertion radii shrinks by at most this factor elsewhere).
        let need = floor.max(0.5 * shortest);
        // The distance from `c` to the nearest vertex of its walled cavity: the tet's
        // circumradius where the CDT is Delaunay, less where a vertex hidden behind a
        // subface lies inside the circumsphere.
        let mut nearest = norm(&sub(&c, &p[0]));
        let target = match self.walk_toward(t, &c) {
            Walk::Hull => return Ok(None),
            Walk::Wall(f) => Some(Encroached::Subface(face_key(f))),
            Walk::Inside(at) => {
                self.tets.dt.start_walks_at(at);
                let (e, near) = self.encroached_by(&c);
                nearest = nearest.min(near);
                e
            }
        };
        let Some(e) = target else {
            if nearest < need {
                return Ok(None);
            }
            let before = self.added;
            let (v, _, _) = self.insert_vertex_id(c)?;
            return Ok(Some((self.added - before, Some(v))));
        };
        if self.keep_boundary {
            return Ok(None);
        }
        let m = match e {
            Encroached::Subsegment(a, b) => self.edge_split_point(a, b),
            Encroached::Subface(f) => {
                let [a, b, c] = f.map(|x| self.tets.dt.points[x as usize]);
                face_circumcenter(&a, &b, &c)
            }
        };
        if self.was_refused(&m) {
            return Err(InsertError::Refused(m));
        }
        let on = match e {
            Encroached::Subsegment(a, b) => super::split::On::Subsegment(a, b),
            Encroached::Subface(f) => super::split::On::Subface(f),
        };
        if self.insertion_radius(&m, on) < need {
            return Ok(None);
        }
        let n = match e {
            Encroached::Subsegment(a, b) => self.split_subsegment(a, b)?,
            Encroached::Subface(f) => self.split_subface(f)?,
        };
        Ok(Some((n, None)))
    }

    /// The corners of tet `t`.
    fn corners(&self, t: TetId) -> [Point; 4] {
        self.tets
            .dt
            .mesh
            .verts(t)
            .map(|x| self.tets.dt.points[x as usize])
    }

    /// Walks from tet `t` toward `c` through faces that are no subfaces.
    fn walk_toward(&self, mut t: TetId, c: &Point) -> Walk {
        let mesh = &self.tets.dt.mesh;
        let pt = |x: VertexId| &self.tets.dt.points[x as usize];
        let mut from = 4usize;
        // In a CDT a visibility walk can cycle; past a step per tet it is given up, and
        // the point is treated as beyond the tet's hull side (the tet is left).
        let bound = mesh.num_slots() + 16;
        for step in 0..bound {
            let mut next = None;
            for r in 0..4 {
                let i = (step + r) & 3;
                if i == from {
                    continue;
                }
                let f = mesh.face_verts(t, i);
                if orient3d(pt(f[0]), pt(f[1]), pt(f[2]), c) < 0.0 {
                    next = Some((i, f));
                    break;
                }
            }
            let Some((i, f)) = next else {
                return Walk::Inside(t);
            };
            if self.tets.subfaces.contains_key(&face_key(f)) {
                return Walk::Wall(f);
            }
            let n = mesh.adj(FaceRef::new(t, i));
            if mesh.is_ghost(n.tet()) {
                return Walk::Hull;
            }
            t = n.tet();
            from = n.face();
        }
        Walk::Hull
    }

    /// The constraint of point `c`'s walled cavity that `c` encroaches upon, if any: a
    /// subsegment first (the one with the lowest key), then a subface; and the distance
    /// from `c` to the cavity's nearest vertex.
    fn encroached_by(&mut self, c: &Point) -> (Option<Encroached>, f64) {
        let pert = self.next_pert;
        let found = super::split::encroached_constraints(&mut self.tets, c, pert, None, true);
        let e = found
            .seg
            .map(|(a, b)| Encroached::Subsegment(a, b))
            .or(found.face.map(Encroached::Subface));
        (e, found.nearest)
    }

    /// The distance from split point `m`, on constraint `on`, to the nearest vertex of
    /// its cavity walled in by the other subfaces (both sides of `on` count): the length
    /// of the shortest edge its insertion would make.
    fn insertion_radius(&mut self, m: &Point, on: super::split::On) -> f64 {
        let pert = self.next_pert;
        super::split::encroached_constraints(&mut self.tets, m, pert, Some(on), false).nearest
    }
}

/// How much further than the insertion floor a cascade of splits may go: three halvings.
const CASCADE_STEPS: f64 = 8.0;

/// The vertices of a tet, sorted: its key across passes.
fn sorted(mut v: [VertexId; 4]) -> [VertexId; 4] {
    v.sort_unstable();
    v
}
