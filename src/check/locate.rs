//! Points located in the tets, exactly: how many tets hold a point, through a uniform grid
//! over the tets' boxes. It decides that the tets tile the domain (one point per
//! face-connected part of the mesh is held by exactly one tet), that hole points and
//! input points left out of the mesh lie in no tet, and that a facet without faces on it
//! crosses no tet.

use crate::geom::{orient3d, Point};

/// Where a point lies relative to one tet.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum InTet {
    /// Strictly inside.
    Inside,
    /// On its boundary.
    Boundary,
    /// Outside.
    Outside,
}

/// Where `q` lies relative to tet `t` (positively oriented), decided exactly.
pub(super) fn in_tet(points: &[Point], t: &[u32; 4], q: &Point) -> InTet {
    let w = t.map(|v| &points[v as usize]);
    let mut zero = false;
    for i in 0..4 {
        let mut x = w;
        x[i] = q;
        let o = orient3d(x[0], x[1], x[2], x[3]);
        if o < 0.0 {
            return InTet::Outside;
        }
        zero |= o == 0.0;
    }
    if zero {
        InTet::Boundary
    } else {
        InTet::Inside
    }
}

/// A uniform grid over the tets' boxes.
pub(super) struct Grid {
    lo: Point,
    cell: Point,
    dims: [usize; 3],
    start: Vec<u32>,
    items: Vec<u32>,
}

/// A tet is filed in at most this many cells; a larger one (a needle across the model)
/// is filed in every query's list of large tets instead, which keeps the grid linear in
/// size.
const MAX_CELLS: usize = 64;

impl Grid {
    /// The grid of `tets`, with about one cell per tet.
    pub fn new(points: &[Point], tets: &[[u32; 4]]) -> Self {
        let [lo, hi] = crate::geom::bounding_box(points);
        let n = tets.len().max(1) as f64;
        let ext: Point = std::array::from_fn(|k| (hi[k] - lo[k]).max(f64::MIN_POSITIVE));
        let vol = ext[0] * ext[1] * ext[2];
        let side = (vol / n).cbrt();
        let dims: [usize; 3] = std::array::from_fn(|k| {
            let d = if side > 0.0 && side.is_finite() {
                (ext[k] / side).ceil()
            } else {
                1.0
            };
            (d as usize).clamp(1, 1 << 10)
        });
        // Degenerate extents (a flat model) would make too many cells: at most a few per tet.
        let mut dims = dims;
        while dims.iter().product::<usize>() > 4 * tets.len() + 64 {
            let k = (0..3).max_by_key(|&k| dims[k]).unwrap_or(0);
            dims[k] = dims[k].div_ceil(2);
        }
        let cell: Point = std::array::from_fn(|k| ext[k] / dims[k] as f64);
        let mut g = Grid {
            lo,
            cell,
            dims,
            start: Vec::new(),
            items: Vec::new(),
        };
        let ncells = dims[0] * dims[1] * dims[2] + 1; // the last one lists the large tets
        let ranges: Vec<([usize; 3], [usize; 3])> = tets
            .iter()
            .map(|t| {
                let b = crate::geom::bounding_box(&t.map(|v| points[v as usize]));
                (g.cell_of(&b[0]), g.cell_of(&b[1]))
            })
            .collect();
        let cells_of =
            |(a, b): &([usize; 3], [usize; 3])| (0..3).map(|k| b[k] - a[k] + 1).product::<usize>();
        let mut count = vec![0u32; ncells + 1];
        for r in &ranges {
            if cells_of(r) > MAX_CELLS {
                count[ncells] += 1;
            } else {
                g.each_cell(r, |c| count[c + 1] += 1);
            }
        }
        for i in 0..ncells {
            count[i + 1] += count[i];
        }
        let mut fill = count.clone();
        let mut items = vec![0u32; count[ncells] as usize];
        for (t, r) in ranges.iter().enumerate() {
            if cells_of(r) > MAX_CELLS {
                items[fill[ncells - 1] as usize] = t as u32;
                fill[ncells - 1] += 1;
            } else {
                g.each_cell(r, |c| {
                    items[fill[c] as usize] = t as u32;
                    fill[c] += 1;
                });
            }
        }
        g.start = count;
        g.items = items;
        g
    }

