//! Reader of TetGen's `.ele` files (the tets of a mesh), for certifying a mesh.
//!
//! Format: a header `<#tets> <nodes per tet (4 or 10)> <#attributes>`, then one line per
//! tet `<tet #> <node> <node> <node> <node> [more nodes] [attributes]`. Nodes are numbered
//! as in the mesh's `.node` file (from `first_index`); second-order nodes are skipped.

use super::tokens::{read_text, Lines};
use crate::error::InputError;
use std::path::Path;

/// Reads the tets of a `.ele` file whose nodes are numbered from `first_index` and are
/// fewer than `nodes`, as 0-based node indices.
pub fn read(path: &Path, first_index: usize, nodes: usize) -> Result<Vec<[u32; 4]>, InputError> {
    let text = read_text(path)?;
    if let Some(tets) = fast(&text, first_index, nodes) {
        return Ok(tets);
    }
    parse(&text, path, first_index, nodes)
}

/// The tets of a well-formed file, its lines parsed on every core (a million-point mesh
/// has seven million of them); `None` leaves the file to [`parse`], which names what is
/// wrong.
fn fast(text: &str, first_index: usize, nodes: usize) -> Option<Vec<[u32; 4]>> {
    use rayon::prelude::*;
    let body = |l: &&str| {
        let l = l.split('#').next().unwrap_or("").trim();
        !l.is_empty()
    };
    let mut lines = text.lines().filter(body);
    let mut header = lines.next()?.split('#').next()?.split_whitespace();
    let count: usize = header.next()?.parse().ok()?;
    let per: usize = header.next().map_or(Some(4), |x| x.parse().ok())?;
    if per != 4 && per != 10 {
        return None;
    }
    let rows: Vec<&str> = lines.take(count).collect();
    if rows.len() != count {
        return None;
    }
    let tets: Option<Vec<[u32; 4]>> = rows
        .par_iter()
        .with_min_len(4096)
        .enumerate()
        .map(|(i, row)| {
            let mut it = row.split('#').next()?.split_whitespace();
            let number: usize = it.next()?.parse().ok()?;
            if number != i + first_index {
                return None;
            }
            let mut t = [0u32; 4];
            for x in &mut t {
                let v: usize = it.next()?.parse().ok()?;
                let idx = v.checked_sub(first_index).filter(|&k| k < nodes)?;
                *x = idx as u32;
            }
            Some(t)
        })
        .collect();
    tets
}

/// Parses the text of a `.ele` file (see [`read`]).
pub fn parse(
    text: &str,
    path: &Path,
    first_index: usize,
    nodes: usize,
) -> Result<Vec<[u32; 4]>, InputError> {
    let mut lines = Lines::new(text, path);
    let mut header = lines
        .expect_line(|| "the element header `<#tets> <nodes per tet> <#attributes>`".into())?;
    let count = header.count(|| "the number of tets".into())?;
    let per = header
        .opt_count(|| "the number of nodes per tet".into())?
        .unwrap_or(4);
    if per != 4 && per != 10 {
        return Err(header.error(format!("a tet has 4 or 10 nodes, not {per}")));
    }
    let mut tets = Vec::with_capacity(lines.capacity_for(count));
    for i in 0..count {
        let n = i + first_index;
        let mut line = lines.expect_line(|| format!("tet {n} of {count}"))?;
        line.int(|| format!("the number of tet {n}"))?;
        let mut t = [0u32; 4];
        for (k, x) in t.iter_mut().enumerate() {
            let v = line.int(|| format!("node {} of tet {n}", k + 1))?;
            let idx = v - first_index as i64;
            if idx < 0 || idx as usize >= nodes {
                return Err(line.error(format!(
                    "tet {n}: node {v} does not exist ({nodes} nodes, numbered from {first_index})"
                )));
            }
            *x = idx as u32;
        }
        tets.push(t);
    }
    Ok(tets)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fast_reader_reads_what_the_exact_one_does_and_leaves_it_the_errors() {
        let good = "# mesh\n3 4 0\n1 1 2 3 4\n\n2 2 3 4 5 # c\n3 5 4 3 2 7.5\n";
        let exact = parse(good, Path::new("m.ele"), 1, 5).unwrap();
        assert_eq!(fast(good, 1, 5), Some(exact));
        // Out of range, misnumbered, short: left to the exact reader.
        assert_eq!(fast(good, 1, 4), None);
        assert_eq!(fast("2 4 0\n1 0 1 2 3\n3 0 1 2 3\n", 1, 4), None);
        assert_eq!(fast("2 4 0\n0 0 1 2 3\n", 0, 4), None);
    }

    #[test]
    fn tets_are_read_from_zero_based_indices() {
        let text = "# mesh\n2 4 0\n1 1 2 3 4\n2 2 3 4 5 # c\n";
        let t = parse(text, Path::new("m.ele"), 1, 5).unwrap();
        assert_eq!(t, vec![[0, 1, 2, 3], [1, 2, 3, 4]]);
        let e = parse(text, Path::new("m.ele"), 1, 4)
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "m.ele:4: tet 2: node 5 does not exist (4 nodes, numbered from 1)"
        );
        let e = parse("3 4 0\n0 0 1 2 3\n", Path::new("m.ele"), 0, 4)
            .unwrap_err()
            .to_string();
        assert!(e.contains("tet 1 of 3"), "{e}");
    }
}
