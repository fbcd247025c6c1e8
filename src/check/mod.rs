//! The certifier behind `--certify` and `--check`: decides from a mesh's nodes and tets
//! alone, with exact predicates, whether it is a constrained Delaunay tetrahedralization
//! (with Steiner points) of a PLC, or the Delaunay tetrahedralization of a point set. It
//! reads nothing the mesher keeps (no list of subfaces or subsegments), so it judges any
//! mesh, TetGen's included.
//!
//! The checks:
//! * every tet is positively oriented, each face belongs to one or two tets, and two tets
//!   sharing a face lie on its two sides;
//! * the tets tile the domain: each face-connected part of the mesh has a point held by
//!   exactly one tet (with the checks above, the number of tets holding a point is the
//!   winding number of the boundary around it, constant over each part), and hole points
//!   and input points left out of the mesh lie in no tet;
//! * every input segment is a chain of mesh edges, every facet is covered exactly once
//!   by the faces on it and no face lies outside it, and no shim tet (a flat tet with all
//!   four nodes on one facet) survives (`facets.rs`);
//! * every face on no facet is locally Delaunay under TetGen's symbolic perturbation, by
//!   node number; the boundary lies on facets (with `-c`, on the convex hull).

mod facets;
mod locate;
mod topology;

use crate::error::InputError;
use crate::geom::{insphere_sos, orient3d, Point, Sign};
use crate::output::MeshOut;
use crate::plc::prepare::PreparedPlc;
use crate::plc::Plc;
use rayon::prelude::*;

/// Stop collecting after this many problems; the count of the rest is reported.
const MAX_REPORTED: usize = 20;

/// The problems found so far, and how the mesh and the input number their elements.
pub(crate) struct Problems {
    list: Vec<String>,
    more: usize,
    /// The number of the first node.
    base: usize,
    /// The number of the first input facet.
    facet_base: usize,
}

impl Problems {
    fn new(base: usize, facet_base: usize) -> Self {
        Problems {
            list: Vec::new(),
            more: 0,
            base,
            facet_base,
        }
    }

    fn push(&mut self, msg: String) {
        if self.list.len() < MAX_REPORTED {
            self.list.push(msg);
        } else {
            self.more += 1;
        }
    }

    fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// Takes in the problems `other` found.
    fn absorb(&mut self, other: Problems) {
        for p in other.list {
            self.push(p);
        }
        self.more += other.more;
    }

    fn finish(self) -> Result<(), CheckFailure> {
        if self.list.is_empty() {
            Ok(())
        } else {
            Err(CheckFailure {
                total: self.list.len() + self.more,
                listed: self.list,
            })
        }
    }
}

/// Node `v` as numbered in the mesh's files.
fn name(pr: &Problems, v: u32) -> usize {
    v as usize + pr.base
}

/// Nodes as numbered in the mesh's files.
fn names(pr: &Problems, t: &[u32]) -> Vec<usize> {
    t.iter().map(|&v| name(pr, v)).collect()
}

/// What a failed check found: the first problems, a line each, and how many there are.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CheckFailure {
    /// The first problems found, at most twenty.
    pub listed: Vec<String>,
    /// How many problems there are in all, listed or not.
    pub total: usize,
}

impl CheckFailure {
    /// The count of problems and the listed ones, one per indented line.
    pub fn report(&self) -> String {
        let mut msg = format!("{} problem(s):", self.total);
        for p in self.to_string().lines() {
            msg.push_str("\n  ");
            msg.push_str(p);
        }
        msg
    }
}

impl std::fmt::Display for CheckFailure {
    /// The listed problems, one per line, and a last line counting the others.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.listed.join("\n"))?;
        if self.total > self.listed.len() {
            write!(
                f,
                "\n... and {} more problems",
                self.total - self.listed.len()
            )?;
        }
        Ok(())
    }
}

