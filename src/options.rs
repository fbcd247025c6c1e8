//! The run's options and the parser of TetGen-style packed switches (`-pq1.2a0.5VV`).
//!
//! A switch string is a `-` followed by one-letter switches, some of which carry a numeric
//! argument written right after the letter (`q1.2/15`, `a0.5`, `T1e-8`, `O0`). Every
//! switch TetGen 1.5 knows is recognised, with its number, so that the rest of the string
//! still parses; the ones we do not implement are refused by name. Unknown letters are
//! refused too: nothing is ever silently ignored.
//!
//! ```
//! use tetcdt::options::Options;
//! let opts = Options::from_switches(["-zQ", "-VV"]).unwrap();
//! assert!(opts.zero_based && opts.quiet && opts.verbose == 2);
//! assert!(Options::from_switches(["-q1.2"]).is_err());
//! ```

use std::fmt;
use std::path::PathBuf;

/// Whether PLC meshing (`-p`) is implemented. While false, `-p` is refused as a usage
/// error; flipping it turns `-p` (and with it `-C`/`-F`) on.
pub const PLC_IMPLEMENTED: bool = true;

/// The algorithm that recovers the facets of a PLC.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FacetAlgo {
    /// Cavity retriangulation (`-C`, the default).
    #[default]
    Cavity,
    /// Flip insertion (`-F`).
    Flip,
}

/// Everything a run was asked to do.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Options {
    /// `-p`: mesh a piecewise linear complex (else the Delaunay tetrahedralization of the points).
    pub plc: bool,
    /// `-C` (cavity) / `-F` (flip): how facets are recovered; needs `-p`.
    pub facet_algo: FacetAlgo,
    /// `-Q`: no terminal output except errors.
    pub quiet: bool,
    /// `-V`: verbosity, one level per `V` (`-VV` is 2).
    pub verbose: u8,
    /// `-z`: number output items from zero.
    pub zero_based: bool,
    /// `-e`: write the `.edge` file with all edges.
    pub write_edges: bool,
    /// `-n`: write the `.neigh` file.
    pub write_neighbors: bool,
    /// `-f`: the `.face` file holds all faces, not only boundary ones.
    pub all_faces: bool,
    /// `-I`: no iteration number in output file names (`cube.node`, not `cube.1.node`).
    pub no_iteration: bool,
    /// `-o PREFIX` / `--output PREFIX`: write `PREFIX.node`, `PREFIX.ele`, ...
    pub output: Option<PathBuf>,
    /// `--check`: validate the mesh after writing it.
    pub check: bool,
    /// `--stats-json FILE`: write the run's statistics as JSON.
    pub stats_json: Option<PathBuf>,
    /// `-M`: do not merge edge-adjacent coplanar facets; needs `-p`.
    pub no_merge: bool,
    /// `-c`: keep the convex hull instead of carving the exterior; needs `-p`.
    pub keep_hull: bool,
    /// `-A`: give each tet its region attribute; needs `-p`.
    pub region_attributes: bool,
    /// `-d`: only detect intersecting facets, report them and write their triangles.
    pub detect_intersections: bool,
    /// `-S`: the most Steiner points to add (`-S` alone or `-S0` means no limit).
    pub max_steiner: Option<usize>,
    /// `-k`: also write the mesh as a legacy VTK `.vtk` file.
    pub vtk_output: bool,
    /// `-g`: also write the mesh as a Medit `.mesh` file.
    pub medit_output: bool,
    /// `-J`: keep the input points that are in no tet (duplicates, points outside the
    /// domain or in holes) in the output, instead of dropping them as TetGen does.
    pub keep_unused: bool,
    /// `-q[ratio][/angle]`: refine until no tet exceeds the radius-edge ratio (or has a
    /// dihedral angle under the angle); needs `-p`.
    pub quality: Option<QualityBounds>,
    /// `-a<vol>`: no tet larger than this volume; needs `-p`.
    pub max_volume: Option<f64>,
    /// `-a` without a number: the volume bounds of the `.poly` file's regions; needs `-p`.
    pub region_volumes: bool,
    /// `-Y`: no Steiner point on the boundary (segments and facets keep their input
    /// vertices); a mesh that needs one is a failure; needs `-p`.
    pub keep_boundary: bool,
}

