#!/usr/bin/env python3
"""Writes one of the fine star surfaces of data/nonflat/ (fine_star*.poly).

usage: scripts/gen-fine-star.py SEED RINGS POINTS OUT.poly

The surface is the one `star()` of scripts/live-compare-plc.py draws with
`random.Random(SEED)`, with its ring count (RINGS), points per ring (POINTS), amplitude
(every point moved along its ray by up to 40%) and grid (none) fixed instead of drawn,
and no points inside. Deterministic: the same arguments write the same file byte for
byte (`gen-fine-star.py 14 12 30 OUT` writes data/nonflat/fine_star_group.poly).
"""
import importlib.util
import os
import random
import sys


def load_star():
    here = os.path.dirname(os.path.abspath(__file__))
    spec = importlib.util.spec_from_file_location(
        "live_compare_plc", os.path.join(here, "live-compare-plc.py"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


class Fixed(random.Random):
    """A generator whose first two `randint` and first three `choice` calls (the ring
    and point counts; the amplitude, the grid and the number of inner points) return
    the given values instead of drawing them."""

    def __init__(self, seed, rings, points):
        super().__init__(seed)
        self.ints = [rings, points]
        self.choices = [0.4, 0, 0]

    def randint(self, a, b):
        return self.ints.pop(0) if self.ints else super().randint(a, b)

    def choice(self, seq):
        return self.choices.pop(0) if self.choices else super().choice(seq)


def main(argv):
    if len(argv) != 4:
        sys.exit(__doc__)
    seed, rings, points, out = int(argv[0]), int(argv[1]), int(argv[2]), argv[3]
    lc = load_star()
    pts, tris = lc.star(Fixed(seed, rings, points), "small")
    lc.write_poly(out, pts, tris)


if __name__ == "__main__":
    main(sys.argv[1:])