/// Why a mesh could not be certified.
#[derive(Debug, thiserror::Error)]
pub enum CertifyError {
    /// The PLC itself is invalid, so no mesh is a CDT of it.
    #[error(transparent)]
    Input(#[from] InputError),
    /// The mesh is not a CDT of the PLC.
    #[error("{0}")]
    Failed(CheckFailure),
}

/// How the mesh was meant to be made, which changes what it must be.
#[derive(Clone, Copy, Debug)]
pub struct CertifyOptions {
    /// The exterior was kept (`-c`): the boundary lies on the convex hull, not only on
    /// polygons.
    pub keep_hull: bool,
    /// Coplanar neighbouring facets are merged (TetGen's default; `-M` keeps them apart):
    /// their common edges need not be meshed.
    pub merge: bool,
}

impl CertifyOptions {
    /// What the switches of a run say the mesh must be.
    pub fn of(opts: &crate::options::Options) -> Self {
        CertifyOptions {
            keep_hull: opts.keep_hull,
            merge: opts.merges_facets(),
        }
    }
}

impl Default for CertifyOptions {
    fn default() -> Self {
        CertifyOptions {
            keep_hull: false,
            merge: true,
        }
    }
}

/// What a certified mesh holds.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Certificate {
    /// Tets.
    pub tets: usize,
    /// Nodes that are no input point.
    pub steiner_points: usize,
    /// Faces on facets.
    pub subfaces: usize,
    /// Edges on segments.
    pub subsegments: usize,
}

/// A mesh to certify: its nodes and tets (0-based), and the number its files give the
/// first node (for messages).
#[derive(Clone, Copy, Debug)]
pub struct MeshView<'a> {
    /// Node coordinates.
    pub points: &'a [Point],
    /// Tets, as node indices, positively oriented in TetGen's sense.
    pub tets: &'a [[u32; 4]],
    /// The number of the first node in the files.
    pub first_index: usize,
}

/// Certifies `mesh` as a CDT of `plc` (of its points alone when it has no facets).
pub fn certify(
    plc: &Plc,
    mesh: MeshView<'_>,
    opts: &CertifyOptions,
) -> Result<Certificate, CertifyError> {
    let prep = if plc.facets.is_empty() {
        None
    } else {
        Some(crate::plc::prepare::prepare(plc, opts.merge)?)
    };
    certify_prepared(plc, prep.as_ref(), mesh, opts).map_err(CertifyError::Failed)
}