/// The bounds of `-q`: TetGen's defaults are a radius-edge ratio of 2 and no dihedral
/// bound.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QualityBounds {
    /// The largest radius-edge ratio a tet may have.
    pub max_ratio: f64,
    /// The smallest dihedral angle a tet may have, in degrees (0: no bound).
    pub min_dihedral: f64,
}

impl Default for QualityBounds {
    fn default() -> Self {
        QualityBounds {
            max_ratio: 2.0,
            min_dihedral: 0.0,
        }
    }
}

/// The dihedral angles of a regular tet, `acos(1/3)` in degrees: no tet has a smallest
/// dihedral angle above it, so a `-q` angle bound must stay below.
pub const REGULAR_DIHEDRAL: f64 = 70.528_779_365_509_31;

/// One thing wrong with the switches.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SwitchProblem {
    /// A TetGen switch we recognise but do not implement: the switch as written (with
    /// its number, e.g. `q1.2/15`) and what it does.
    Unimplemented {
        /// The switch as written, without the leading `-`.
        switch: String,
        /// What the switch does in TetGen.
        what: &'static str,
    },
    /// A letter (or character) that is no switch at all.
    Unknown(char),
    /// A switch that needs another one: the switch and what it needs.
    Needs {
        /// The switch as written.
        switch: char,
        /// What it needs, e.g. "-p".
        needs: &'static str,
        /// What the switch does.
        what: &'static str,
    },
    /// Two switches that exclude each other.
    Conflict(char, char),
    /// A switch given a number it does not take, or a malformed number (e.g. `-z5`).
    BadArgument {
        /// The switch letter.
        switch: char,
        /// The offending text.
        text: String,
    },
    /// `-o` inside a packed switch string (other than `-o2`): the prefix must be a
    /// separate argument.
    PackedOutput,
    /// An empty switch string (`-`).
    Empty,
}

impl fmt::Display for SwitchProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SwitchProblem::Unimplemented { switch, what } => {
                write!(f, "switch -{switch} ({what}) is not implemented yet")
            }
            SwitchProblem::Unknown(c) if !c.is_control() && !c.is_whitespace() => {
                write!(f, "unknown switch -{c}")
            }
            SwitchProblem::Unknown(c) => write!(f, "unknown switch {c:?}"),
            SwitchProblem::Needs {
                switch,
                needs,
                what,
            } => {
                write!(f, "switch -{switch} ({what}) needs {needs}")
            }
            SwitchProblem::Conflict(a, b) => {
                write!(f, "switches -{a} and -{b} exclude each other")
            }
            SwitchProblem::BadArgument { switch, text } => {
                write!(f, "switch -{switch} does not take the argument {text:?}")
            }
            SwitchProblem::PackedOutput => write!(
                f,
                "switch -o takes the output prefix as a separate argument (-o PREFIX); \
                 -o2 (second-order elements) is not implemented"
            ),
            SwitchProblem::Empty => write!(f, "empty switch string \"-\""),
        }
    }
}

/// The switches could not be accepted: every problem found, in order. A usage error.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SwitchError {
    /// What is wrong, at least one item.
    pub problems: Vec<SwitchProblem>,
}

impl fmt::Display for SwitchError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, p) in self.problems.iter().enumerate() {
            if i > 0 {
                f.write_str("; ")?;
            }
            write!(f, "{p}")?;
        }
        Ok(())
    }
}

impl std::error::Error for SwitchError {}

/// What follows a switch letter.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Arg {
    /// Nothing: a digit after it is an error.
    None,
    /// An optional number, possibly followed by `/number` groups (`q1.2/15`, `O2/7`).
    Numbers,
}

