//! Figures about one meshing run, printed under `-V` and later written as JSON.

/// Counts and timings of one run.
#[derive(Clone, Debug, Default)]
pub struct Stats {
    /// Number of input points.
    pub input_points: usize,
    /// Input points skipped because they coincide with an earlier one.
    pub duplicate_points: usize,
    /// Number of tets in the output.
    pub output_tets: usize,
    /// Number of hull faces of the output.
    pub hull_faces: usize,
    /// Seconds spent sorting the points (BRIO and Hilbert order).
    pub sort_secs: f64,
    /// Seconds spent building the Delaunay tetrahedralization (including sorting).
    pub delaunay_secs: f64,
    /// Seconds of the checks before meshing (`-p`: the intersection test above all).
    pub precheck_secs: f64,
    /// Seconds of the certification of the finished mesh (`-p`).
    pub certify_secs: f64,
    /// Seconds of the whole meshing call.
    pub total_secs: f64,
    /// The figures of PLC meshing (`-p`), the rows of the paper's Table 1.
    pub plc: Option<crate::constrained::PlcStats>,
    /// The shapes of the output tets (with `-V`, `--stats-json`, `-q` or `-a`).
    pub quality: Option<QualityFigures>,
}

/// The upper ends of the dihedral-angle histogram's bins, in degrees, as TetGen prints
/// them (the first bin starts at 0).
pub const DIHEDRAL_BINS: [f64; 18] = [
    5.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 80.0, 110.0, 120.0, 130.0, 140.0, 150.0, 160.0,
    170.0, 175.0, 180.0,
];

/// The shape figures of a mesh: its worst radius-edge ratio and its dihedral angles.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct QualityFigures {
    /// The largest radius-edge ratio of a tet.
    pub max_ratio: f64,
    /// The smallest dihedral angle, in degrees.
    pub min_dihedral: f64,
    /// The largest dihedral angle, in degrees.
    pub max_dihedral: f64,
    /// The smallest and the largest tet volume.
    pub volume_range: (f64, f64),
    /// Dihedral angles (six per tet) per bin of [`DIHEDRAL_BINS`].
    pub dihedral_histogram: [usize; 18],
}

impl QualityFigures {
    /// The figures of the tets `tets` (indices into `points`, from 0).
    pub fn of(points: &[crate::geom::Point], tets: &[[u32; 4]]) -> QualityFigures {
        use crate::geom::quality;
        let mut q = QualityFigures {
            min_dihedral: 180.0,
            volume_range: (f64::INFINITY, 0.0),
            ..Default::default()
        };
        for t in tets {
            let p = t.map(|v| points[v as usize]);
            q.max_ratio = q.max_ratio.max(quality::radius_edge_ratio(&p));
            let vol = quality::volume(&p);
            q.volume_range = (q.volume_range.0.min(vol), q.volume_range.1.max(vol));
            for a in quality::dihedral_angles(&p) {
                q.min_dihedral = q.min_dihedral.min(a);
                q.max_dihedral = q.max_dihedral.max(a);
                let bin = DIHEDRAL_BINS.iter().position(|&hi| a < hi).unwrap_or(17);
                q.dihedral_histogram[bin] += 1;
            }
        }
        if tets.is_empty() {
            q.min_dihedral = 0.0;
            q.volume_range = (0.0, 0.0);
        }
        q
    }

    /// The figures as `-V` prints them, one line each.
    pub fn lines(&self) -> Vec<String> {
        let mut out = vec![
            format!("Largest radius-edge ratio: {:.6}", self.max_ratio),
            format!(
                "Smallest / largest dihedral angle: {:.4} / {:.4} degrees",
                self.min_dihedral, self.max_dihedral
            ),
            format!(
                "Smallest / largest volume: {:e} / {:e}",
                self.volume_range.0, self.volume_range.1
            ),
            "Dihedral angle histogram:".to_string(),
        ];
        // Two columns, as TetGen prints it: the first nine bins on the left.
        let label = |i: usize| {
            let lo = if i == 0 { 0.0 } else { DIHEDRAL_BINS[i - 1] };
            format!(
                "{lo:>5} - {:>3} degrees: {:>10}",
                DIHEDRAL_BINS[i], self.dihedral_histogram[i]
            )
        };
        for i in 0..9 {
            out.push(format!("  {}   |  {}", label(i), label(i + 9)));
        }
        out
    }
}

