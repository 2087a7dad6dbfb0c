"""bench/vs_cycles.py's arithmetic: luminance, the 4x4 cells and their worst ratio, the relative MSE
with the reference's noise taken out, efficiency, the -m to Cycles bounces mapping and the table row."""
import sys
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))
import vs_cycles as vc  # noqa: E402


def flat(h, w, v):
    return [[v] * w for _ in range(h)]


class Report(unittest.TestCase):
    def test_luminance_is_rec709(self):
        lum = vc.luminance_rows([[(1, 0, 0), (0, 1, 0)], [(0, 0, 1), (1, 1, 1)]])
        self.assertAlmostEqual(lum[0][0], 0.2126)
        self.assertAlmostEqual(lum[0][1], 0.7152)
        self.assertAlmostEqual(lum[1][0], 0.0722)
        self.assertAlmostEqual(lum[1][1], 1.0)

    def test_cells_split_the_image_top_left_first(self):
        # 8x8: the top-left 2x2 pixels are 5, the rest 1; the bottom-right 2x2 are 3.
        img = flat(8, 8, 1.0)
        for y in range(2):
            for x in range(2):
                img[y][x] = 5.0
                img[6 + y][6 + x] = 3.0
        cells = vc.cell_means(img)
        self.assertEqual(cells[0][0], 5.0)
        self.assertEqual(cells[3][3], 3.0)
        self.assertEqual(cells[1][2], 1.0)

    def test_cells_of_an_odd_size_count_every_pixel_once(self):
        # 7 wide, 5 high: cell edges at floor(i * size / 4); the pixel-weighted cell means give the mean.
        img = [[float(x + 10 * y) for x in range(7)] for y in range(5)]
        cells = vc.cell_means(img)
        ys, xs = [0, 1, 2, 3, 5], [0, 1, 3, 5, 7]
        total = sum(cells[r][c] * (ys[r + 1] - ys[r]) * (xs[c + 1] - xs[c]) for r in range(4) for c in range(4))
        self.assertAlmostEqual(total / 35, vc.mean(img))
        self.assertAlmostEqual(cells[3][3], (35 + 36 + 45 + 46) / 4)

    def test_the_worst_cell_is_the_farthest_from_one_with_its_sign(self):
        theirs = flat(8, 8, 1.0)
        ours = flat(8, 8, 1.0)
        ours[0][7] = ours[1][7] = ours[0][6] = ours[1][6] = 1.1  # cell (0, 3): +10%
        ours[4][2] = ours[5][2] = ours[4][3] = ours[5][3] = 0.8  # cell (2, 1): -20%
        dev, row, col = vc.worst_cell(ours, theirs)
        self.assertAlmostEqual(dev, -0.2)
        self.assertEqual((row, col), (2, 1))
        self.assertAlmostEqual(vc.cell_ratios(ours, theirs)[0][3], 1.1)

    def test_ratios_of_black(self):
        self.assertEqual(vc.ratio(0.0, 0.0), 1.0)
        self.assertEqual(vc.ratio(1.0, 0.0), float("inf"))
        self.assertEqual(vc.ratio(1.0, 4.0), 0.25)

    def test_relative_mse_as_the_renderer_computes_it(self):
        # (1 - 0.5)^2 / (0.25 + 0.01) and 0 over two pixels.
        err = vc.rel_mse([[1.0, 0.0]], [[0.5, 0.0]])
        self.assertAlmostEqual(err, 0.25 / 0.26 / 2)
        # A 4096-spp reference adds 256/4096 of a 256-spp image's variance: scaled by 4096/4352.
        self.assertAlmostEqual(vc.rel_mse([[1.0, 0.0]], [[0.5, 0.0]], 256, 4096), 0.25 / 0.26 / 2 * 4096 / 4352)

    def test_efficiency(self):
        self.assertAlmostEqual(vc.efficiency(0.01, 2.0), 50.0)
        self.assertEqual(vc.efficiency(0.0, 2.0), float("inf"))

    def test_our_depth_maps_to_cycles_bounces(self):
        self.assertEqual(vc.bounces_for_depth(1), 0)  # direct light both ways
        self.assertEqual(vc.bounces_for_depth(8), 7)
        with self.assertRaises(ValueError):
            vc.bounces_for_depth(0)

    def test_the_table_row(self):
        r = dict(name="cornell_gltf", depth=8, mean_o=0.92, mean_c=1.0, cell=(-0.212, 1, 0),
                 o_sec=2.0, o_err=0.001, c_sec=10.0, c_err=0.002)
        self.assertEqual(vc.table_row(r), "| cornell_gltf | 8 | 0.920 | -21.2% (1, 0) | 2.00 s, 1.00e-03, 500.0 "
                                          "| 10.00 s, 2.00e-03, 50.0 | 10.00x |")
        untimed = dict(r, o_sec=None)
        self.assertEqual(vc.table_row(untimed), "| cornell_gltf | 8 | 0.920 | -21.2% (1, 0) |  |  |  |")
        self.assertEqual(vc.TABLE_HEAD.count("\n"), 1)


if __name__ == "__main__":
    unittest.main()