/// A TetGen switch we recognise but refuse: letter, argument, description.
const REFUSED: &[(char, Arg, &str)] = &[
    ('r', Arg::None, "reconstruct a previous mesh"),
    ('i', Arg::None, "insert additional points"),
    ('m', Arg::None, "mesh sizing function"),
    ('T', Arg::Numbers, "coplanarity tolerance"),
    ('R', Arg::Numbers, "mesh coarsening"),
    ('D', Arg::Numbers, "conforming Delaunay refinement"),
    (
        'L',
        Arg::Numbers,
        "flip-based constrained Delaunay (TetGen -L)",
    ),
    ('l', Arg::None, "incremental flip algorithm"),
    ('s', Arg::None, "no Steiner point removal"),
    ('w', Arg::Numbers, "weighted Delaunay tetrahedralization"),
    ('W', Arg::None, "regular tetrahedralization"),
    ('x', Arg::Numbers, "memory size of blocks"),
    ('X', Arg::None, "inexact arithmetic"),
    ('B', Arg::None, "no boundary information in the output"),
    ('N', Arg::None, "no .node output"),
    ('E', Arg::None, "no .ele output"),
    ('G', Arg::None, "GiD .msh output"),
    ('K', Arg::None, "VTK output with extras"),
    ('v', Arg::None, "Voronoi diagram output"),
    ('u', Arg::None, "random point insertion order"),
    ('b', Arg::None, "brio point ordering parameters"),
    ('H', Arg::None, "Hilbert curve parameters"),
    ('h', Arg::None, "help; use --help"),
];

/// Switches that are only accepted together with `-p`.
const NEED_PLC: &[(char, &str)] = &[
    ('C', "cavity facet insertion"),
    ('F', "flip facet insertion"),
    ('M', "no merging of coplanar facets"),
    ('c', "convex hull retention"),
    ('A', "region attributes"),
    ('q', "quality mesh generation"),
    ('a', "maximum volume constraint"),
    ('Y', "boundary preservation"),
];

/// What the parser noticed across all switch strings, for the checks made at the end.
#[derive(Default)]
struct Seen {
    cavity: bool,
    flip: bool,
    no_merge: bool,
    keep_hull: bool,
    regions: bool,
    quality: bool,
    volume: bool,
    keep_boundary: bool,
    jettison: bool,
    problems: Vec<SwitchProblem>,
}

impl Options {
    /// Whether coplanar neighbouring facets merge into one: not with `-M`, and not with
    /// `-Y`, whose boundary is the input's polygons as given (a merged facet's inner
    /// edges are free to change).
    pub fn merges_facets(&self) -> bool {
        !(self.no_merge || self.keep_boundary)
    }

    /// Parses switch strings (each `-` + packed switches) into options, starting from the
    /// defaults; returns every problem found if any switch is refused.
    pub fn from_switches<'a, I>(switches: I) -> Result<Options, SwitchError>
    where
        I: IntoIterator<Item = &'a str>,
    {
        let mut opts = Options::default();
        opts.apply_switches(switches)?;
        Ok(opts)
    }

    /// Applies switch strings to these options (all of them, then the checks that relate
    /// switches to each other); on error `self` may be partly changed.
    pub fn apply_switches<'a, I>(&mut self, switches: I) -> Result<(), SwitchError>
    where
        I: IntoIterator<Item = &'a str>,
    {
        let mut seen = Seen::default();
        for s in switches {
            self.apply_one(s, &mut seen);
        }
        self.finish(seen)
    }

