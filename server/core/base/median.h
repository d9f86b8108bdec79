// The median of a list of numbers.
#pragma once

#include <algorithm>
#include <vector>

namespace deform {

// The upper median (the element at size / 2 in sorted order); 0 for an empty list. O(n).
inline double Median(std::vector<double> values) {
  if (values.empty()) return 0;
  const auto middle = values.begin() + values.size() / 2;
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace deform