/// [`certify`] with the PLC already prepared (`None` for a point set).
pub fn certify_prepared(
    plc: &Plc,
    prep: Option<&PreparedPlc>,
    mesh: MeshView<'_>,
    opts: &CertifyOptions,
) -> Result<Certificate, CheckFailure> {
    let MeshView {
        points,
        tets,
        first_index,
    } = mesh;
    let mut pr = Problems::new(first_index, plc.first_index);
    let n = points.len();
    for (i, t) in tets.iter().enumerate() {
        let bad_index = t.iter().any(|&v| v as usize >= n);
        let repeated = (0..4).any(|a| (a + 1..4).any(|b| t[a] == t[b]));
        if bad_index || repeated {
            pr.push(format!(
                "tet {} has invalid nodes {:?}",
                i + first_index,
                t.iter()
                    .map(|&v| v as usize + first_index)
                    .collect::<Vec<_>>()
            ));
        }
    }
    if tets.is_empty() {
        pr.push("the mesh has no tets".into());
    }
    if !pr.is_empty() {
        return pr.finish().map(|()| Certificate::default());
    }
    let p = |v: u32| -> &Point { &points[v as usize] };
    let inverted: Vec<usize> = (0..tets.len())
        .into_par_iter()
        .filter(|&i| {
            let t = &tets[i];
            orient3d(p(t[0]), p(t[1]), p(t[2]), p(t[3])) <= 0.0
        })
        .collect();
    for i in inverted {
        pr.push(format!(
            "tet {} {:?} is not positively oriented",
            i + first_index,
            names(&pr, &tets[i])
        ));
    }
    let stars = facets::Rows::stars(n, tets);
    let topo = topology::Topology::build(tets, &stars, n, &mut pr);
    let same_side: Vec<(u32, u32)> = topo
        .pairs()
        .filter(|&(a, b)| {
            let (ta, fa) = topology::split(a);
            let (tb, fb) = topology::split(b);
            let f = topology::oriented_face(&tets[ta], fa);
            orient3d(p(f[0]), p(f[1]), p(f[2]), p(tets[tb][fb])) >= 0.0
        })
        .collect();
    for (a, b) in same_side {
        pr.push(format!(
            "tets {} and {} lie on the same side of their face {:?}",
            (a >> 2) as usize + first_index,
            (b >> 2) as usize + first_index,
            names(&pr, &topology::key(tets, a))
        ));
    }
    let node = facets::nodes_of_inputs(&plc.points, points);
    let mut cert = Certificate {
        tets: tets.len(),
        steiner_points: n - {
            let mut v: Vec<u32> = node.iter().copied().filter(|&x| x != u32::MAX).collect();
            v.sort_unstable();
            v.dedup();
            v.len()
        },
        ..Default::default()
    };
    // The constraints on one core; the local Delaunay tests of every face and the
    // tiling on the other (faces on facets are exempted afterwards).
    let mut other = Problems::new(first_index, plc.first_index);
    let (found, not_delaunay) = rayon::join(
        || {
            prep.map(|prep| {
                missing_vertices(plc, prep, &node, &mut pr);
                let keys: Vec<[u32; 3]> = topo
                    .boundary
                    .iter()
                    .map(|&s| topology::key(tets, s))
                    .chain(
                        topo.pairs()
                            .map(|(s, _)| topology::key(tets, s))
                            .collect::<Vec<_>>(),
                    )
                    .collect();
                facets::find(
                    prep,
                    &node,
                    points,
                    tets,
                    &stars,
                    &keys,
                    plc.points.len(),
                    &mut pr,
                )
            })
        },
        || {
            let bad: Vec<(u32, u32)> = topo
                .pairs()
                .filter(|&(a, b)| !is_delaunay(points, tets, a, b))
                .collect();
            check_tiling(points, tets, &topo, &mut other);
            bad
        },
    );
    pr.absorb(other);
    let mut locator = locate::Locator::new(points, tets);
    let subfaces = match (prep, &found) {
        (Some(prep), Some(found)) => {
            uncovered_facets(prep, found, &mut locator, &mut pr);
            cert.subfaces = found.subfaces.len();
            cert.subsegments = found.chains.iter().map(|c| c.len().saturating_sub(1)).sum();
            Some(&found.subfaces)
        }
        _ => {
            unused_points(plc, &node, points, tets, &mut pr);
            None
        }
    };
    let on_facet = |k: &[u32; 3]| subfaces.is_some_and(|s| s.contains_key(k));
    for (a, b) in not_delaunay {
        let k = topology::key(tets, a);
        if !on_facet(&k) {
            pr.push(format!(
                "face {:?} between tets {} and {} lies on no facet and is not locally Delaunay",
                names(&pr, &k),
                (a >> 2) as usize + first_index,
                (b >> 2) as usize + first_index
            ));
        }
    }
    check_boundary(tets, &topo.boundary, &mut pr);
    let hull_only = prep.is_none() || opts.keep_hull;
    for &s in &topo.boundary {
        let k = topology::key(tets, s);
        if !on_facet(&k) && !hull_only {
            pr.push(format!(
                "boundary face {:?} lies on no facet",
                names(&pr, &k)
            ));
        }
    }
    if hull_only {
        check_hull(points, tets, &topo.boundary, on_facet, &mut pr);
    }
    if prep.is_some() {
        points_outside(plc, &node, points, tets, &mut locator, &mut pr);
    }
    pr.finish()?;
    Ok(cert)
}

/// Whether the face between slots `a` and `b` is locally Delaunay: `b`'s other node
/// outside `a`'s tet's circumsphere, ties broken by the symbolic perturbation by node
/// number.
fn is_delaunay(points: &[Point], tets: &[[u32; 4]], a: u32, b: u32) -> bool {
    let (ta, _) = topology::split(a);
    let (tb, fb) = topology::split(b);
    let t = tets[ta];
    let q = [t[0], t[1], t[2], t[3], tets[tb][fb]];
    insphere_sos(q.map(|v| &points[v as usize]), q) == Sign::Negative
}

