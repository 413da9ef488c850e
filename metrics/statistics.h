#pragma once
// Summary statistics of a set of errors: count, RMSE, mean, median, max. An empty set has
// count 0 and NaN for every statistic, so "no data" is never mistaken for "no error".

#include <cstddef>
#include <vector>

namespace kestrel::metrics {

struct Summary {
  size_t count = 0;
  double rmse = 0.0;
  double mean = 0.0;
  double median = 0.0;  ///< mean of the two middle values for an even count
  double max = 0.0;
};

/// Statistics of `values` (taken by value: the median sorts a copy).
Summary summarize(std::vector<double> values);

}  // namespace kestrel::metrics
