// Statistical helpers for the sampling and BSDF tests: a pooled Pearson chi-square
// goodness-of-fit test and midpoint quadrature of a direction pdf over (theta, phi) bins.
// PT_CHI2_DEBUG=1 in the environment prints every chi-square statistic (to see the margins).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numeric>
#include <sstream>
#include <string>
#include <vector>

#include "math.h"

namespace pt::test {

// z with P(Z > z) = alpha for a standard normal Z (bisection on erfc; alpha in (0, 0.5)).
inline double normal_upper_quantile(double alpha) {
  double lo = 0, hi = 40;
  for (int i = 0; i < 200; ++i) {
    double mid = 0.5 * (lo + hi);
    if (0.5 * std::erfc(mid / std::sqrt(2.0)) > alpha) lo = mid; else hi = mid;
  }
  return 0.5 * (lo + hi);
}

// Upper critical value of chi-square with `dof` degrees of freedom at significance alpha:
// Wilson & Hilferty, "The distribution of chi-square", PNAS 17, 1931 (cube root is ~normal).
inline double chi2_critical(int dof, double alpha) {
  double h = 2.0 / (9.0 * dof), z = normal_upper_quantile(alpha);
  return dof * std::pow(1 - h + z * std::sqrt(h), 3);
}

// The significance each of `tests` chi-square tests is run at so that all of them together fail
// by chance with probability `family` (Šidák 1967, "Rectangular confidence regions for the means
// of multivariate normal distributions"), as pbrt-v4's and Mitsuba 3's chi-square tests do.
// Each test file states how many it runs (PT_CHI2_DEBUG=1 prints every one).
inline double sidak_alpha(double family, int tests) { return 1 - std::pow(1 - family, 1.0 / tests); }

struct Chi2Result {
  bool passed = false;
  double statistic = 0, critical = 0;
  int dof = 0;
  std::string message;  // why it failed, with the numbers
};

// Pearson's chi-square test of observed against expected counts. Cells whose expected count is
// below `min_expected` are pooled into one cell (and that cell into the next-smallest one if it is
// still too small), as usual for the asymptotic distribution to hold. A sample in a cell of zero
// expected count fails outright: the sampler produced something the pdf says is impossible.
inline Chi2Result chi2_test(const std::vector<double>& observed, const std::vector<double>& expected,
                            double alpha = 1e-3, double min_expected = 5) {
  Chi2Result r;
  std::vector<size_t> order(observed.size());
  std::iota(order.begin(), order.end(), size_t(0));
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return expected[a] < expected[b]; });
  std::vector<std::pair<double, double>> cells;  // (observed, expected)
  double pool_o = 0, pool_e = 0;
  for (size_t i : order) {
    if (expected[i] <= 0 && observed[i] > 0) {
      std::ostringstream os;
      os << observed[i] << " samples in cell " << i << " whose expected count is " << expected[i];
      r.message = os.str();
      return r;
    }
    if (expected[i] < min_expected) {
      pool_o += observed[i];
      pool_e += expected[i];
    } else {
      cells.push_back({observed[i], expected[i]});
    }
  }
  if (pool_e > 0) {
    if (pool_e < min_expected && !cells.empty()) {  // cells[0] is the smallest regular cell
      cells[0].first += pool_o;
      cells[0].second += pool_e;
    } else {
      cells.push_back({pool_o, pool_e});
    }
  }
  if (cells.size() < 2) {
    r.message = "fewer than two cells after pooling";
    return r;
  }
  for (auto& c : cells) r.statistic += (c.first - c.second) * (c.first - c.second) / c.second;
  r.dof = int(cells.size()) - 1;
  r.critical = chi2_critical(r.dof, alpha);
  r.passed = r.statistic <= r.critical;
  std::ostringstream os;
  os << "chi2 = " << r.statistic << " with " << r.dof << " dof, critical value " << r.critical
     << " at alpha " << alpha;
  r.message = os.str();
  if (std::getenv("PT_CHI2_DEBUG")) std::fprintf(stderr, "[chi2] %s\n", r.message.c_str());
  return r;
}

// Bins of the unit sphere, uniform in theta in [0, pi] (pole +z) and phi in [0, 2 pi).
struct SphereBins {
  int n_theta, n_phi;
  SphereBins(int nt, int np) : n_theta(nt), n_phi(np) {}
  int size() const { return n_theta * n_phi; }
  int index(Vec3 w) const {
    double len = std::sqrt(double(w.x) * w.x + double(w.y) * w.y + double(w.z) * w.z);
    double theta = std::acos(std::clamp(double(w.z) / len, -1.0, 1.0));
    double phi = std::atan2(double(w.y), double(w.x));
    if (phi < 0) phi += 2 * M_PI;
    int it = std::min(int(theta / M_PI * n_theta), n_theta - 1);
    int ip = std::min(int(phi / (2 * M_PI) * n_phi), n_phi - 1);
    return it * n_phi + ip;
  }
  // Integral of a solid-angle pdf over every bin, by the midpoint rule with sub_t x sub_p points
  // per bin (d omega = sin theta d theta d phi).
  template <class Pdf>
  std::vector<double> integrate(Pdf pdf, int sub_t, int sub_p) const {
    std::vector<double> out(size(), 0.0);
    int nt = n_theta * sub_t, np = n_phi * sub_p;
    double dt = M_PI / nt, dp = 2 * M_PI / np;
    std::vector<double> cp(np), sp(np);
    for (int j = 0; j < np; ++j) {
      cp[j] = std::cos((j + 0.5) * dp);
      sp[j] = std::sin((j + 0.5) * dp);
    }
    for (int i = 0; i < nt; ++i) {
      double t = (i + 0.5) * dt, st = std::sin(t), ct = std::cos(t);
      int bt = i / sub_t;
      for (int j = 0; j < np; ++j) {
        Vec3 w(float(st * cp[j]), float(st * sp[j]), float(ct));
        out[bt * n_phi + j / sub_p] += double(pdf(w)) * st * dt * dp;
      }
    }
    return out;
  }
};

inline double sum(const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0); }

}  // namespace pt::test