/// The boundary must be a closed surface: every edge of the boundary faces in as many
/// of them seen one way as the other (two solids may touch along an edge).
fn check_boundary(tets: &[[u32; 4]], boundary: &[u32], pr: &mut Problems) {
    let mut edges: Vec<(u32, u32, bool)> = Vec::with_capacity(3 * boundary.len());
    for &s in boundary {
        let (t, f) = topology::split(s);
        let fv = topology::oriented_face(&tets[t], f);
        for k in 0..3 {
            let (a, b) = (fv[k], fv[(k + 1) % 3]);
            edges.push((a.min(b), a.max(b), a < b));
        }
    }
    edges.par_sort_unstable();
    for run in edges.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        let forward = run.iter().filter(|e| e.2).count();
        if 2 * forward != run.len() {
            pr.push(format!(
                "boundary edge ({}, {}) is in {} boundary faces, not paired by opposite sides",
                name(pr, run[0].0),
                name(pr, run[0].1),
                run.len()
            ));
        }
    }
}

/// Boundary faces that lie on no facet must lie on the convex hull: at every edge they
/// share with another such face the two meet convexly, and where coplanar, they are
/// Delaunay under the perturbation (TetGen's hull triangulation).
fn check_hull(
    points: &[Point],
    tets: &[[u32; 4]],
    boundary: &[u32],
    on_facet: impl Fn(&[u32; 3]) -> bool,
    pr: &mut Problems,
) {
    let hull: Vec<u32> = boundary
        .iter()
        .copied()
        .filter(|&s| !on_facet(&topology::key(tets, s)))
        .collect();
    let face = |s: u32| {
        let (t, f) = topology::split(s);
        topology::oriented_face(&tets[t], f)
    };
    let mut edges: Vec<(u32, u32, u32)> = Vec::with_capacity(3 * hull.len());
    for &s in &hull {
        let fv = face(s);
        for k in 0..3 {
            let (a, b) = (fv[k], fv[(k + 1) % 3]);
            edges.push((a.min(b), a.max(b), s));
        }
    }
    edges.par_sort_unstable();
    let p = |v: u32| &points[v as usize];
    for run in edges.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        let [e1, e2] = run else { continue };
        let (face1, face2) = (face(e1.2), face(e2.2));
        let Some(&x) = face2.iter().find(|v| !face1.contains(v)) else {
            continue;
        };
        let o = orient3d(p(face1[0]), p(face1[1]), p(face1[2]), p(x));
        if o < 0.0 {
            pr.push(format!(
                "the boundary is not convex at faces {:?} and {:?}",
                names(pr, &face1),
                names(pr, &face2)
            ));
        } else if o == 0.0 {
            let t1 = tets[(e1.2 >> 2) as usize];
            let q = [t1[0], t1[1], t1[2], t1[3], x];
            if insphere_sos(q.map(p), q) != Sign::Negative {
                pr.push(format!(
                    "coplanar hull faces {:?} and {:?} are not Delaunay",
                    names(pr, &face1),
                    names(pr, &face2)
                ));
            }
        }
    }
}