    /// Parses one packed switch string into `self`, recording problems in `seen`.
    fn apply_one(&mut self, s: &str, seen: &mut Seen) {
        let body = s.strip_prefix('-').unwrap_or(s);
        if body.is_empty() {
            seen.problems.push(SwitchProblem::Empty);
            return;
        }
        let chars: Vec<char> = body.chars().collect();
        let mut i = 0;
        while i < chars.len() {
            let c = chars[i];
            i += 1;
            // Switches without an argument: a number right after them is an error.
            let simple = match c {
                'p' => {
                    self.plc = true;
                    true
                }
                'Q' => {
                    self.quiet = true;
                    true
                }
                'V' => {
                    self.verbose = self.verbose.saturating_add(1);
                    true
                }
                'z' => {
                    self.zero_based = true;
                    true
                }
                'e' => {
                    self.write_edges = true;
                    true
                }
                'n' => {
                    self.write_neighbors = true;
                    true
                }
                'f' => {
                    self.all_faces = true;
                    true
                }
                'I' => {
                    self.no_iteration = true;
                    true
                }
                'k' => {
                    self.vtk_output = true;
                    true
                }
                'g' => {
                    self.medit_output = true;
                    true
                }
                'C' => {
                    self.facet_algo = FacetAlgo::Cavity;
                    seen.cavity = true;
                    true
                }
                'F' => {
                    self.facet_algo = FacetAlgo::Flip;
                    seen.flip = true;
                    true
                }
                'M' => {
                    self.no_merge = true;
                    seen.no_merge = true;
                    true
                }
                'c' => {
                    self.keep_hull = true;
                    seen.keep_hull = true;
                    true
                }
                'd' => {
                    self.detect_intersections = true;
                    true
                }
                'A' => {
                    self.region_attributes = true;
                    seen.regions = true;
                    true
                }
                // TetGen's -j asks for what it does by default with -p (and we always).
                'j' => {
                    seen.jettison = true;
                    true
                }
                'J' => {
                    self.keep_unused = true;
                    true
                }
                'Y' => {
                    self.keep_boundary = true;
                    seen.keep_boundary = true;
                    true
                }
                _ => false,
            };
            if simple {
                let num = take_numbers(&chars, &mut i);
                if !num.is_empty() {
                    seen.problems.push(SwitchProblem::BadArgument {
                        switch: c,
                        text: num,
                    });
                }
                continue;
            }
            match c {
                'S' => {
                    let num = take_numbers(&chars, &mut i);
                    if num.is_empty() {
                        self.max_steiner = None;
                    } else {
                        match num.parse::<usize>() {
                            Ok(0) => self.max_steiner = None,
                            Ok(n) => self.max_steiner = Some(n),
                            Err(_) => seen.problems.push(SwitchProblem::BadArgument {
                                switch: 'S',
                                text: num,
                            }),
                        }
                    }
                }
                'O' => {
                    // -O0 (no optimization) is what we always do; any other level is refused.
                    let num = take_numbers(&chars, &mut i);
                    if !is_zero_level(&num) {
                        seen.problems.push(SwitchProblem::Unimplemented {
                            switch: format!("O{num}"),
                            what: "mesh optimization; only -O0 is accepted",
                        });
                    }
                }
                'q' => {
                    let num = take_numbers(&chars, &mut i);
                    seen.quality = true;
                    match parse_quality(&num) {
                        Some(q) => self.quality = Some(q),
                        None => seen.problems.push(SwitchProblem::BadArgument {
                            switch: 'q',
                            text: num,
                        }),
                    }
                }
                'a' => {
                    let num = take_numbers(&chars, &mut i);
                    seen.volume = true;
                    if num.is_empty() {
                        self.region_volumes = true;
                    } else {
                        match num.parse::<f64>() {
                            Ok(v) if v > 0.0 && v.is_finite() => self.max_volume = Some(v),
                            _ => seen.problems.push(SwitchProblem::BadArgument {
                                switch: 'a',
                                text: num,
                            }),
                        }
                    }
                }
                'o' => {
                    let num = take_numbers(&chars, &mut i);
                    if num.is_empty() {
                        seen.problems.push(SwitchProblem::PackedOutput);
                    } else {
                        seen.problems.push(SwitchProblem::Unimplemented {
                            switch: format!("o{num}"),
                            what: "second-order elements",
                        });
                    }
                }
                _ => match REFUSED.iter().find(|r| r.0 == c) {
                    Some(&(_, arg, what)) => {
                        let num = match arg {
                            Arg::Numbers => take_numbers(&chars, &mut i),
                            Arg::None => String::new(),
                        };
                        seen.problems.push(SwitchProblem::Unimplemented {
                            switch: format!("{c}{num}"),
                            what,
                        });
                        if arg == Arg::None {
                            let extra = take_numbers(&chars, &mut i);
                            if !extra.is_empty() {
                                seen.problems.push(SwitchProblem::BadArgument {
                                    switch: c,
                                    text: extra,
                                });
                            }
                        }
                    }
                    None => {
                        // A stray number (e.g. "-5") is reported whole, as one problem.
                        if c.is_ascii_digit() || c == '.' || c == '/' {
                            take_numbers(&chars, &mut i);
                        }
                        seen.problems.push(SwitchProblem::Unknown(c));
                    }
                },
            }
        }
    }

