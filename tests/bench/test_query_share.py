"""bench/query_share.py's reading of a perf report: which rows are ray queries."""
import sys
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))
import query_share as qs  # noqa: E402

# Rows as `perf report --stdio --sort dso,sym -F overhead,dso,sym` prints them (cut from real runs).
MITSUBA = """# Samples: 10K of event 'cpu-clock:pppH'
#
# Overhead  Shared Object         Symbol
# ........  ....................  ..........
#
    60.00%  libembree3.so         [.] 0x00000000024db0d6
    20.00%  [JIT] tid 23218       [.] 0x00007ff6b68b8144
     5.00%  sphere.so             [.] mitsuba::Sphere<drjit::DiffArray<drjit::LLVMArray<float> > >::ray_intersect_preliminary_impl<drjit::Packet<float, 16ul> >
     1.00%  sphere.so             [.] mitsuba::Sphere<drjit::DiffArray<drjit::LLVMArray<float> > >::ray_test_impl<drjit::Packet<float, 16ul> >
     4.00%  rectangle.so          [.] mitsuba::Rectangle<drjit::DiffArray<drjit::LLVMArray<float> > >::sample_position
    10.00%  libmitsuba.so         [.] mitsuba::Scene::ray_intersect
"""

OURS = """# Samples: 20000 of event 'cpu-clock:pppH'
    40.00%  libembree3.so.3.13.5  [.] 0x00000000024daffc
     5.00%  pathtracer            [.] pt::sphere_hit4
     1.00%  pathtracer            [.] pt::(anonymous namespace)::sphere_intersect
    10.00%  pathtracer            [.] pt::(anonymous namespace)::intersect_packets<16>
    24.00%  pathtracer            [.] pt::(anonymous namespace)::diffuse_in_lanes
    20.00%  pathtracer            [.] pt::SamplerLanes::draw<pt::Sampler::next_2d_many>
"""


class ShareInQueries(unittest.TestCase):
    def test_mitsuba_embree_and_shape_intersections_count_sampling_does_not(self):
        share, samples = qs.share_in_queries(MITSUBA, qs.MITSUBA_CALLBACKS)
        self.assertAlmostEqual(share, 0.66)  # Embree 60 + sphere intersection 5 + shadow test 1
        self.assertEqual(samples, 10000)

    def test_ours_embree_and_sphere_callbacks_count_refinement_does_not(self):
        share, samples = qs.share_in_queries(OURS, qs.OURS_CALLBACKS)
        self.assertAlmostEqual(share, 0.46)  # the packet wrapper and refinement are our own time
        self.assertEqual(samples, 20000)

    def test_rows_are_normalised_by_their_sum(self):
        # --percent-limit leaves rows out of a report whose percentages are of all samples.
        share, _ = qs.share_in_queries("  30.00%  libembree3.so  [.] 0x1\n  10.00%  a.out  [.] main\n",
                                       qs.OURS_CALLBACKS)
        self.assertAlmostEqual(share, 0.75)

    def test_empty_report_is_no_share(self):
        self.assertEqual(qs.share_in_queries("# nothing sampled\n", qs.OURS_CALLBACKS), (0.0, 0))


if __name__ == "__main__":
    unittest.main()
