//! Polygons into a live CDT ([`Cdt::insert_polygon`]): the corners go in as vertices,
//! each edge is recovered as a chain of subsegments (pieces that are no mesh edge are
//! split, at their middles or on power-of-two shells around a corner, until every piece
//! is one), and the polygon's triangulation in its plane is recovered by facet insertion
//! (cavity retriangulation or flips, as the options say), with the Steiner points and
//! subsegment splits that asks for made in place. All of it, or nothing: a polygon that
//! fails leaves the CDT as it was.

use super::{Cdt, InsertError, Tets};
use crate::constrained::cavity::Outcome;
use crate::constrained::cdt::{edge_key, face_key};
use crate::constrained::regions_of;
use crate::geom::facet2d;
use crate::geom::polygon::{newell_normal, Projection};
use crate::geom::Point;
use crate::mesh::VertexId;
use crate::plc::prepare::MergedFacet;
use crate::plc::{Facet, Plc};
use rustc_hash::{FxHashMap, FxHashSet};

/// Why [`Cdt::insert_polygon`] left a polygon out; the CDT is then as it was.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PolygonError {
    /// Fewer than three distinct corners, corners all on one line, or a coordinate that
    /// is not finite.
    #[error("the polygon is degenerate: {0}")]
    Degenerate(String),
    /// With the polygon the PLC is no longer valid (it crosses a facet or a segment,
    /// repeats one, …): the input checks' message.
    #[error("the polygon makes the PLC invalid: {0}")]
    Invalid(String),
    /// A corner, or a point that splits an edge or the polygon, could not go in.
    #[error(transparent)]
    Vertex(#[from] InsertError),
    /// The polygon's triangulation could not be recovered in place.
    #[error("the polygon could not be recovered: {0}")]
    NotRecovered(String),
}

/// What [`Cdt::insert_polygon`] did.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PolygonInserted {
    /// The node index of each corner (0-based; the files add the first index).
    pub corners: Vec<usize>,
    /// The subfaces that cover the polygon.
    pub subfaces: usize,
    /// Steiner points added for it: corners that were no node, points on its edges and
    /// on it, and splits of other constraints.
    pub added: usize,
}

/// What is restored when a polygon fails.
struct Saved {
    tets: Tets,
    next_pert: u32,
    added: usize,
    corners: FxHashSet<VertexId>,
    facets: usize,
}

impl Cdt {
    /// Inserts the polygon with corners `ring` (in order around it; nearly flat) and
    /// boundary marker `marker` as a new facet: its corners and edges become vertices and
    /// chains of subsegments, and its triangulation subfaces. All or nothing.
    pub fn insert_polygon(
        &mut self,
        ring: &[Point],
        marker: i32,
    ) -> Result<PolygonInserted, PolygonError> {
        let saved = Saved {
            tets: self.tets.clone(),
            next_pert: self.next_pert,
            added: self.added,
            corners: self.corners.clone(),
            facets: self.meshed.facets.len(),
        };
        self.split_log = Some(Vec::new());
        let done = self.try_insert_polygon(ring, marker);
        self.split_log = None;
        if done.is_err() {
            self.tets = saved.tets;
            self.next_pert = saved.next_pert;
            self.added = saved.added;
            self.corners = saved.corners;
            self.meshed.facets.truncate(saved.facets);
        }
        done.map(|mut d| {
            d.added = self.added - saved.added;
            d
        })
    }