    /// The checks that relate switches to each other, then the verdict.
    fn finish(&mut self, mut seen: Seen) -> Result<(), SwitchError> {
        if self.plc && !PLC_IMPLEMENTED {
            seen.problems.insert(
                0,
                SwitchProblem::Unimplemented {
                    switch: "p".into(),
                    what: "PLC meshing",
                },
            );
        }
        if seen.cavity && seen.flip {
            seen.problems.push(SwitchProblem::Conflict('C', 'F'));
        }
        if seen.jettison && self.keep_unused {
            seen.problems.push(SwitchProblem::Conflict('j', 'J'));
        }
        if !self.plc {
            for &(c, what) in NEED_PLC {
                let given = match c {
                    'C' => seen.cavity,
                    'F' => seen.flip,
                    'M' => seen.no_merge,
                    'c' => seen.keep_hull,
                    'q' => seen.quality,
                    'a' => seen.volume,
                    'Y' => seen.keep_boundary,
                    _ => seen.regions,
                };
                if given {
                    seen.problems.push(SwitchProblem::Needs {
                        switch: c,
                        needs: "-p",
                        what,
                    });
                }
            }
        }
        // The same problem twice (e.g. `-ofoo`) is reported once.
        let mut unique: Vec<SwitchProblem> = Vec::with_capacity(seen.problems.len());
        for p in seen.problems {
            if !unique.contains(&p) {
                unique.push(p);
            }
        }
        seen.problems = unique;
        if seen.problems.is_empty() {
            Ok(())
        } else {
            Err(SwitchError {
                problems: seen.problems,
            })
        }
    }
}

/// The bounds of `-q` from its argument (`""`, `1.414`, `1.2/15`, `/15`): a positive
/// ratio, and an angle from 0 up to (not including) a regular tet's; `None` if malformed.
fn parse_quality(num: &str) -> Option<QualityBounds> {
    let mut q = QualityBounds::default();
    let mut parts = num.split('/');
    let ratio = parts.next().unwrap_or("");
    if !ratio.is_empty() {
        q.max_ratio = ratio
            .parse()
            .ok()
            .filter(|&r: &f64| r > 0.0 && r.is_finite())?;
    }
    if let Some(angle) = parts.next() {
        if !angle.is_empty() {
            q.min_dihedral = angle
                .parse()
                .ok()
                .filter(|&a: &f64| (0.0..REGULAR_DIHEDRAL).contains(&a))?;
        }
    }
    parts.next().is_none().then_some(q)
}

/// Consumes the numeric argument starting at `chars[*i]`: a number (digits, `.`, and an
/// exponent `e`/`E` only when a digit or sign+digit follows, so `-q1.2e` is `q1.2` then
/// `e`), then any `/number` groups. Returns the text consumed (empty if none).
fn take_numbers(chars: &[char], i: &mut usize) -> String {
    let start = *i;
    loop {
        take_number(chars, i);
        if *i < chars.len() && chars[*i] == '/' {
            *i += 1;
            continue;
        }
        break;
    }
    chars[start..*i].iter().collect()
}