    fn cell_of(&self, p: &Point) -> [usize; 3] {
        std::array::from_fn(|k| {
            let x = ((p[k] - self.lo[k]) / self.cell[k]).floor();
            if x.is_nan() || x < 0.0 {
                0
            } else {
                (x as usize).min(self.dims[k] - 1)
            }
        })
    }

    fn index(&self, c: [usize; 3]) -> usize {
        (c[2] * self.dims[1] + c[1]) * self.dims[0] + c[0]
    }

    fn each_cell(&self, (a, b): &([usize; 3], [usize; 3]), mut f: impl FnMut(usize)) {
        for z in a[2]..=b[2] {
            for y in a[1]..=b[1] {
                for x in a[0]..=b[0] {
                    f(self.index([x, y, z]));
                }
            }
        }
    }

    /// The tets that may hold `q`: those of its cell and the large ones.
    pub fn candidates(&self, q: &Point) -> impl Iterator<Item = u32> + '_ {
        let c = self.index(self.cell_of(q));
        let large = self.start.len() - 2;
        let own = &self.items[self.start[c] as usize..self.start[c + 1] as usize];
        let big = &self.items[self.start[large] as usize..self.start[large + 1] as usize];
        own.iter().chain(big).copied()
    }
}

/// Locates points in the tets: by a scan of every tet for a few points, through a
/// [`Grid`] built when more are expected.
pub(super) struct Locator<'a> {
    points: &'a [Point],
    tets: &'a [[u32; 4]],
    grid: Option<Grid>,
}

/// Up to this many points are located by scanning every tet (a grid costs about as much
/// to build as a few scans).
const SCANS: usize = 4;

impl<'a> Locator<'a> {
    pub fn new(points: &'a [Point], tets: &'a [[u32; 4]]) -> Self {
        Locator {
            points,
            tets,
            grid: None,
        }
    }

    /// Announces `n` more points to locate: past a few, the grid is built.
    pub fn expect(&mut self, n: usize) {
        if n > SCANS && self.grid.is_none() {
            self.grid = Some(Grid::new(self.points, self.tets));
        }
    }

    /// The tets that may hold `q`.
    fn candidates(&self, q: &Point) -> Box<dyn Iterator<Item = u32> + '_> {
        match &self.grid {
            Some(g) => Box::new(g.candidates(q)),
            None => {
                let (points, q) = (self.points, *q);
                Box::new((0..self.tets.len() as u32).filter(move |&t| {
                    let tv = &self.tets[t as usize];
                    (0..3).all(|k| {
                        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
                        for &v in tv {
                            lo = lo.min(points[v as usize][k]);
                            hi = hi.max(points[v as usize][k]);
                        }
                        lo <= q[k] && q[k] <= hi
                    })
                }))
            }
        }
    }

    /// How many tets hold `q` strictly inside, and how many on their boundary.
    pub fn count(&self, q: &Point) -> (usize, usize) {
        let (mut inside, mut boundary) = (0, 0);
        for t in self.candidates(q) {
            match in_tet(self.points, &self.tets[t as usize], q) {
                InTet::Inside => inside += 1,
                InTet::Boundary => boundary += 1,
                InTet::Outside => {}
            }
        }
        (inside, boundary)
    }

    /// A tet that holds `q` (its boundary included), if any.
    pub fn holder(&self, q: &Point) -> Option<u32> {
        self.candidates(q)
            .find(|&t| in_tet(self.points, &self.tets[t as usize], q) != InTet::Outside)
    }
}