    fn try_insert_polygon(
        &mut self,
        ring: &[Point],
        marker: i32,
    ) -> Result<PolygonInserted, PolygonError> {
        let ring = clean_ring(ring)?;
        let (judged, normal) = self.judged_with(&ring, marker)?;
        let mut corners = Vec::with_capacity(ring.len());
        for &p in &ring {
            let (v, _, _) = self.insert_vertex_id(p)?;
            self.corners.insert(v);
            corners.push(v);
        }
        let fi = self.meshed.facets.len() as u32;
        self.meshed.facets.push(MergedFacet {
            marker,
            source_facets: vec![judged.0.facets.len() - 1],
            normal,
            ..Default::default()
        });
        let edges: Vec<(VertexId, VertexId)> = (0..corners.len())
            .map(|i| (corners[i], corners[(i + 1) % corners.len()]))
            .collect();
        for &(a, b) in &edges {
            self.recover_edge(a, b, marker)?;
        }
        self.recover_polygon(fi, &edges, normal)?;
        // A polygon in the exterior or a hole would be carved away with it.
        if let Err(e) = self.mesh() {
            return Err(PolygonError::Invalid(e.to_string()));
        }
        self.judged = judged;
        self.facet_index = Default::default();
        let subfaces = self.tets.subfaces.values().filter(|&&f| f == fi).count();
        Ok(PolygonInserted {
            corners: corners
                .iter()
                .map(|&v| self.tets.dt.orig[v as usize] as usize)
                .collect(),
            subfaces,
            added: 0,
        })
    }

    /// The judged PLC with the polygon `ring` added as a facet (its corners appended as
    /// points), checked as an input is and prepared; and the polygon's normal.
    fn judged_with(
        &self,
        ring: &[Point],
        marker: i32,
    ) -> Result<((Plc, crate::plc::prepare::PreparedPlc), Point), PolygonError> {
        let invalid = |e: &dyn std::fmt::Display| PolygonError::Invalid(e.to_string());
        let mut plc = self.judged.0.clone();
        let first = plc.points.len() as u32;
        plc.points.extend_from_slice(ring);
        let attrs = plc.num_point_attrs * ring.len();
        plc.point_attrs.extend(std::iter::repeat_n(0.0, attrs));
        if let Some(m) = &mut plc.point_markers {
            m.extend(std::iter::repeat_n(0, ring.len()));
        }
        let poly: Vec<u32> = (first..first + ring.len() as u32).collect();
        let normal = newell_normal(&plc.points, &poly);
        plc.facets.push(Facet {
            polygons: vec![poly],
            holes: Vec::new(),
            marker,
            line: 0,
        });
        let rep = crate::precheck::check_elements(&plc).map_err(|e| invalid(&e))?;
        crate::precheck::check_surface(&plc, &rep).map_err(|e| invalid(&e))?;
        let prep = crate::plc::prepare::prepare(&plc, self.opts.merge).map_err(|e| invalid(&e))?;
        Ok(((plc, prep), normal))
    }

    /// Recovers edge `a`–`b` as a chain of subsegments with `marker`: a piece that is a
    /// mesh edge becomes a subsegment at once (later points then treat it as one), a
    /// piece that is none is split. Every split point lies inside the piece's diametral
    /// ball, away from its ends by a third of it at least, and a piece whose ball holds
    /// no vertex is a mesh edge: the splits end as segment recovery's do (ARCHITECTURE.md);
    /// [`Cdt::split_bound`] bounds them.
    fn recover_edge(&mut self, a: VertexId, b: VertexId, marker: i32) -> Result<(), PolygonError> {
        let bound = self.split_bound();
        let mut splits = 0;
        let mut stack = vec![(a, b)];
        while let Some((u, v)) = stack.pop() {
            let e = edge_key(u, v);
            if self.tets.subsegs.contains_key(&e) {
                continue;
            }
            if let Some(w) = self.logged_split(e) {
                stack.extend([(u, w), (w, v)]);
                continue;
            }
            if self.tets.has_edge(u, v) {
                self.tets.subsegs.insert(e, marker);
                continue;
            }
            splits += 1;
            if splits > bound {
                let point = self.tets.dt.points[u as usize];
                return Err(InsertError::TooManySplits { point, bound }.into());
            }
            let m = self.edge_split_point(u, v);
            let (w, _, _) = self.insert_vertex_id(m)?;
            if w == u || w == v {
                return Err(PolygonError::NotRecovered(format!(
                    "an edge piece is too short to split at {m:?}"
                )));
            }
            if let Some(log) = &mut self.split_log {
                log.push((e, w));
            }
            stack.extend([(u, w), (w, v)]);
        }
        Ok(())
    }

