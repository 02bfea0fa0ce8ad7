// A stable sort for types with Eigen's fixed-size vectorisable members (Eigen::Isometry3d, ...).
// std::stable_sort's temporary buffer ignores over-alignment in GCC 12's libstdc++: built with
// AVX (-march=native) those members are 32-byte aligned and the ranking crashed in its sort.
// Here the indices are sorted and the elements moved once, through std::vector (aligned new).
#pragma once
#include <algorithm>
#include <numeric>
#include <utility>
#include <vector>

namespace place_planner {

template <typename T, typename Less>
void stableSortAligned(std::vector<T>& v, const Less& less) {
  std::vector<size_t> idx(v.size());
  std::iota(idx.begin(), idx.end(), size_t(0));
  std::stable_sort(idx.begin(), idx.end(), [&](size_t a, size_t b) { return less(v[a], v[b]); });
  std::vector<T> out;
  out.reserve(v.size());
  for (size_t i : idx) out.push_back(std::move(v[i]));
  v.swap(out);
}

}  // namespace place_planner
