// The lock-step driver's latency ledger, on hand-made events with known times.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "tools/replay/latency.h"

namespace kestrel::replay {
namespace {

TEST(Quantile, NearestRankOnKnownSets) {
  EXPECT_TRUE(std::isnan(quantile({}, 0.5)));
  EXPECT_EQ(quantile({7.0}, 0.95), 7.0);
  // 1..20: the median by nearest rank is the 10th value, p95 the 19th.
  std::vector<double> v;
  for (int i = 20; i >= 1; --i) v.push_back(i);
  EXPECT_EQ(quantile(v, 0.5), 10.0);
  EXPECT_EQ(quantile(v, 0.95), 19.0);
  EXPECT_EQ(quantile(v, 1.0), 20.0);
  EXPECT_EQ(quantile(v, 0.0), 1.0);
}

TEST(LatencyLedger, TimesEachProcessFromThePublicationOfItsEvent) {
  LatencyLedger ledger;
  ledger.acknowledge("vo", "CAMERA_RGBD", 0.5);  // before any event: not counted
  // Three frames: vo answers after 4, 6, 5 ms; the estimator's STATE after VO_UPDATE 1 ms later.
  const double vo_ms[] = {4, 6, 5};
  for (int k = 0; k < 3; ++k) {
    const double t0 = 10.0 + k;
    ledger.begin_event("CAMERA_RGBD", t0);
    ledger.acknowledge("vo", "CAMERA_RGBD", t0 + 1e-3 * vo_ms[k]);
    ledger.acknowledge("estimator", "VO_UPDATE", t0 + 1e-3 * (vo_ms[k] + 1));
    ledger.acknowledge("estimator", "VO_UPDATE", t0 + 0.5);  // a second one: only the first counts
    ledger.end_event();
    ledger.acknowledge("vo", "CAMERA_RGBD", t0 + 0.9);  // after the event settled: not counted
  }
  ledger.begin_event("IMU", 20.0);
  ledger.acknowledge("estimator", "IMU", 20.0002);
  ledger.end_event();

  std::vector<LatencyRow> rows, all;  // per handled channel; per process, done with the event
  for (const auto& r : ledger.rows()) (r.handled == LatencyLedger::kAll ? all : rows).push_back(r);
  ASSERT_EQ(all.size(), 3u);
  EXPECT_EQ(all[0].process, "vo");
  EXPECT_NEAR(all[0].median_ms, 5.0, 1e-9);  // vo's only acknowledgement
  EXPECT_EQ(all[1].process, "estimator");
  EXPECT_NEAR(all[1].median_ms, 500.0, 1e-9);  // its last one, the second VO_UPDATE's
  EXPECT_EQ(all[2].input, "IMU");
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0].input, "CAMERA_RGBD");
  EXPECT_EQ(rows[0].process, "vo");  // ordered by median within an input
  EXPECT_EQ(rows[0].count, 3);
  EXPECT_NEAR(rows[0].median_ms, 5.0, 1e-9);
  EXPECT_NEAR(rows[0].p95_ms, 6.0, 1e-9);
  EXPECT_NEAR(rows[0].max_ms, 6.0, 1e-9);
  EXPECT_EQ(rows[1].process, "estimator");
  EXPECT_EQ(rows[1].handled, "VO_UPDATE");
  EXPECT_NEAR(rows[1].median_ms, 6.0, 1e-9);
  EXPECT_NEAR(rows[1].max_ms, 7.0, 1e-9);
  EXPECT_EQ(rows[2].input, "IMU");
  EXPECT_NEAR(rows[2].median_ms, 0.2, 1e-9);

  const std::string table = format_latency(rows);
  EXPECT_EQ(table.rfind("latency, from publishing an event", 0), 0u) << table;
  EXPECT_NE(table.find("CAMERA_RGBD      estimator    VO_UPDATE              3      6.00      7.00      7.00"),
            std::string::npos)
      << table;
  EXPECT_EQ(format_latency({}), "");
}

}  // namespace
}  // namespace kestrel::replay

namespace kestrel::replay {
namespace {

// Past kExactSamples a row's samples are folded into 1 % bins: a long run keeps kilobytes, and
// its quantiles stay within 1 % of the exact ones, with the count and the maximum exact.
TEST(LatencySamples, ALongRunIsSummarisedToAPercentWithTheCountAndMaximumExact) {
  LatencySamples few, many;
  std::vector<double> all;
  for (int i = 1; i <= 100; ++i) few.add(0.1 * i);
  EXPECT_EQ(few.quantile(0.5), 5.0);  // exact while few: nearest rank
  EXPECT_EQ(few.quantile(0.95), 9.5);
  for (int i = 0; i < 200000; ++i) {
    const double ms = 0.5 + 0.0001 * ((i * 7919) % 100000);  // 0.5 .. 10.5 ms, every value 2x
    many.add(ms);
    all.push_back(ms);
  }
  EXPECT_EQ(many.count(), 200000);
  EXPECT_EQ(many.max(), *std::max_element(all.begin(), all.end()));
  for (double q : {0.5, 0.95, 0.99}) {
    const double exact = quantile(all, q);
    EXPECT_NEAR(many.quantile(q), exact, 0.01 * exact) << "q = " << q;
  }
}

}  // namespace
}  // namespace kestrel::replay