impl Stats {
    /// The PLC figures as `(label, value)` rows, numbered like the paper's Table 1.
    pub fn table1_rows(&self) -> Vec<(&'static str, String)> {
        let Some(p) = &self.plc else {
            return Vec::new();
        };
        let mean = if p.regions > 0 {
            p.crossing_tets as f64 / p.regions as f64
        } else {
            0.0
        };
        let mut rows = vec![
            ("(1) input vertices", p.input_points.to_string()),
            ("(2) input polygons", p.input_polygons.to_string()),
            ("(3) Steiner points", p.steiner_points.to_string()),
            (
                "    of them on polygons",
                p.facet_steiner_points.to_string(),
            ),
            (
                "    of them free, inside the domain",
                p.free_steiner_points.to_string(),
            ),
            (
                "    flat tets left on one facet",
                p.flat_tets_left.to_string(),
            ),
            (
                "    thick tets left in a facet's slab",
                p.thick_tets_left.to_string(),
            ),
            (
                "    free-point searches cut short",
                p.free_searches_cut.to_string(),
            ),
            ("(4) output tetrahedra", p.output_tets.to_string()),
            ("(5) output subpolygons", p.output_subfaces.to_string()),
            (
                "(6) recovered subpolygons",
                p.recovered_subfaces.to_string(),
            ),
            (
                "(7) most recovered in one region",
                p.max_region_subfaces.to_string(),
            ),
            ("(9) crossing tetrahedra", p.crossing_tets.to_string()),
            (
                "(10) most crossing in one region",
                p.max_region_crossing_tets.to_string(),
            ),
            ("(11) mean crossing per region", format!("{mean:.1}")),
            ("    missing regions", p.regions.to_string()),
            (
                "    tets added by cavity enlargement",
                p.enlarged_tets.to_string(),
            ),
            (
                "    restarts for Steiner points on polygons",
                p.restarts.to_string(),
            ),
            (
                "    points put in without a restart",
                p.in_place_splits.to_string(),
            ),
        ];
        if p.inserter == crate::constrained::FacetInserter::Flip {
            let f = &p.flips;
            let fallbacks = if p.flip_fallback_facets.is_empty() {
                f.fallbacks.to_string()
            } else {
                let list: Vec<String> = p
                    .flip_fallback_facets
                    .iter()
                    .map(|x| x.to_string())
                    .collect();
                format!("{} (merged facets {})", f.fallbacks, list.join(","))
            };
            rows.extend([
                ("(8) flips performed", f.total().to_string()),
                (
                    "    2-3 / 3-2 / 4-4 flips",
                    format!("{} / {} / {}", f.flips23, f.flips32, f.flips44),
                ),
                (
                    "    repair flips (weights restored)",
                    f.repair_flips.to_string(),
                ),
                (
                    "    safeguard 1: refused, tet outside R",
                    f.outside_r.to_string(),
                ),
                (
                    "    safeguard 2: not locally regular, flipped",
                    f.not_regular.to_string(),
                ),
                (
                    "    safeguard 3: deferred to list L",
                    f.deferred.to_string(),
                ),
                (
                    "    flips refused by constraints",
                    f.constrained.to_string(),
                ),
                (
                    "    exact / perturbed flip-time comparisons",
                    format!("{} / {}", f.exact_compares, f.perturbed_compares),
                ),
                ("    fallbacks to cavity retriangulation", fallbacks),
                (
                    "    stuck on polygons not flat: Steiner points",
                    f.not_flat_stuck.to_string(),
                ),
                (
                    "      of which placed by the cavity code",
                    f.not_flat_cavity_points.to_string(),
                ),
            ]);
        }
        rows.extend([
            ("(12) Delaunay seconds", format!("{:.6}", p.delaunay_secs)),
            (
                "(13) segment recovery seconds",
                format!("{:.6}", p.segment_secs),
            ),
            (
                "    surface triangulation seconds",
                format!("{:.6}", p.surface_secs),
            ),
            (
                "(14) facet recovery seconds",
                format!("{:.6}", p.facet_secs),
            ),
            (
                "    quality refinement: points added",
                p.refine_points.to_string(),
            ),
            (
                "    tets left over the bounds (small angles)",
                p.refine_left.to_string(),
            ),
            ("    refinement seconds", format!("{:.6}", p.refine_secs)),
            ("    carving seconds", format!("{:.6}", p.carve_secs)),
            ("(16) total CDT seconds", format!("{:.6}", self.total_secs)),
        ]);
        rows
    }

