//! A live constrained Delaunay tetrahedralization: built once from a PLC, then changed
//! in place, one vertex at a time, each insertion leaving a CDT of the PLC with its
//! Steiner points (every face that is no subface locally Delaunay under the
//! perturbation, every constraint a union of subsegments and subfaces).
//!
//! See the crate docs for an example, and `examples/incremental.rs`.
//!
//! [`Cdt::insert_vertex`] places a point by where it lands:
//! - on a vertex: nothing changes;
//! - exactly on a subsegment, or exactly on a subface: the constraint is split there,
//!   its pieces keeping its marker and facet (`split.rs`);
//! - elsewhere: a cavity walled in by the subfaces, then flips to local Delaunayhood.
//!
//! A point inside the diametral ball of a subsegment of its cavity encroaches upon it:
//! the subsegment is split first (at its middle, or on a power-of-two shell around an
//! input vertex), and the point tried again. A point whose walled cavity would remove a
//! subsegment, or wrap around a subface, gets that constraint split first too. The
//! splits are queue-driven; ARCHITECTURE.md gives why they end.
//!
//! [`Cdt::insert_polygon`] adds a polygon as a new facet, all or nothing (`polygon.rs`).

mod polygon;
mod refine;
mod split;
#[cfg(test)]
mod tests;

use crate::check::{Certificate, CertifyOptions, MeshView};
use crate::constrained::cdt::Cdt as Tets;
use crate::constrained::free;
use crate::constrained::{PlcOptions, PlcStats};
use crate::delaunay::Location;
use crate::error::{Error, MeshError};
use crate::geom::Point;
use crate::mesh::VertexId;
use crate::output::MeshOut;
use crate::plc::prepare::PreparedPlc;
use crate::plc::Plc;

pub use polygon::{PolygonError, PolygonInserted};
pub use refine::{RefineParameters, RefineResult};

/// Why [`Cdt::insert_vertex`] left a point out (the CDT is then as it was before the
/// point's own insertion, with any splits made for it kept: they are valid).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum InsertError {
    /// A coordinate is infinite or NaN.
    #[error("the point {0:?} is not finite")]
    NotFinite(Point),
    /// The point lies outside the convex hull of the vertices.
    #[error("the point {0:?} lies outside the convex hull of the vertices")]
    OutsideHull(Point),
    /// The splits it needed went past their bound (see ARCHITECTURE.md).
    #[error("the point {point:?} needed more than {bound} constraint splits")]
    TooManySplits {
        /// The point.
        point: Point,
        /// The bound.
        bound: usize,
    },
    /// The Steiner point budget (`-S`) is spent.
    #[error("the Steiner point budget of {0} is spent")]
    Budget(usize),
    /// No cavity of the point is seen whole from it, and no split made one: a bug or a
    /// configuration the splits do not cover.
    #[error("the point {0:?} fits no cavity of the CDT")]
    Refused(Point),
    /// While refining: the split would put a point nearer a vertex than the insertion
    /// floor.
    #[error("the split point {point:?} would come within {floor} of a vertex")]
    TooClose {
        /// The split point.
        point: Point,
        /// The insertion floor.
        floor: f64,
    },
    /// The point needs a split of a subsegment or subface, and the boundary is kept
    /// (`-Y`).
    #[error("the point {0:?} needs a split of the boundary, which is kept")]
    BoundaryKept(Point),
}

/// What [`Cdt::insert_vertex`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Inserted {
    /// The point's node index (0-based; the files add the first index).
    pub node: usize,
    /// False if the point coincided with a node already there.
    pub new: bool,
    /// Constraint splits made first (each adds one Steiner point).
    pub splits: usize,
}

/// A constrained Delaunay tetrahedralization of a PLC, kept live for insertions. The
/// exterior is carved only when a mesh is taken out ([`Cdt::mesh`]).
pub struct Cdt {
    /// The PLC as given to [`Cdt::build`]: its points are the first output nodes, its
    /// holes and regions carve the mesh.
    plc: Plc,
    opts: PlcOptions,
    /// The facets the subfaces name (by index), with the polygons inserted since.
    meshed: PreparedPlc,
    /// The PLC with the polygons inserted since (their vertices appended as points),
    /// which certification judges against, and its preparation.
    judged: (Plc, PreparedPlc),
    /// The judged facets' slabs and which facets each input vertex is on, for the shim
    /// test after each insertion: made when first needed, again after a polygon goes in.
    facet_index: std::cell::OnceCell<crate::constrained::slivers::FacetIndex>,
    /// Vertices treated as input vertices when a subsegment is split: those of the PLC,
    /// and the corners of inserted polygons (the power-of-two shells protect the angles
    /// at both).
    corners: rustc_hash::FxHashSet<VertexId>,
    /// While a polygon goes in: each split of a subsegment or of a piece of its edges,
    /// with the split vertex, so that its edges can be followed as chains of subsegments.
    split_log: Option<Vec<((VertexId, VertexId), VertexId)>>,
    tets: Tets,
    stats: PlcStats,
    warnings: Vec<String>,
    /// Points this close to a subsegment or subface lie on it: the certifier's thinnest
    /// slab of a facet (1e-10 of the model's diagonal), which rounding puts points
    /// computed on a facet within.
    near: f64,
    /// The next perturbation (and node) index: above every one in use.
    next_pert: u32,
    /// Steiner points added by insertions.
    added: usize,
    /// While refining: the split points the CDT refused, which are not tried again
    /// (many bad tets lead to the same split, through the constraints they encroach
    /// upon, and the CDT around it rarely changes in between).
    refused_splits: Option<rustc_hash::FxHashSet<[u64; 3]>>,
    /// While refining under `-Y`: no subsegment or subface may be split.
    keep_boundary: bool,
    /// While refining: no split point may come nearer a vertex than this (0 otherwise).
    split_floor: f64,
}

