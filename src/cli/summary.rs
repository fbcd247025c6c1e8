//! What a run reports about its models: the summary table (stdout), its TSV form
//! (`--summary FILE`) and the JSON Lines records of a batch (`--stats-json FILE`).

use super::model::ModelReport;
use crate::error_chain;
use tetcdt::stats::{json_f64, json_string};

/// The widest status shown in the stdout table; the TSV has the whole reason.
const STATUS_WIDTH: usize = 50;

/// One model's line of the summary.
pub struct Row {
    /// The input file as given.
    pub model: String,
    /// 0 for success, else the model's exit code.
    pub code: i32,
    /// Why the model failed (the first line of the error), empty on success.
    pub reason: String,
    /// Nodes, Steiner points and tets written, for successful models.
    pub figures: Option<[usize; 3]>,
    /// The worst radius-edge ratio, the smallest dihedral angle and the tets refinement
    /// left over its bounds, where the run computed them (`-q`, `-a`, `-V`).
    pub quality: Option<(f64, f64, usize)>,
    /// Wall seconds.
    pub secs: f64,
}

impl Row {
    /// The row of a finished model.
    pub fn of(report: &ModelReport) -> Row {
        let (code, reason, figures, quality) = match &report.result {
            Ok(done) => {
                let steiner = done.stats.plc.as_ref().map_or(0, |p| p.steiner_points);
                let left = done.stats.plc.as_ref().map_or(0, |p| p.refine_left);
                let quality = done
                    .stats
                    .quality
                    .as_ref()
                    .map(|q| (q.max_ratio, q.min_dihedral, left));
                (
                    0,
                    String::new(),
                    Some([done.points, steiner, done.stats.output_tets]),
                    quality,
                )
            }
            Err(f) => (f.code, first_line(&error_chain(&f.err)), None, None),
        };
        Row {
            model: report.file.display().to_string(),
            code,
            reason,
            figures,
            quality,
            secs: report.secs,
        }
    }

    /// "ok", or the exit code and the reason.
    fn status(&self) -> String {
        if self.code == 0 {
            "ok".into()
        } else {
            format!("exit {}: {}", self.code, self.reason)
        }
    }
}

/// The first line of a message, with tabs made spaces (TSV fields hold no tabs).
fn first_line(msg: &str) -> String {
    msg.lines().next().unwrap_or("").replace('\t', " ")
}

/// Cuts `s` to at most `width` characters, marking the cut with "...".
fn clip(s: &str, width: usize) -> String {
    if s.chars().count() <= width {
        return s.to_owned();
    }
    let mut out: String = s.chars().take(width.saturating_sub(3)).collect();
    out.push_str("...");
    out
}

/// The quality figures of a row as text: worst ratio, smallest dihedral angle, tets left.
fn quality_cells(r: &Row) -> [String; 3] {
    match r.quality {
        Some((ratio, angle, left)) => [
            format!("{ratio:.3}"),
            format!("{angle:.2}"),
            left.to_string(),
        ],
        None => ["-".into(), "-".into(), "-".into()],
    }
}

/// The summary as an aligned text table with a closing count line; the quality columns
/// appear when a model has quality figures.
pub fn table(rows: &[Row]) -> String {
    let with_quality = rows.iter().any(|r| r.quality.is_some());
    let mut head = vec!["model", "status", "vertices", "Steiner", "tets", "seconds"];
    if with_quality {
        head.extend(["max ratio", "min dihedral", "left"]);
    }
    let cells: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            let fig = |i: usize| r.figures.map_or("-".to_string(), |f| f[i].to_string());
            let mut c = vec![
                r.model.clone(),
                clip(&r.status(), STATUS_WIDTH),
                fig(0),
                fig(1),
                fig(2),
                format!("{:.3}", r.secs),
            ];
            if with_quality {
                c.extend(quality_cells(r));
            }
            c
        })
        .collect();
    let mut width: Vec<usize> = head.iter().map(|h| h.chars().count()).collect();
    for c in &cells {
        for (w, s) in width.iter_mut().zip(c) {
            *w = (*w).max(s.chars().count());
        }
    }
    let line = |c: &[String]| {
        let mut s = String::new();
        for (i, (cell, w)) in c.iter().zip(&width).enumerate() {
            if i > 0 {
                s.push_str("  ");
            }
            // Text columns align left, figures right.
            if i < 2 {
                s.push_str(&format!("{cell:<w$}"));
            } else {
                s.push_str(&format!("{cell:>w$}"));
            }
        }
        s.trim_end().to_owned() + "\n"
    };
    let head: Vec<String> = head.into_iter().map(String::from).collect();
    let mut out = line(&head);
    for c in &cells {
        out.push_str(&line(c));
    }
    let failed = rows.iter().filter(|r| r.code != 0).count();
    out.push_str(&format!(
        "{} models: {} ok, {} failed\n",
        rows.len(),
        rows.len() - failed,
        failed
    ));
    out
}

