// lane_math.h: the physics compiled in four SSE2 lanes and eight AVX2 lanes computes, lane by
// lane, the bits it computes at width 1 (the scalar code's), on random inputs and on zeros,
// signed zeros, infinities, NaN and extreme magnitudes. The images' checks (test_packets,
// test_camera) see only what the scenes reach; this sees every function on every edge.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>

#include "lane_math.h"
#include "rng.h"

namespace pt::lane1 {
#include "lane_table.inc"
}  // namespace pt::lane1
namespace pt::lane4 {
#include "lane_table.inc"
}  // namespace pt::lane4
PT_BEGIN_AVX2
namespace pt::lane8 {
#include "lane_table.inc"
}  // namespace pt::lane8
PT_END_AVX2

using namespace pt;

namespace {

constexpr int kInputs = 8, kColumns = 64, kRows = 2048;

struct alignas(32) Table {
  float col[kColumns][kRows];
  float* ptr[kColumns];
  Table() {
    for (int k = 0; k < kColumns; ++k) ptr[k] = col[k];
  }
};

// Column c, row r: every tenth row of a column an edge value (a different one per column, so that
// rows mix them), the other rows uniform in [0, 1) (sample-like) or [-1.5, 1.5).
void fill_inputs(Table& in) {
  const float edges[] = {0.0f, -0.0f, 1.0f, -1.0f, kInf, -kInf, NAN, 1e-30f, -1e30f, 0.5f, 0x1p-126f, 0.999999f};
  const int n_edges = int(sizeof edges / sizeof edges[0]);
  Pcg32 rng(11, 13);
  for (int c = 0; c < kInputs; ++c)
    for (int r = 0; r < kRows; ++r) {
      float u = rng.next_float();
      in.col[c][r] = r % 10 == c ? edges[(r / 10 + 3 * c) % n_edges] : (r % 2 ? 3 * u - 1.5f : u);
    }
}

bool same_bits(float a, float b) { return std::memcmp(&a, &b, 4) == 0 || (std::isnan(a) && std::isnan(b)); }

void expect_table(const Table& want, const Table& got, int columns, const char* lanes) {
  int differing = 0;
  for (int k = 0; k < columns; ++k)
    for (int r = 0; r < kRows; ++r)
      if (!same_bits(want.col[k][r], got.col[k][r]) && ++differing <= 10)
        ADD_FAILURE() << lanes << ": output " << k << ", row " << r << ": " << got.col[k][r] << " where width 1 gives "
                      << want.col[k][r];
  EXPECT_EQ(differing, 0) << lanes;
}

}  // namespace

TEST(Lanes, EveryWidthComputesTheScalarBits) {
  auto in = std::make_unique<Table>(), one = std::make_unique<Table>(), four = std::make_unique<Table>();
  fill_inputs(*in);
  const int columns = lane1::fill_table(in->ptr, one->ptr, kRows);
  ASSERT_LE(columns, kColumns);
  EXPECT_GT(columns, 50);
  EXPECT_EQ(lane4::fill_table(in->ptr, four->ptr, kRows), columns);
  expect_table(*one, *four, columns, "four SSE2 lanes");
  if (!simd::avx2_available()) GTEST_SKIP() << "no AVX2 here: only the SSE2 lanes were checked";
  auto eight = std::make_unique<Table>();
  EXPECT_EQ(lane8::fill_table(in->ptr, eight->ptr, kRows), columns);
  expect_table(*one, *eight, columns, "eight AVX2 lanes");
}

// The tables do see the edges: masks both ways, and non-finite results among finite ones.
TEST(Lanes, TheTableReachesBothSidesOfEveryTest) {
  auto in = std::make_unique<Table>(), out = std::make_unique<Table>();
  fill_inputs(*in);
  const int columns = lane1::fill_table(in->ptr, out->ptr, kRows);
  int nonfinite = 0;
  for (int k = 0; k < columns; ++k)
    for (int r = 0; r < kRows; ++r) nonfinite += !std::isfinite(out->col[k][r]);
  EXPECT_GT(nonfinite, 100);
  const int mask_column = 2 + 3 + 1;  // russian_roulette's: after the disk, the hemisphere, the MIS weight
  int alive = 0;
  for (int r = 0; r < kRows; ++r) alive += out->col[mask_column][r] == 1.0f;
  EXPECT_GT(alive, kRows / 8);
  EXPECT_LT(alive, kRows - kRows / 8);
}