    /// The vertex that split subsegment `e` while this polygon went in, if any.
    fn logged_split(&self, e: (VertexId, VertexId)) -> Option<VertexId> {
        let log = self.split_log.as_ref()?;
        log.iter().rev().find(|&&(x, _)| x == e).map(|&(_, w)| w)
    }

    /// The subsegments that edge `a`–`b` is now made of.
    fn chain(
        &self,
        a: VertexId,
        b: VertexId,
        out: &mut Vec<[VertexId; 2]>,
    ) -> Result<(), PolygonError> {
        let mut stack = vec![(a, b)];
        while let Some((u, v)) = stack.pop() {
            if self.tets.subsegs.contains_key(&edge_key(u, v)) {
                out.push([u, v]);
            } else if let Some(w) = self.logged_split(edge_key(u, v)) {
                stack.extend([(w, v), (u, w)]);
            } else {
                return Err(PolygonError::NotRecovered(format!(
                    "a piece of an edge, {:?} to {:?}, is no subsegment",
                    self.tets.dt.points[u as usize], self.tets.dt.points[v as usize]
                )));
            }
        }
        Ok(())
    }

    /// Recovers the triangulation of polygon `fi` (edges `edges`, recovered) in its
    /// plane. Each round triangulates it with the vertices it has now, keeps the
    /// triangles that are faces, and inserts the missing regions; a region that asks for
    /// a Steiner point or a subsegment split gets it in place, and the round is done
    /// again. Each round but the last adds a point, so [`Cdt::split_bound`] bounds them.
    fn recover_polygon(
        &mut self,
        fi: u32,
        edges: &[(VertexId, VertexId)],
        normal: Point,
    ) -> Result<(), PolygonError> {
        let not_recovered = |e: &dyn std::fmt::Display| PolygonError::NotRecovered(e.to_string());
        let bound = self.split_bound();
        // Vertices put in on the polygon for its recovery.
        let mut on_it: Vec<VertexId> = Vec::new();
        for round in 0.. {
            if round > bound {
                return Err(not_recovered(&format!("more than {bound} rounds")));
            }
            let mut cons = Vec::new();
            for &(a, b) in edges {
                self.chain(a, b, &mut cons)?;
            }
            let mut verts: Vec<VertexId> = cons.iter().flatten().copied().collect();
            verts.extend_from_slice(&on_it);
            let tris = facet2d::triangulate_facet(
                &self.tets.dt.points,
                &self.tets.dt.orig,
                &verts,
                &cons,
                &[],
                normal,
            )
            .map_err(|e| not_recovered(&e))?;
            // Subfaces of an earlier round that this triangulation lacks are taken out:
            // the regions that cover their place delete them.
            let keys: FxHashSet<[VertexId; 3]> = tris.iter().map(|&t| face_key(t)).collect();
            self.tets
                .subfaces
                .retain(|k, f| *f != fi || keys.contains(k));
            let missing = self.tets.keep_present(&tris, fi);
            if missing.is_empty() {
                // A flat tet with four vertices on the polygon (its corners and split
                // points are not exactly coplanar) is a shim: the paper's remedy, a
                // Steiner point on the polygon, goes in by splitting a subface of it.
                let Some(g) = self.shim_subface(fi, &verts) else {
                    return Ok(());
                };
                let before = self.tets.dt.points.len() as VertexId;
                self.split_subface(g)?;
                let new_on_it: FxHashSet<VertexId> = self
                    .tets
                    .subfaces
                    .iter()
                    .filter(|&(_, &f)| f == fi)
                    .flat_map(|(k, _)| *k)
                    .filter(|&x| x >= before)
                    .collect();
                on_it.extend(new_on_it);
                continue;
            }
            let mut point = None;
            for region in regions_of(&missing, &self.tets.subsegs) {
                match self.insert_region(&region, fi, normal)? {
                    Outcome::Inserted(rs) => self.recover_lost(rs.lost)?,
                    Outcome::NeedsSteiner(p) => {
                        point = Some(p);
                        break;
                    }
                    Outcome::SplitSubsegment(u, v) => {
                        self.split_subsegment(u, v)?;
                        break;
                    }
                }
            }
            if let Some(p) = point {
                let (v, _, _) = self.insert_vertex_id(p)?;
                on_it.push(v);
            }
        }
        unreachable!("the rounds are bounded")
    }