/// The summary as TSV with a header line (`--summary FILE`); figures of failed models,
/// and quality figures a run did not compute, are empty fields.
pub fn tsv(rows: &[Row]) -> String {
    let mut out = String::from(
        "model\tstatus\texit_code\tvertices\tsteiner_points\ttets\tseconds\t\
         max_radius_edge_ratio\tmin_dihedral\trefine_left\treason\n",
    );
    for r in rows {
        let fig = |i: usize| r.figures.map_or(String::new(), |f| f[i].to_string());
        let quality = r
            .quality
            .map_or(["".into(), "".into(), "".into()], |(q, a, l)| {
                [q.to_string(), a.to_string(), l.to_string()]
            });
        out.push_str(&format!(
            "{}\t{}\t{}\t{}\t{}\t{}\t{:.6}\t{}\t{}\t{}\t{}\n",
            r.model.replace('\t', " "),
            if r.code == 0 { "ok" } else { "failed" },
            r.code,
            fig(0),
            fig(1),
            fig(2),
            r.secs,
            quality[0],
            quality[1],
            quality[2],
            r.reason
        ));
    }
    out
}

/// One model's JSON record, one line: on success the fields of `Stats::to_json` and
/// the node count; always the status, the exit code and the wall seconds; on failure
/// the error.
pub fn json_record(report: &ModelReport) -> String {
    let model = report.file.to_string_lossy();
    let tail = |code: i32| {
        format!(
            "\"status\": {}, \"exit_code\": {code}, \"wall_secs\": {}",
            json_string(if code == 0 { "ok" } else { "failed" }),
            json_f64(report.secs)
        )
    };
    match &report.result {
        Ok(done) => {
            let json = done.stats.to_json(&model);
            let body = json
                .strip_prefix('{')
                .and_then(|j| j.strip_suffix('}'))
                .unwrap_or(&json);
            format!(
                "{{{body}, \"output_points\": {}, {}}}",
                done.points,
                tail(0)
            )
        }
        Err(f) => format!(
            "{{\"model\": {}, {}, \"error\": {}}}",
            json_string(&model),
            tail(f.code),
            json_string(&error_chain(&f.err))
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::model::Done;
    use crate::Failure;
    use std::path::PathBuf;

    fn reports() -> Vec<ModelReport> {
        let stats = tetcdt::Stats {
            input_points: 8,
            output_tets: 6,
            ..Default::default()
        };
        vec![
            ModelReport {
                file: PathBuf::from("a/cube.poly"),
                result: Ok(Done { stats, points: 9 }),
                secs: 0.25,
            },
            ModelReport {
                file: PathBuf::from("bad.off"),
                result: Err(Failure::new(
                    3,
                    anyhow::anyhow!("bad.off:4: polygon 1:\tvertex 9 is not a vertex\nmore"),
                )),
                secs: 0.5,
            },
        ]
    }

    #[test]
    fn table_aligns_and_counts() {
        let rows: Vec<Row> = reports().iter().map(Row::of).collect();
        let t = table(&rows);
        let lines: Vec<&str> = t.lines().collect();
        assert_eq!(lines.len(), 4, "{t}");
        assert!(lines[0].starts_with("model        status"), "{t}");
        assert!(lines[1].starts_with("a/cube.poly  ok"), "{t}");
        assert!(lines[1].ends_with("9        0     6    0.250"), "{t}");
        assert!(
            lines[2].contains("exit 3: bad.off:4: polygon 1: vertex 9"),
            "{t}"
        );
        assert!(!t.contains("more"), "only the first line of an error: {t}");
        assert_eq!(lines[3], "2 models: 1 ok, 1 failed");
    }

    #[test]
    fn tsv_has_a_header_and_empty_figures_for_failures() {
        let rows: Vec<Row> = reports().iter().map(Row::of).collect();
        let t = tsv(&rows);
        let lines: Vec<Vec<&str>> = t.lines().map(|l| l.split('\t').collect()).collect();
        assert_eq!(lines.len(), 3);
        assert!(lines.iter().all(|l| l.len() == 11), "{t}");
        assert_eq!(
            lines[1][..10],
            [
                "a/cube.poly",
                "ok",
                "0",
                "9",
                "0",
                "6",
                "0.250000",
                "",
                "",
                ""
            ]
        );
        assert_eq!(lines[2][..6], ["bad.off", "failed", "3", "", "", ""]);
        assert_eq!(
            lines[2][10],
            "bad.off:4: polygon 1: vertex 9 is not a vertex"
        );
    }

    #[test]
    fn json_records_are_single_lines() {
        let r = reports();
        let ok = json_record(&r[0]);
        assert!(
            ok.starts_with("{\"model\": \"a/cube.poly\", \"input_points\": 8"),
            "{ok}"
        );
        assert!(
            ok.ends_with(
                "\"output_points\": 9, \"status\": \"ok\", \"exit_code\": 0, \"wall_secs\": 0.25}"
            ),
            "{ok}"
        );
        let bad = json_record(&r[1]);
        assert!(!bad.contains('\n') && !ok.contains('\n'));
        assert!(
            bad.starts_with("{\"model\": \"bad.off\", \"status\": \"failed\", \"exit_code\": 3,"),
            "{bad}"
        );
        assert!(
            bad.contains("\\u0009vertex 9 is not a vertex\\u000amore\"}"),
            "{bad}"
        );
    }

    #[test]
    fn clipping_marks_the_cut() {
        assert_eq!(clip("abcdef", 6), "abcdef");
        assert_eq!(clip("abcdefg", 6), "abc...");
    }
}