impl Cdt {
    /// The CDT of `plc` (read → Delaunay → segments → facets), not carved.
    pub fn build(plc: &Plc, opts: &PlcOptions) -> Result<Cdt, Error> {
        let elements = crate::precheck::check_elements(plc)?;
        crate::precheck::check_surface(plc, &elements)?;
        let c = crate::constrained::construct(plc, opts, &crate::progress::no_progress)?;
        Ok(Cdt::of_construction(plc, opts, c))
    }

    /// The live CDT of a finished construction of `plc`.
    pub(crate) fn of_construction(
        plc: &Plc,
        opts: &PlcOptions,
        c: crate::constrained::Constructed,
    ) -> Cdt {
        let built = *c.built;
        let mut tets = built.cdt;
        tets.subsegs = built.seg_markers;
        let next_pert = tets.dt.orig.iter().map(|&o| o + 1).max().unwrap_or(0);
        let next_pert = next_pert.max(plc.points.len() as u32);
        Cdt {
            plc: plc.clone(),
            opts: opts.clone(),
            meshed: c.split.unwrap_or_else(|| c.base.clone()),
            judged: (plc.clone(), c.base),
            facet_index: Default::default(),
            corners: Default::default(),
            split_log: None,
            near: 1e-10 * crate::geom::diagonal(&plc.points),
            tets,
            stats: c.stats,
            warnings: c.warnings,
            next_pert,
            added: 0,
            refused_splits: None,
            keep_boundary: false,
            split_floor: 0.0,
        }
    }

    /// Warnings from building it.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// The figures of its construction.
    pub fn stats(&self) -> &PlcStats {
        &self.stats
    }

    /// The number of vertices (input points meshed, and Steiner points).
    pub fn num_vertices(&self) -> usize {
        self.tets.dt.points.len()
    }

    /// The number of tets, the exterior not yet carved.
    pub fn num_tets(&self) -> usize {
        self.tets.num_tets()
    }

    /// The number of subsegments and of subfaces.
    pub fn num_constraints(&self) -> (usize, usize) {
        (self.tets.subsegs.len(), self.tets.subfaces.len())
    }

    /// Steiner points added by insertions so far (the inserted points and their splits).
    pub fn added_points(&self) -> usize {
        self.added
    }

    /// The mesh, carved, in output form.
    pub fn mesh(&self) -> Result<MeshOut, Error> {
        let mut stats = self.stats.clone();
        crate::carve::carve_copy(&self.plc, &self.meshed, &self.tets, &self.opts, &mut stats)
    }

    /// The mesh, carved, in output form, with the PLC as prepared for meshing (which
    /// the certifier judges it against) and the figures: the end of the pipeline.
    pub(crate) fn into_mesh(
        self,
        progress: crate::progress::Progress<'_>,
    ) -> Result<(MeshOut, PreparedPlc, PlcStats, Vec<String>), Error> {
        let mut stats = self.stats;
        stats.steiner_points += self.added;
        let subsegs = self.tets.subsegs.clone();
        let built = crate::constrained::construction::Built::of(self.tets, subsegs);
        let mesh = crate::carve::carve(
            &self.plc,
            &self.meshed,
            built,
            &self.opts,
            &mut stats,
            progress,
        )?;
        Ok((mesh, self.judged.1, stats, self.warnings))
    }

    /// Certifies the carved mesh as a CDT of the PLC ([`crate::check`]).
    pub fn certify(&self) -> Result<Certificate, Error> {
        let mesh = self.mesh()?;
        let view = MeshView {
            points: &mesh.points,
            tets: &mesh.tets,
            first_index: mesh.first_index,
        };
        let opts = CertifyOptions {
            keep_hull: self.opts.keep_hull,
            merge: self.opts.merge,
        };
        let (plc, prep) = &self.judged;
        crate::check::certify_prepared(plc, Some(prep), view, &opts)
            .map_err(|f| MeshError::NotCertified(f).into())
    }

