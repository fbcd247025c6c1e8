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
        let mut body = vec![format!("\"model\": {}", json_string(model))];
        body.extend(
            self.fields()
                .iter()
                .map(|(k, v)| format!("\"{k}\": {}", v.to_json())),
        );
        format!("{{{}}}", body.join(", "))
    }

    /// All figures as named, typed values, in the order `--stats-json` writes them (the
    /// Python package's `stats` dict is made of these too).
    pub fn fields(&self) -> Vec<(&'static str, StatValue)> {
        use StatValue::{Count, Number, Text};
        let mut fields = vec![
            ("input_points", Count(self.input_points)),
            ("duplicate_points", Count(self.duplicate_points)),
            ("output_tets", Count(self.output_tets)),
            ("delaunay_secs", Number(self.delaunay_secs)),
            ("certify_secs", Number(self.certify_secs)),
            ("total_secs", Number(self.total_secs)),
        ];
        if let Some(q) = &self.quality {
            fields.extend([
                ("max_radius_edge_ratio", Number(q.max_ratio)),
                ("min_dihedral", Number(q.min_dihedral)),
                ("max_dihedral", Number(q.max_dihedral)),
                ("min_volume", Number(q.volume_range.0)),
                ("max_volume", Number(q.volume_range.1)),
                (
                    "dihedral_histogram",
                    StatValue::Counts(q.dihedral_histogram.to_vec()),
                ),
            ]);
        }
        if let Some(p) = &self.plc {
            fields.extend([
                ("refine_points", Count(p.refine_points)),
                ("refine_left", Count(p.refine_left)),
                ("refine_secs", Number(p.refine_secs)),
                ("input_polygons", Count(p.input_polygons)),
                ("steiner_points", Count(p.steiner_points)),
                ("facet_steiner_points", Count(p.facet_steiner_points)),
                ("free_steiner_points", Count(p.free_steiner_points)),
                ("flat_tets_left", Count(p.flat_tets_left)),
                ("thick_tets_left", Count(p.thick_tets_left)),
                ("free_searches_cut", Count(p.free_searches_cut)),
                ("output_subfaces", Count(p.output_subfaces)),
                ("recovered_subfaces", Count(p.recovered_subfaces)),
                ("max_region_subfaces", Count(p.max_region_subfaces)),
                ("regions", Count(p.regions)),
                ("crossing_tets", Count(p.crossing_tets)),
                (
                    "max_region_crossing_tets",
                    Count(p.max_region_crossing_tets),
                ),
                ("enlarged_tets", Count(p.enlarged_tets)),
                ("restarts", Count(p.restarts)),
                ("in_place_splits", Count(p.in_place_splits)),
                ("in_place_off", StatValue::Flag(p.in_place_off)),
                ("segment_secs", Number(p.segment_secs)),
                ("surface_secs", Number(p.surface_secs)),
                ("facet_secs", Number(p.facet_secs)),
                ("carve_secs", Number(p.carve_secs)),
                (
                    "facet_algorithm",
                    Text(match p.inserter {
                        crate::constrained::FacetInserter::Cavity => "cavity",
                        crate::constrained::FacetInserter::Flip => "flip",
                    }),
                ),
                ("plc", StatValue::Flag(true)),
            ]);
            let f = &p.flips;
            fields.extend([
                ("flips", Count(f.total())),
                ("flips_2_3", Count(f.flips23)),
                ("flips_3_2", Count(f.flips32)),
                ("flips_4_4", Count(f.flips44)),
                ("repair_flips", Count(f.repair_flips)),
                ("safeguard_outside_r", Count(f.outside_r)),
                ("safeguard_not_regular", Count(f.not_regular)),
                ("safeguard_deferred", Count(f.deferred)),
                ("flips_refused_by_constraints", Count(f.constrained)),
                ("exact_flip_time_compares", Count(f.exact_compares)),
                ("flip_fallbacks", Count(f.fallbacks)),
                ("flip_not_flat_stuck", Count(f.not_flat_stuck)),
                (
                    "flip_not_flat_cavity_points",
                    Count(f.not_flat_cavity_points),
                ),
            ]);
        }
        fields
    }
}

/// One figure of [`Stats::fields`].
#[derive(Clone, Debug, PartialEq)]
pub enum StatValue {
    /// A count.
    Count(usize),
    /// A measurement (seconds, angles, volumes); not finite when undefined.
    Number(f64),
    /// A name.
    Text(&'static str),
    /// A yes/no figure.
    Flag(bool),
    /// Counts per bin.
    Counts(Vec<usize>),
}

impl StatValue {
    /// The value as JSON.
    pub fn to_json(&self) -> String {
        match self {
            StatValue::Count(n) => n.to_string(),
            StatValue::Number(x) => json_f64(*x),
            StatValue::Text(s) => json_string(s),
            StatValue::Flag(b) => b.to_string(),
            StatValue::Counts(v) => {
                let items: Vec<String> = v.iter().map(|n| n.to_string()).collect();
                format!("[{}]", items.join(", "))
            }
        }
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