    /// A subface of polygon `fi` on a tet whose four vertices are among the polygon's
    /// `verts`, if there is one.
    fn shim_subface(&mut self, fi: u32, verts: &[VertexId]) -> Option<[VertexId; 3]> {
        let on: FxHashSet<VertexId> = verts.iter().copied().collect();
        let mut star = Vec::new();
        for &v in verts {
            self.tets.dt.star(v, &mut star);
            for &t in &star {
                let tv = self.tets.dt.mesh.verts(t);
                if !tv.iter().all(|x| on.contains(x)) {
                    continue;
                }
                let face = crate::mesh::FACE_VERTS
                    .iter()
                    .map(|fv| face_key(fv.map(|k| tv[k])))
                    .find(|k| self.tets.subfaces.get(k) == Some(&fi));
                if face.is_some() {
                    return face;
                }
            }
        }
        None
    }

    /// Inserts region `tris` of facet `fi` with the configured algorithm.
    fn insert_region(
        &mut self,
        tris: &[[VertexId; 3]],
        fi: u32,
        normal: Point,
    ) -> Result<Outcome, PolygonError> {
        self.opts
            .inserter
            .insert(&mut self.tets, tris, fi, normal, &mut self.stats.flips)
            .map_err(|e| PolygonError::NotRecovered(e.to_string()))
    }

    /// Inserts again the subfaces of other facets that a region's retriangulation
    /// destroyed, facet by facet; they must go back without Steiner points.
    fn recover_lost(&mut self, lost: Vec<([VertexId; 3], u32)>) -> Result<(), PolygonError> {
        let mut by_facet: FxHashMap<u32, Vec<[VertexId; 3]>> = FxHashMap::default();
        for (k, f) in lost {
            by_facet.entry(f).or_default().push(k);
        }
        let mut facets: Vec<_> = by_facet.into_iter().collect();
        facets.sort_unstable();
        for (g, keys) in facets {
            let normal = self.meshed.facets[g as usize].normal;
            let proj = Projection::along(&normal);
            let pts = &self.tets.dt.points;
            let tris: Vec<[VertexId; 3]> = keys
                .into_iter()
                .map(|[a, b, c]| {
                    let ccw = proj.orient(&pts[a as usize], &pts[b as usize], &pts[c as usize]);
                    if ccw > 0.0 {
                        [a, b, c]
                    } else {
                        [a, c, b]
                    }
                })
                .collect();
            let missing = self.tets.keep_present(&tris, g);
            for region in regions_of(&missing, &self.tets.subsegs) {
                match self.insert_region(&region, g, normal)? {
                    Outcome::Inserted(rs) if rs.lost.is_empty() => {}
                    _ => {
                        return Err(PolygonError::NotRecovered(format!(
                            "subfaces of facet {g} that it displaced do not go back in place"
                        )))
                    }
                }
            }
        }
        Ok(())
    }
}

/// The ring's corners with consecutive repeats (and a closing repeat) dropped, checked.
fn clean_ring(ring: &[Point]) -> Result<Vec<Point>, PolygonError> {
    if let Some(p) = ring.iter().find(|p| !p.iter().all(|c| c.is_finite())) {
        return Err(PolygonError::Degenerate(format!(
            "the corner {p:?} is not finite"
        )));
    }
    let mut out: Vec<Point> = Vec::with_capacity(ring.len());
    for &p in ring {
        if out.last() != Some(&p) {
            out.push(p);
        }
    }
    while out.len() > 1 && out.first() == out.last() {
        out.pop();
    }
    if out.len() < 3 {
        return Err(PolygonError::Degenerate(format!(
            "{} distinct corners; three at least are needed",
            out.len()
        )));
    }
    let idx: Vec<u32> = (0..out.len() as u32).collect();
    if crate::geom::polygon::all_collinear(&out, &idx) {
        return Err(PolygonError::Degenerate(
            "its corners lie on one line".into(),
        ));
    }
    Ok(out)
}