/// Consumes one number at `chars[*i]` (possibly empty).
fn take_number(chars: &[char], i: &mut usize) {
    let digit = |k: usize| chars.get(k).is_some_and(|c| c.is_ascii_digit());
    let mut any = false;
    while *i < chars.len() && (chars[*i].is_ascii_digit() || chars[*i] == '.') {
        *i += 1;
        any = true;
    }
    if any && *i < chars.len() && (chars[*i] == 'e' || chars[*i] == 'E') {
        let sign = matches!(chars.get(*i + 1), Some('+') | Some('-'));
        let first = if sign { *i + 2 } else { *i + 1 };
        if digit(first) {
            *i = first;
            while digit(*i) {
                *i += 1;
            }
        }
    }
}

/// True when the argument of `-O` asks for level 0 and nothing else.
fn is_zero_level(num: &str) -> bool {
    !num.is_empty() && num.chars().all(|c| c == '0')
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ok(s: &[&str]) -> Options {
        match Options::from_switches(s.iter().copied()) {
            Ok(o) => o,
            Err(e) => panic!("{s:?} refused: {e}"),
        }
    }

    fn err(s: &[&str]) -> String {
        match Options::from_switches(s.iter().copied()) {
            Ok(o) => panic!("{s:?} accepted as {o:?}"),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn accepted_switches() {
        let d = Options::default;
        let table: &[(&[&str], Options)] = &[
            (&["-Q"], Options { quiet: true, ..d() }),
            (&["-V"], Options { verbose: 1, ..d() }),
            (&["-VVV"], Options { verbose: 3, ..d() }),
            (&["-V", "-V"], Options { verbose: 2, ..d() }),
            (
                &["-kg"],
                Options {
                    vtk_output: true,
                    medit_output: true,
                    ..d()
                },
            ),
            (&["-j"], d()),
            (&["-pj"], Options { plc: true, ..d() }),
            (
                &["-J"],
                Options {
                    keep_unused: true,
                    ..d()
                },
            ),
            (
                &["-z"],
                Options {
                    zero_based: true,
                    ..d()
                },
            ),
            (
                &["-zQ"],
                Options {
                    zero_based: true,
                    quiet: true,
                    ..d()
                },
            ),
            (
                &["-e"],
                Options {
                    write_edges: true,
                    ..d()
                },
            ),
            (
                &["-n"],
                Options {
                    write_neighbors: true,
                    ..d()
                },
            ),
            (
                &["-f"],
                Options {
                    all_faces: true,
                    ..d()
                },
            ),
            (
                &["-I"],
                Options {
                    no_iteration: true,
                    ..d()
                },
            ),
            (&["-O0"], d()),
            (&["-O00"], d()),
            (
                &["-O0z"],
                Options {
                    zero_based: true,
                    ..d()
                },
            ),
            (&["O0Q"], Options { quiet: true, ..d() }),
            (
                &["-d"],
                Options {
                    detect_intersections: true,
                    ..d()
                },
            ),
            (
                &["-fenzIQV"],
                Options {
                    all_faces: true,
                    write_edges: true,
                    write_neighbors: true,
                    zero_based: true,
                    no_iteration: true,
                    quiet: true,
                    verbose: 1,
                    ..d()
                },
            ),
            (&[], d()),
        ];
        for (s, want) in table {
            assert_eq!(&ok(s), want, "switches {s:?}");
        }
    }

    #[test]
    fn defaults() {
        let o = Options::default();
        assert!(!o.plc && !o.quiet && o.verbose == 0 && !o.zero_based);
        assert!(!o.write_edges && !o.write_neighbors && !o.all_faces && !o.no_iteration);
        assert_eq!(o.facet_algo, FacetAlgo::Cavity);
        assert_eq!(o.output, None);
        assert!(!o.check);
    }

    #[test]
    fn refused_switches_name_themselves() {
        // (switches, substrings the message must contain)
        let table: &[(&[&str], &[&str])] = &[
            (&["-q"], &["-q (quality mesh generation) needs -p"]),
            (&["-q1.2/15"], &["-q (quality mesh generation) needs -p"]),
            (&["-a0.5"], &["-a (maximum volume constraint) needs -p"]),
            (&["-pq0"], &["-q does not take the argument \"0\""]),
            (&["-pq1/80"], &["-q does not take the argument \"1/80\""]),
            (&["-pq1/2/3"], &["-q does not take the argument \"1/2/3\""]),
            (&["-pa0"], &["-a does not take the argument \"0\""]),
            (&["-pa1/2"], &["-a does not take the argument \"1/2\""]),
            (&["-r"], &["-r (reconstruct"]),
            (&["-Y"], &["-Y (boundary preservation) needs -p"]),
            (&["-pY1"], &["-Y does not take the argument \"1\""]),
            (&["-A"], &["-A (region attributes) needs -p"]),
            (&["-c"], &["-c (convex hull retention) needs -p"]),
            (&["-M"], &["-M (no merging of coplanar facets) needs -p"]),
            (&["-d5"], &["-d does not take the argument \"5\""]),
            (&["-T1e-8"], &["-T1e-8 (coplanarity"]),
            (&["-S1y"], &["unknown switch -y"]),
            (&["-R"], &["-R (mesh coarsening"]),
            (&["-m"], &["-m (mesh sizing"]),
            (&["-i"], &["-i (insert"]),
            (&["-o2"], &["-o2 (second-order"]),
            (&["-K"], &["-K (VTK output with extras"]),
            (&["-G"], &["-G (GiD"]),
            (&["-k1"], &["-k does not take the argument \"1\""]),
            (&["-jJ"], &["-j and -J exclude each other"]),
            (&["-J5"], &["-J does not take the argument \"5\""]),
            (&["-B"], &["-B (no boundary"]),
            (&["-N"], &["-N (no .node"]),
            (&["-E"], &["-E (no .ele"]),
            (&["-w"], &["-w (weighted"]),
            (&["-x1000"], &["-x1000 (memory"]),
            (&["-D"], &["-D (conforming"]),
            (&["-L"], &["-L (flip-based"]),
            (&["-l"], &["-l (incremental flip"]),
            (&["-s"], &["-s (no Steiner"]),
            (&["-u"], &["-u (random"]),
            (&["-v"], &["-v (Voronoi"]),
            (&["-h"], &["-h (help"]),
            (&["-O"], &["-O (mesh optimization"]),
            (&["-O2"], &["-O2 (mesh optimization; only -O0"]),
            (&["-O/1"], &["-O/1 (mesh optimization"]),
            (&["-O0/7"], &["-O0/7 (mesh optimization"]),
            (&["-O3/7z"], &["-O3/7 ("]),
            (&["-C"], &["-C (cavity facet insertion) needs -p"]),
            (&["-F"], &["-F (flip facet insertion) needs -p"]),
            (&["-CF"], &["-C and -F exclude each other"]),
            (&["-y"], &["unknown switch -y"]),
            (&["-%"], &["unknown switch -%"]),
            (&["-5"], &["unknown switch -5"]),
            (&["-"], &["empty switch string"]),
            (&["-o"], &["separate argument (-o PREFIX)"]),
            (&["-zo"], &["separate argument"]),
            (&["-z5"], &["-z does not take the argument \"5\""]),
            (&["-Q1.5"], &["-Q does not take the argument \"1.5\""]),
            (
                &["-A2"],
                &["-A (region", "-A does not take the argument \"2\""],
            ),
        ];
        for (s, wants) in table {
            let msg = err(s);
            for w in *wants {
                assert!(
                    msg.contains(w),
                    "switches {s:?}: message {msg:?} lacks {w:?}"
                );
            }
        }
    }

    #[test]
    fn numbers_do_not_swallow_following_switches() {
        // Every problem of the string is reported, so the later letters must parse.
        let table: &[(&str, &[&str])] = &[
            ("-pq1.2a0.5r", &["-r ("]),
            ("-pq1.2/15zy", &["unknown switch -y"]),
            ("-q1.2e", &["-q (quality mesh generation) needs -p"]),
            ("-pa.5T1e+3S10K", &["-T1e+3 (", "-K ("]),
            ("-O2/7Vpq", &["-O2/7 ("]),
        ];
        for (s, wants) in table {
            let e = Options::from_switches([*s]).unwrap_err();
            assert_eq!(e.problems.len(), wants.len(), "{s}: {e}");
            let msg = e.to_string();
            for w in *wants {
                assert!(msg.contains(w), "{s}: message {msg:?} lacks {w:?}");
            }
        }
        // `-q1.2e`: the `e` after the number is the edge switch, not an exponent.
        let mut o = Options::default();
        assert!(o.apply_switches(["-pq1.2e"]).is_ok());
        assert!(o.write_edges);
        assert_eq!(o.quality.unwrap().max_ratio, 1.2);
    }

    #[test]
    fn quality_and_volume_bounds() {
        let q = |s: &str| ok(&[s]).quality.unwrap();
        assert_eq!(q("-pq"), QualityBounds::default());
        assert_eq!(q("-pq").max_ratio, 2.0);
        assert_eq!(q("-pq1.414").max_ratio, 1.414);
        let b = q("-pq1.2/15");
        assert_eq!((b.max_ratio, b.min_dihedral), (1.2, 15.0));
        let b = q("-pq/10");
        assert_eq!((b.max_ratio, b.min_dihedral), (2.0, 10.0));
        assert_eq!(ok(&["-p"]).quality, None);
        let o = ok(&["-pa0.5"]);
        assert_eq!((o.max_volume, o.region_volumes), (Some(0.5), false));
        let o = ok(&["-pa", "-a1e-3A"]);
        assert_eq!((o.max_volume, o.region_volumes), (Some(1e-3), true));
        assert!(o.region_attributes);
    }

    #[test]
    fn repeated_problems_are_reported_once() {
        let e = Options::from_switches(["-ofoo", "-y", "-y"]).unwrap_err();
        assert_eq!(
            e.problems,
            vec![SwitchProblem::PackedOutput, SwitchProblem::Unknown('y')],
            "{e}"
        );
    }

    #[test]
    fn problem_kinds() {
        let e = Options::from_switches(["-zy"]).unwrap_err();
        assert_eq!(e.problems, vec![SwitchProblem::Unknown('y')]);
        let e = Options::from_switches(["-C"]).unwrap_err();
        assert!(matches!(
            e.problems[..],
            [SwitchProblem::Needs { switch: 'C', .. }]
        ));
        let o = Options::from_switches(["-pF"]).unwrap();
        assert_eq!(o.facet_algo, FacetAlgo::Flip);
        let o = Options::from_switches(["-pcAMS500"]).unwrap();
        assert!(o.plc && o.keep_hull && o.region_attributes && o.no_merge);
        assert_eq!(o.max_steiner, Some(500));
        assert_eq!(Options::from_switches(["-pS"]).unwrap().max_steiner, None);
    }

    #[test]
    fn facet_algo_selection() {
        // -C/-F set the field.
        let mut o = Options::default();
        let _ = o.apply_switches(["-pF"]);
        assert!(o.plc);
        assert_eq!(o.facet_algo, FacetAlgo::Flip);
        let mut o = Options::default();
        let _ = o.apply_switches(["-pC"]);
        assert_eq!(o.facet_algo, FacetAlgo::Cavity);
    }

    #[test]
    fn non_ascii_is_refused_not_panicking() {
        let msg = err(&["-zé"]);
        assert!(msg.contains("unknown switch -é"), "{msg}");
        let msg = err(&["-\u{7}"]);
        assert!(msg.contains("unknown switch"), "{msg}");
    }
}