    /// Inserts point `p`, splitting the constraints it lands on or encroaches upon.
    pub fn insert_vertex(&mut self, p: Point) -> Result<Inserted, InsertError> {
        let (v, new, splits) = self.insert_vertex_id(p)?;
        Ok(Inserted {
            node: self.tets.dt.orig[v as usize] as usize,
            new,
            splits,
        })
    }

    /// [`Cdt::insert_vertex`] by vertex id: the vertex, whether it is new, and the
    /// splits made first.
    fn insert_vertex_id(&mut self, p: Point) -> Result<(VertexId, bool, usize), InsertError> {
        if !p.iter().all(|c| c.is_finite()) {
            return Err(InsertError::NotFinite(p));
        }
        let bound = self.split_bound();
        let mut splits = 0;
        // Vertices from here on are new: `p` itself may go in as a split point (of the
        // constraint it lies on, or of one it encroaches upon whose split point it is).
        let before = self.tets.dt.points.len();
        loop {
            let found = match self.tets.dt.locate_anywhere(&p) {
                Location::Vertex(v) => {
                    let new = v as usize >= before;
                    return Ok((v, new, splits - new as usize));
                }
                Location::Outside(_) => return Err(InsertError::OutsideHull(p)),
                Location::Inside(t) => t,
            };
            self.check_budget()?;
            let on = split::on_constraint(&self.tets, found, &p, self.near);
            let step = match on {
                Some(split::On::Subsegment(a, b)) => self.split_subsegment_at(a, b, p)?,
                Some(split::On::Subface(f)) => self.split_subface_at(f, p)?,
                None => match split::encroached(self, &p) {
                    Some((a, b)) => Step::Split(self.split_subsegment(a, b)?),
                    None => self.insert_free(p)?,
                },
            };
            match step {
                Step::Done(v) => return Ok((v, true, splits)),
                Step::Split(n) => {
                    splits += n;
                    if splits > bound {
                        return Err(InsertError::TooManySplits { point: p, bound });
                    }
                }
            }
        }
    }

    /// The most splits one insertion may make: every split adds a vertex inside a
    /// constraint whose pieces stay at least a fixed fraction of the local feature size
    /// (ARCHITECTURE.md), so a cascade longer than a multiple of the constraints and
    /// vertices there are means that argument's premises failed.
    fn split_bound(&self) -> usize {
        let (s, f) = self.num_constraints();
        4 * (s + f + self.num_vertices()) + 64
    }

    /// Sets the most Steiner points the CDT may have, those of its construction
    /// included (`-S`).
    pub fn set_steiner_budget(&mut self, n: usize) {
        self.opts.max_steiner = n;
    }

    fn check_budget(&self) -> Result<(), InsertError> {
        let used = self.stats.steiner_points + self.added;
        if used >= self.opts.max_steiner {
            return Err(InsertError::Budget(self.opts.max_steiner));
        }
        Ok(())
    }

    /// A point that lands on no constraint and encroaches upon no subsegment: a walled
    /// cavity and flips; where the CDT refuses it, the constraint in the way is split.
    fn insert_free(&mut self, p: Point) -> Result<Step, InsertError> {
        let inserted = free::insert_point(&mut self.tets, p, self.next_pert, true)
            .map_err(|_| InsertError::Refused(p))?;
        match inserted {
            free::Inserted::Yes { vertex, .. } if self.breaks_facets(vertex) => {
                free::take_back(&mut self.tets, inserted);
                Err(InsertError::Refused(p))
            }
            free::Inserted::Yes { vertex, .. } if self.too_close(vertex) => {
                free::take_back(&mut self.tets, inserted);
                Err(InsertError::TooClose {
                    point: p,
                    floor: self.split_floor,
                })
            }
            free::Inserted::Yes { vertex, .. } => {
                self.next_pert += 1;
                self.added += 1;
                Ok(Step::Done(vertex))
            }
            free::Inserted::OnVertex => Err(InsertError::Refused(p)),
            free::Inserted::Refused {
                lost: Some((a, b)), ..
            } => Ok(Step::Split(self.split_subsegment(a, b)?)),
            free::Inserted::Refused {
                wrapped: Some(f), ..
            } => Ok(Step::Split(self.split_subface(f)?)),
            free::Inserted::Refused { .. } => Err(InsertError::Refused(p)),
        }
    }
}

/// One step of an insertion.
enum Step {
    /// The point is in, as this vertex.
    Done(VertexId),
    /// Constraints were split (this many points), and the point is tried again.
    Split(usize),
}