    /// All figures as one JSON object (for `--stats-json`).
    pub fn to_json(&self, model: &str) -> String {
        let mut fields: Vec<(String, String)> = vec![
            ("model".into(), json_string(model)),
            ("input_points".into(), self.input_points.to_string()),
            ("duplicate_points".into(), self.duplicate_points.to_string()),
            ("output_tets".into(), self.output_tets.to_string()),
            ("delaunay_secs".into(), json_f64(self.delaunay_secs)),
            ("certify_secs".into(), json_f64(self.certify_secs)),
            ("total_secs".into(), json_f64(self.total_secs)),
        ];
        if let Some(q) = &self.quality {
            let hist: Vec<String> = q.dihedral_histogram.iter().map(|n| n.to_string()).collect();
            fields.extend([
                ("max_radius_edge_ratio".into(), json_f64(q.max_ratio)),
                ("min_dihedral".into(), json_f64(q.min_dihedral)),
                ("max_dihedral".into(), json_f64(q.max_dihedral)),
                ("min_volume".into(), json_f64(q.volume_range.0)),
                ("max_volume".into(), json_f64(q.volume_range.1)),
                (
                    "dihedral_histogram".into(),
                    format!("[{}]", hist.join(", ")),
                ),
            ]);
        }
        if let Some(p) = &self.plc {
            let pairs: [(&str, String); 26] = [
                ("refine_points", p.refine_points.to_string()),
                ("refine_left", p.refine_left.to_string()),
                ("refine_secs", json_f64(p.refine_secs)),
                ("input_polygons", p.input_polygons.to_string()),
                ("steiner_points", p.steiner_points.to_string()),
                ("facet_steiner_points", p.facet_steiner_points.to_string()),
                ("free_steiner_points", p.free_steiner_points.to_string()),
                ("flat_tets_left", p.flat_tets_left.to_string()),
                ("thick_tets_left", p.thick_tets_left.to_string()),
                ("free_searches_cut", p.free_searches_cut.to_string()),
                ("output_subfaces", p.output_subfaces.to_string()),
                ("recovered_subfaces", p.recovered_subfaces.to_string()),
                ("max_region_subfaces", p.max_region_subfaces.to_string()),
                ("regions", p.regions.to_string()),
                ("crossing_tets", p.crossing_tets.to_string()),
                (
                    "max_region_crossing_tets",
                    p.max_region_crossing_tets.to_string(),
                ),
                ("enlarged_tets", p.enlarged_tets.to_string()),
                ("restarts", p.restarts.to_string()),
                ("in_place_splits", p.in_place_splits.to_string()),
                ("in_place_off", p.in_place_off.to_string()),
                ("segment_secs", json_f64(p.segment_secs)),
                ("surface_secs", json_f64(p.surface_secs)),
                ("facet_secs", json_f64(p.facet_secs)),
                ("carve_secs", json_f64(p.carve_secs)),
                (
                    "facet_algorithm",
                    json_string(match p.inserter {
                        crate::constrained::FacetInserter::Cavity => "cavity",
                        crate::constrained::FacetInserter::Flip => "flip",
                    }),
                ),
                ("plc", "true".into()),
            ];
            fields.extend(pairs.into_iter().map(|(k, v)| (k.to_string(), v)));
            let f = &p.flips;
            let flips: [(&str, usize); 13] = [
                ("flips", f.total()),
                ("flips_2_3", f.flips23),
                ("flips_3_2", f.flips32),
                ("flips_4_4", f.flips44),
                ("repair_flips", f.repair_flips),
                ("safeguard_outside_r", f.outside_r),
                ("safeguard_not_regular", f.not_regular),
                ("safeguard_deferred", f.deferred),
                ("flips_refused_by_constraints", f.constrained),
                ("exact_flip_time_compares", f.exact_compares),
                ("flip_fallbacks", f.fallbacks),
                ("flip_not_flat_stuck", f.not_flat_stuck),
                ("flip_not_flat_cavity_points", f.not_flat_cavity_points),
            ];
            fields.extend(
                flips
                    .into_iter()
                    .map(|(k, v)| (k.to_string(), v.to_string())),
            );
        }
        let body: Vec<String> = fields
            .iter()
            .map(|(k, v)| format!("\"{k}\": {v}"))
            .collect();
        format!("{{{}}}", body.join(", "))
    }
}

/// A number as JSON (`null` when not finite).
pub fn json_f64(x: f64) -> String {
    if x.is_finite() {
        format!("{x}")
    } else {
        "null".into()
    }
}

/// A string as a JSON string literal, escaped.
pub fn json_string(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if (c as u32) < 0x20 => out.push_str(&format!("\\u{:04x}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_escapes_and_lists_plc_figures() {
        let s = Stats {
            input_points: 8,
            plc: Some(crate::constrained::PlcStats {
                regions: 2,
                crossing_tets: 10,
                ..Default::default()
            }),
            ..Default::default()
        };
        let j = s.to_json("a \"b\"\\c");
        assert!(j.starts_with("{\"model\": \"a \\\"b\\\"\\\\c\""), "{j}");
        assert!(j.contains("\"crossing_tets\": 10"), "{j}");
        let rows = s.table1_rows();
        assert!(rows.iter().any(|(k, v)| k.contains("(11)") && v == "5.0"));
    }
}
