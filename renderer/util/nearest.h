// "Did you mean ...?": the closest of some names to a mistyped one, by edit distance
// (insertions, deletions, substitutions and adjacent swaps: the optimal string alignment
// distance). The CLI's options, scene files in a folder and the job service's fields use it.
#pragma once

#include <algorithm>
#include <string>
#include <vector>

namespace pt {

inline size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::vector<size_t>> d(a.size() + 1, std::vector<size_t>(b.size() + 1));
  for (size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (size_t i = 1; i <= a.size(); ++i)
    for (size_t j = 1; j <= b.size(); ++j) {
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + (a[i - 1] != b[j - 1])});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  return d[a.size()][b.size()];
}

// The names within a third of their length (at least 1) of `given`, closest first (ties in the
// order given); none for a name over 128 characters (what it costs grows with the square).
inline std::vector<std::string> nearest_names(const std::string& given, const std::vector<std::string>& names) {
  std::vector<std::pair<size_t, std::string>> close;
  if (given.size() > 128) return {};
  for (const std::string& name : names) {
    if (name.size() > 128) continue;
    const size_t d = edit_distance(given, name);
    if (d <= std::max<size_t>(1, name.size() / 3)) close.emplace_back(d, name);
  }
  std::stable_sort(close.begin(), close.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<std::string> out;
  for (auto& c : close) out.push_back(std::move(c.second));
  return out;
}

// The closest name, or "" when none is close.
inline std::string nearest_name(const std::string& given, const std::vector<std::string>& names) {
  const std::vector<std::string> close = nearest_names(given, names);
  return close.empty() ? "" : close.front();
}

}  // namespace pt
