"""bench/denoise_bench.py's arithmetic: the error log's parsing, the reference's noise taken out, the
time to an error interpolated in log-log (and its bounds), the speed-ups and the table row."""
import math
import sys
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))
import denoise_bench as db  # noqa: E402

LOG = """seconds,spp,error_estimate,rmse,rel_mse,denoise_seconds,denoised_rel_mse
0.002204,1.0000,inf,0.40401,0.337387,0.108676,0.0611995
0.004782,2.0000,0.82274,0.237698,0.159724,0.0260627,0.040207
0.009182,4.0000,0.09515,0.126206,0.0666623,0.026663,nan
"""


class Report(unittest.TestCase):
    def test_the_error_log_reads_as_numbers(self):
        rows = db.parse_error_log(LOG)
        self.assertEqual(len(rows), 3)
        for column in ("preview_denoise_seconds", "preview_rel_mse"):  # an older log has no such column: NaN
            self.assertTrue(math.isnan(rows[1].pop(column)))
        self.assertEqual(rows[1], dict(seconds=0.004782, spp=2.0, rel_mse=0.159724, denoise_seconds=0.0260627,
                                       denoised_rel_mse=0.040207))
        self.assertTrue(math.isnan(rows[2]["denoised_rel_mse"]))

    def test_a_log_without_the_denoised_columns_is_refused(self):
        with self.assertRaises(ValueError) as e:
            db.parse_error_log("seconds,spp,error_estimate,rmse,rel_mse\n0.1,1,inf,0.4,0.3\n")
        self.assertIn("denoise_seconds", str(e.exception))

    def test_the_reference_noise_comes_out_of_both_errors(self):
        # 256 spp against 4096: the raw error is scaled by 4096/4352 (vs_cycles.rel_mse's), and the
        # same amount, 256/4352 of it, leaves the denoised error.
        raw, den = db.corrected(0.01, 0.002, 256, 4096)
        self.assertAlmostEqual(raw, 0.01 * 4096 / 4352)
        self.assertAlmostEqual(den, 0.002 - 0.01 * 256 / 4352)
        self.assertAlmostEqual(db.reference_noise(0.01, 256, 4096), 0.01 - raw)

    def test_curves_add_the_denoise_time(self):
        rows = db.parse_error_log(LOG)[:2]
        raw, den = db.curves(rows, 1024)
        self.assertAlmostEqual(raw[1][0], 0.004782)
        self.assertAlmostEqual(den[1][0], 0.004782 + 0.0260627)
        self.assertAlmostEqual(raw[0][1], 0.337387 * 1024 / 1025)
        self.assertAlmostEqual(den[0][1], 0.0611995 - 0.337387 / 1025)

    def test_time_to_error_is_log_log_between_the_first_bracketing_points(self):
        # Error 1/t: log-log linear, so 1e-2 is reached at t = 100 exactly from points at 10 and 1000.
        points = [(1.0, 1.0), (10.0, 0.1), (1000.0, 0.001)]
        bound, t = db.time_to_error(points, 1e-2)
        self.assertEqual(bound, "")
        self.assertAlmostEqual(t, 100.0)
        # Halfway in log error between 4 s (1e-1) and 16 s (1e-3) is 8 s.
        self.assertAlmostEqual(db.time_to_error([(4.0, 1e-1), (16.0, 1e-3)], 1e-2)[1], 8.0)
        # The first crossing counts, though a later point goes back above the target.
        self.assertAlmostEqual(db.time_to_error([(1.0, 1.0), (10.0, 0.01), (20.0, 0.5), (40.0, 0.001)], 0.01)[1], 10.0)

    def test_time_to_error_bounds(self):
        self.assertEqual(db.time_to_error([(2.0, 0.5), (4.0, 0.2)], 0.1), (">", 4.0))
        self.assertEqual(db.time_to_error([(2.0, 0.05), (4.0, 0.02)], 0.1), ("<=", 2.0))
        self.assertIsNone(db.time_to_error([], 0.1))
        # A corrected error at or below zero is below what the reference can tell: its own time.
        self.assertEqual(db.time_to_error([(2.0, 0.5), (4.0, -1e-4)], 0.1), ("", 4.0))
        # NaN points are skipped.
        self.assertAlmostEqual(db.time_to_error([(1.0, 1.0), (5.0, math.nan), (100.0, 1e-4)], 1e-2)[1], 10.0)

    def test_formatting_times_and_speed_ups(self):
        self.assertEqual(db.format_time(("", 1.234)), "1.23 s")
        self.assertEqual(db.format_time((">", 45.6)), "> 45.6 s")
        self.assertEqual(db.format_time(("<=", 0.01234)), "<= 0.0123 s")
        self.assertEqual(db.format_time(None), "-")
        self.assertEqual(db.format_time((">", 1234.5)), "> 1234 s")
        self.assertEqual(db.speed_up(("", 10.0), ("", 2.5)), "4.00x")
        self.assertEqual(db.speed_up((">", 10.0), ("", 2.5)), "> 4.00x")
        self.assertEqual(db.speed_up(("", 10.0), ("<=", 2.5)), "> 4.00x")
        self.assertEqual(db.speed_up(("", 10.0), (">", 20.0)), "< 0.50x")
        self.assertEqual(db.speed_up((">", 10.0), (">", 20.0)), "?")
        self.assertEqual(db.speed_up(None, ("", 1.0)), "?")

    def test_the_table_row(self):
        ours = ([(1.0, 1.0), (10.0, 0.1), (1000.0, 0.001)], [(2.0, 0.1), (20.0, 0.001)])
        cycles = ([(4.0, 1e-1), (16.0, 1e-3)], [(1.0, 1e-3)])
        self.assertEqual(db.table_row("cornell_gltf", ours, cycles),
                         "| cornell_gltf | 100 s | 6.32 s | 15.81x | 1000 s | 20 s | 50.00x "
                         "| 8 s | <= 1 s | 16 s | <= 1 s |")
        self.assertTrue(db.table_row("CBbunny", ours).endswith("| - | - | - | - |"))
        self.assertEqual(db.TABLE_HEAD.count("\n"), 1)
        self.assertEqual(db.TABLE_HEAD.splitlines()[0].count("|"), db.table_row("CBbunny", ours).count("|"))

    def test_the_denoise_cost(self):
        rows = [dict(seconds=s, spp=n, denoise_seconds=d) for s, n, d in
                [(1.0, 1, 0.5), (2.0, 2, 0.1), (4.0, 4, 0.1), (8.0, 8, 0.2)]]
        cost = db.denoise_cost(rows)
        self.assertAlmostEqual(cost["median"], 0.15)
        self.assertAlmostEqual(cost["first"], 0.5)
        self.assertAlmostEqual(cost["pass_median"], 1.5)  # passes of 1, 1, 2 and 4 s
        self.assertAlmostEqual(cost["ratio"], 0.1)
        self.assertAlmostEqual(cost["spp"], 0.15)  # 1 spp a second

    def test_the_fast_curve_and_its_row(self):
        rows = [dict(seconds=s, spp=n, rel_mse=e, preview_denoise_seconds=0.5, preview_rel_mse=f)
                for s, n, e, f in [(1.0, 1, 0.1, 0.01), (2.0, 2, 0.05, 0.001)]]
        fast = db.fast_curve(rows, 1024)
        self.assertEqual([t for t, _ in fast], [1.5, 2.5])
        self.assertAlmostEqual(fast[0][1], 0.01 - 0.1 * 1 / 1025)  # the reference's noise out
        self.assertEqual(db.fast_curve([dict(seconds=1.0, spp=1, rel_mse=0.1)], 1024), [])
        row = db.fast_row("x", [(1.0, 0.1), (100.0, 0.001)], fast)
        self.assertEqual(row.count("|"), db.FAST_HEAD.splitlines()[0].count("|"))

    def test_the_preview_cost_per_pass(self):
        rows = [dict(seconds=s, spp=n, preview_denoise_seconds=d) for s, n, d in
                [(1.0, 1, 0.5), (2.0, 2, 0.2), (4.0, 4, 0.15), (8.0, 8, math.nan)]]
        passes, first = db.preview_cost(rows)
        self.assertEqual(passes, [(1, 1.0, 0.5), (2, 1.0, 0.2), (4, 2.0, 0.15)])
        self.assertEqual(first, 4)  # 0.15 s against a 2 s pass
        self.assertEqual(db.preview_cost(rows[:2])[1], None)

    def test_the_spp_ladder(self):
        self.assertEqual(db.spp_ladder(1), [1])
        self.assertEqual(db.spp_ladder(8), [1, 2, 4, 8])
        self.assertEqual(db.spp_ladder(12), [1, 2, 4, 8, 12])

    def test_quick_fills_only_what_is_not_given(self):
        args = db.parse_args(["--quick", "--spp", "32"])
        self.assertEqual((tuple(args.res), args.spp, args.ref_spp, args.cycles_max_spp), ((64, 48), 32, 64, 8))
        args = db.parse_args([])
        self.assertEqual((tuple(args.res), args.spp, args.ref_spp, args.cycles_max_spp), ((200, 150), 1024, 1024, 256))


if __name__ == "__main__":
    unittest.main()