/// The tets tile the domain: in each face-connected part of the mesh, a point inside one
/// of its tets lies in no other tet.
fn check_tiling(points: &[Point], tets: &[[u32; 4]], topo: &topology::Topology, pr: &mut Problems) {
    let mut dsu = crate::plc::prepare::Dsu((0..tets.len()).collect());
    for (s, &o) in topo.adj.iter().enumerate() {
        if o != topology::NONE && (s as u32) < o {
            dsu.union(s >> 2, (o >> 2) as usize);
        }
    }
    let mut parts: Vec<(usize, usize)> = (0..tets.len()).map(|t| (dsu.find(t), t)).collect();
    parts.sort_unstable();
    let parts: Vec<&[(usize, usize)]> = parts.chunk_by(|x, y| x.0 == y.0).collect();
    let mut locator = locate::Locator::new(points, tets);
    locator.expect(parts.len());
    // Points inside a tet: its centroid, else points nearer one corner (a centroid can
    // round onto a face of a very flat tet).
    const WEIGHTS: [[f64; 4]; 5] = [
        [0.25; 4],
        [0.4, 0.2, 0.2, 0.2],
        [0.2, 0.4, 0.2, 0.2],
        [0.2, 0.2, 0.4, 0.2],
        [0.2, 0.2, 0.2, 0.4],
    ];
    for part in parts {
        // A point that falls on another tet's boundary says nothing: try others. A part
        // whose tets are all too flat to hold a floating-point point strictly inside is
        // left to the local checks (orientation, opposite sides, the boundary).
        let samples = part
            .iter()
            .take(64)
            .flat_map(|&(_, t)| WEIGHTS.iter().map(move |w| (t, w)));
        for (t, w) in samples {
            let tv = tets[t];
            let c: Point = std::array::from_fn(|k| {
                (0..4)
                    .map(|i| w[i] * points[tv[i] as usize][k])
                    .sum::<f64>()
            });
            if locate::in_tet(points, &tv, &c) != locate::InTet::Inside {
                continue;
            }
            let (inside, on) = locator.count(&c);
            if on > 0 && inside == 1 {
                continue;
            }
            if inside != 1 {
                pr.push(format!(
                    "the tets overlap: a point inside tet {} lies in {} tets",
                    t + pr.base,
                    inside + on
                ));
            }
            break;
        }
    }
}

/// Every vertex of a polygon must be a mesh node.
fn missing_vertices(plc: &Plc, prep: &PreparedPlc, node: &[u32], pr: &mut Problems) {
    let mut used = vec![false; plc.points.len()];
    for f in &prep.facets {
        let verts = f
            .rings
            .iter()
            .flatten()
            .chain(f.inner_segments.iter().flatten())
            .chain(&f.isolated);
        for &v in verts {
            used[v as usize] = true;
        }
    }
    for (i, &u) in used.iter().enumerate() {
        if u && node[i] == u32::MAX {
            let q = plc.points[i];
            pr.push(format!(
                "input point {} ({}, {}, {}) of a polygon is not a mesh node",
                i + plc.first_index,
                q[0],
                q[1],
                q[2]
            ));
        }
    }
}

/// A facet without faces on it must lie outside the domain: a point inside it in no tet.
fn uncovered_facets(
    prep: &PreparedPlc,
    found: &facets::Constraints,
    locator: &mut locate::Locator,
    pr: &mut Problems,
) {
    locator.expect(found.bare.len());
    for &(g, q) in &found.bare {
        if let Some(t) = locator.holder(&q) {
            pr.push(format!(
                "facet {} has no faces on it, but passes through tet {}",
                facets::facet_label(&prep.facets[g as usize], pr),
                t as usize + pr.base
            ));
        }
    }
}

/// PLC meshes: hole points, and input points that are no mesh node, lie in no tet.
fn points_outside(
    plc: &Plc,
    node: &[u32],
    points: &[Point],
    tets: &[[u32; 4]],
    locator: &mut locate::Locator,
    pr: &mut Problems,
) {
    locator.expect(plc.holes.len());
    for (i, h) in plc.holes.iter().enumerate() {
        if let Some(t) = locator.holder(h) {
            pr.push(format!(
                "hole point {} lies in tet {}",
                i + plc.first_index,
                t as usize + pr.base
            ));
        }
    }
    let used = used_nodes(points.len(), tets);
    let mut reported = 0;
    for (i, q) in plc.points.iter().enumerate() {
        let in_mesh = node[i] != u32::MAX && used[node[i] as usize];
        if in_mesh || reported >= MAX_REPORTED {
            continue;
        }
        if let Some(t) = locator.holder(q) {
            reported += 1;
            pr.push(format!(
                "input point {} lies in tet {} but is not a mesh node",
                i + plc.first_index,
                t as usize + pr.base
            ));
        }
    }
}

