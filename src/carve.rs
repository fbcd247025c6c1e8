//! Carving, the stage after facet recovery: the finished CDT's domain (the tets its
//! subfaces enclose, with their regions) is kept and put in output form, with the
//! subfaces and subsegments that bound it. It reads the CDT's tets and constraints and
//! changes neither.

use crate::constrained::cdt::Cdt;
use crate::constrained::construction::Built;
use crate::constrained::domain::domain;
use crate::constrained::{PlcOptions, PlcStats};
use crate::error::Error;
use crate::mesh::VertexId;
use crate::output::MeshOut;
use crate::plc::prepare::PreparedPlc;
use crate::plc::Plc;
use crate::progress::{Progress, Stage};
use std::time::Instant;

/// Carves a copy of CDT `cdt` (its subsegments with their markers) and puts it in output
/// form.
pub(crate) fn carve_copy(
    plc: &Plc,
    prep: &PreparedPlc,
    cdt: &Cdt,
    opts: &PlcOptions,
    stats: &mut PlcStats,
) -> Result<MeshOut, Error> {
    let built = Built::of(cdt.clone(), cdt.subsegs.clone());
    carve(plc, prep, built, opts, stats, &crate::progress::no_progress)
}

/// Carves the CDT `built` of `plc` (meshed as `prep`): keeps the tets of its domain,
/// gives them their regions, and puts the mesh in output form.
pub(crate) fn carve(
    plc: &Plc,
    prep: &PreparedPlc,
    built: Built,
    opts: &PlcOptions,
    stats: &mut PlcStats,
    progress: Progress<'_>,
) -> Result<MeshOut, Error> {
    progress(Stage::Carve);
    let Built {
        mut cdt,
        seg_markers,
        carved,
        flat_left: _,
        retry_points: _,
        first_point_covers: _,
        covering: _,
    } = built;
    let t = Instant::now();
    let carved =
        carved.unwrap_or_else(|| domain(&mut cdt, &plc.holes, &plc.regions, opts.keep_hull));
    stats.carve_secs = t.elapsed().as_secs_f64();
    if carved.tets.is_empty() {
        return Err(crate::error::InputError::Invalid {
            file: plc.source.clone(),
            msg: crate::precheck::empty_domain_message(plc),
        }
        .into());
    }
    let n_out = cdt
        .dt
        .orig
        .iter()
        .map(|&o| o as usize + 1)
        .max()
        .unwrap_or(0)
        .max(plc.points.len());
    let mut points = plc.points.clone();
    points.resize(n_out, [0.0; 3]);
    for (v, &o) in cdt.dt.orig.iter().enumerate() {
        points[o as usize] = cdt.dt.points[v];
    }
    let orig_ids = cdt.dt.orig.clone();
    let orig = |v: VertexId| orig_ids[v as usize];
    let mut kept = vec![false; cdt.dt.mesh.num_slots()];
    for &t in &carved.tets {
        kept[t as usize] = true;
    }
    let tets: Vec<[u32; 4]> = carved
        .tets
        .iter()
        .map(|&t| cdt.dt.mesh.verts(t).map(orig))
        .collect();
    // Each subface is found through the face index's hint (a walk only where the mesh
    // changed since), and written from a kept side: from the lower tet if both are kept.
    let mut keys: Vec<([VertexId; 3], u32)> = cdt.subfaces.iter().map(|(k, &f)| (*k, f)).collect();
    keys.sort_unstable();
    let mut subfaces: Vec<([u32; 3], i32)> = Vec::with_capacity(keys.len());
    for (k, f) in keys {
        let Some(a) = cdt.face_ref(k[0], k[1], k[2]) else {
            continue;
        };
        let b = cdt.dt.mesh.adj(a);
        let side = match (kept[a.tet() as usize], kept[b.tet() as usize]) {
            (true, true) if b.tet() < a.tet() => b,
            (true, _) => a,
            (false, true) => b,
            (false, false) => continue,
        };
        // Seen from the kept tet, as TetGen orients subfaces: they face into the mesh.
        let w = cdt.dt.mesh.face_verts(side.tet(), side.face()).map(orig);
        subfaces.push((w, prep.facets[f as usize].marker));
    }
    let mut subsegments: Vec<([u32; 2], i32)> = seg_markers
        .iter()
        .map(|(&(a, b), &m)| ([orig(a).min(orig(b)), orig(a).max(orig(b))], m))
        .collect();
    subsegments.sort_unstable();
    // A polygon dangling in the exterior (a fin on a surface) would be carved away with
    // it: its edges would bound no tet, and the mesh would silently lose a constraint.
    // One pass over the tets marks the subsegments found.
    let mut listed =
        crate::mesh::ListedEdges::new(n_out, subsegments.iter().map(|&([a, b], _)| (a, b)));
    listed.mark(tets.iter().copied());
    // `subsegments` is sorted: the flags are in its order.
    let found_edge = listed.flags();
    let lost = found_edge.iter().filter(|&&f| !f).count();
    if let Some(k) = found_edge.iter().position(|&f| !f) {
        let [a, b] = subsegments[k].0;
        let name = |v: u32| v as usize + plc.first_index;
        return Err(crate::error::InputError::Invalid {
            file: plc.source.clone(),
            msg: crate::precheck::exterior_polygon_message(plc, lost, (name(a), name(b))),
        }
        .into());
    }
    stats.output_tets = tets.len();
    stats.output_subfaces = subfaces.len();
    let n_attr = plc.num_point_attrs;
    let mut point_attrs = plc.point_attrs.clone();
    point_attrs.resize(n_out * n_attr, 0.0);
    let point_markers = plc.point_markers.clone().map(|mut m| {
        m.resize(n_out, 0);
        m
    });
    let (num_tet_attrs, tet_attrs) = if opts.region_attributes {
        (1, carved.attributes)
    } else {
        (0, Vec::new())
    };
    let mesh = MeshOut {
        points,
        num_point_attrs: n_attr,
        point_attrs,
        point_markers,
        tets,
        neighbors: Vec::new(),
        num_tet_attrs,
        tet_attrs,
        subfaces,
        subsegments,
        plc_mode: true,
        subfaces_oriented: true,
        first_index: plc.first_index,
        convex_hull_kept: opts.keep_hull,
        ..Default::default()
    };
    Ok(mesh)
}
