"""bench/vs_mitsuba.py's verdicts: we are compared with Mitsuba's best sampler on each scene (the one
with the highest efficiency), and the table's ratios and the targets follow from the medians."""
import contextlib
import io
import sys
import types
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))
import vs_mitsuba as vm  # noqa: E402

PIXELS = 480 * 360


def row(name, mitsuba, o_sec, o_err, o_rate):
    best = max(mitsuba, key=lambda s: 1 / (mitsuba[s][0] * mitsuba[s][1]))
    return dict(name=name, depth=5, mitsuba=mitsuba, best=best, o_sec=o_sec, o_rate=o_rate, o_err=o_err,
                mean_m=0.1, mean_o=0.1, cross=0.001, shares=None, base=None)


def report(rows, spp=256):
    args = types.SimpleNamespace(spp=spp, baseline="")
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        vm.report(args, rows, PIXELS)
    return out.getvalue()


class Report(unittest.TestCase):
    def test_the_best_sampler_is_the_one_we_face(self):
        # multijitter: 1/(0.001 x 10) = 100; independent: 1/(0.003 x 9) = 37: multijitter is the best.
        r = row("CBbunny", {"multijitter": (10.0, 0.001), "independent": (9.0, 0.003)}, 20.0, 0.0004, 2.2e6)
        text = report([r])
        self.assertIn("| CBbunny | multijitter | 100.0 | 125.0 | 1.25x |", text)
        m_rate = PIXELS * 256 / 10.0
        self.assertIn(f"| {m_rate / 1e6:.2f} M | 2.20 M | {2.2e6 / m_rate:.2f}x |", text)
        self.assertIn("target: efficiency 1/(relMSE x s) >= 1.5x Mitsuba's best sampler on every scene: not met", text)
        self.assertIn("target: samples/s >= Mitsuba's on CBbunny: not met on this host (lowest 0.50x: CBbunny", text)
        faster = row("CBbunny", {"multijitter": (10.0, 0.001)}, 8.0, 0.0004, 5e6)
        self.assertIn("target: samples/s >= Mitsuba's on CBbunny: met on this host (lowest 1.13x", report([faster]))
        self.assertIn("mitsuba multijitter *", text)

    def test_the_targets_are_met_only_when_every_scene_meets_them(self):
        good = row("CBspheres", {"multijitter": (10.0, 0.01)}, 10.0, 0.005, 5e6)  # 2x
        weak = row("dof", {"multijitter": (10.0, 0.01)}, 10.0, 0.008, 5e6)       # 1.25x
        self.assertIn("efficiency 1/(relMSE x s) >= 1.5x Mitsuba's best sampler on every scene: met",
                      report([good]))
        self.assertIn("not met on this host (lowest 1.25x: dof; 1 of 2 cases below 1.50x)", report([good, weak]))


if __name__ == "__main__":
    unittest.main()