/// Which of `n` nodes some tet uses.
fn used_nodes(n: usize, tets: &[[u32; 4]]) -> Vec<bool> {
    let mut used = vec![false; n];
    for &v in tets.iter().flatten() {
        used[v as usize] = true;
    }
    used
}

/// Point sets: every input point is a node of some tet.
fn unused_points(plc: &Plc, node: &[u32], points: &[Point], tets: &[[u32; 4]], pr: &mut Problems) {
    let used = used_nodes(points.len(), tets);
    for (i, &x) in node.iter().enumerate() {
        if x == u32::MAX || !used[x as usize] {
            pr.push(format!(
                "input point {} is not a vertex of the mesh",
                i + plc.first_index
            ));
        }
    }
}

/// `--check`: certifies the mesh (as written: without the points no tet uses), then the
/// tables the mesher wrote beside it (neighbours, hull faces) against the tets.
pub fn check_mesh(
    plc: &Plc,
    mesh: &MeshOut,
    opts: &CertifyOptions,
) -> Result<Certificate, CheckFailure> {
    let view = MeshView {
        points: &mesh.points,
        tets: &mesh.tets,
        first_index: mesh.first_index,
    };
    let prep = if plc.facets.is_empty() || !mesh.plc_mode {
        None
    } else {
        match crate::plc::prepare::prepare(plc, opts.merge) {
            Ok(p) => Some(p),
            Err(e) => {
                return Err(CheckFailure {
                    listed: vec![e.to_string()],
                    total: 1,
                })
            }
        }
    };
    let plc_view;
    let plc = if mesh.plc_mode {
        plc
    } else {
        // A point set's facets (a .poly meshed without -p) are not constraints.
        plc_view = Plc {
            facets: Vec::new(),
            ..plc.clone()
        };
        &plc_view
    };
    let cert = certify_prepared(plc, prep.as_ref(), view, opts)?;
    check_tables(mesh)?;
    Ok(cert)
}

/// The neighbour table and the hull faces the mesher lists, against the tets.
fn check_tables(mesh: &MeshOut) -> Result<(), CheckFailure> {
    let mut pr = Problems::new(mesh.first_index, 0);
    let base = mesh.first_index;
    if mesh.neighbors.is_empty() && (mesh.hull_faces.is_empty() || mesh.plc_mode) {
        return Ok(());
    }
    let stars = facets::Rows::stars(mesh.points.len(), &mesh.tets);
    let topo = topology::Topology::build(&mesh.tets, &stars, mesh.points.len(), &mut pr);
    if !mesh.neighbors.is_empty() {
        for (s, &o) in topo.adj.iter().enumerate() {
            let (t, f) = topology::split(s as u32);
            let want = if o == topology::NONE {
                -1
            } else {
                i64::from(o >> 2)
            };
            if mesh.neighbors[t][f] != want {
                pr.push(format!(
                    "the neighbour table disagrees with the tets at face {:?}",
                    names(&pr, &topology::key(&mesh.tets, s as u32))
                ));
            }
        }
    }
    if !mesh.hull_faces.is_empty() && !mesh.plc_mode {
        if mesh.hull_faces.len() != topo.boundary.len() {
            pr.push(format!(
                "the mesh lists {} hull faces but has {} boundary faces",
                mesh.hull_faces.len(),
                topo.boundary.len()
            ));
        } else {
            for (k, (&s, h)) in topo.boundary.iter().zip(&mesh.hull_faces).enumerate() {
                let (t, f) = topology::split(s);
                let o = topology::oriented_face(&mesh.tets[t], f);
                if *h != [o[0], o[2], o[1]] {
                    pr.push(format!(
                        "hull face {} {:?} should be {:?} (face {f} of tet {})",
                        k + base,
                        names(&pr, h),
                        names(&pr, &[o[0], o[2], o[1]]),
                        t + base
                    ));
                }
            }
        }
    }
    pr.finish()
}

#[cfg(test)]
mod tests;
