// ScanSupply: a map starved of scans is found by the gaps in the scans'
// numbers, or by their silence, and is fed again with some hysteresis.

#include <gtest/gtest.h>

#include "ofn/rh_optimizer/scan_supply.hpp"

namespace ofn::rh {
namespace {

constexpr double kScanPeriod = 0.08;  // s, 12.5 Hz

// Feeds scans 0..n-1 at the scanner's rate from `t0`, keeping those for
// which `arrives(i)` holds; returns the time after the last.
template <class Arrives>
double feed(ScanSupply& supply, double t0, int64_t first, int n, Arrives arrives) {
  for (int i = 0; i < n; ++i)
    if (arrives(first + i)) supply.received(t0 + i * kScanPeriod, first + i);
  return t0 + n * kScanPeriod;
}

TEST(ScanSupply, EveryScanOrHalfOfThemIsFed) {
  ScanSupply all;
  const double t = feed(all, 0.0, 0, 100, [](int64_t) { return true; });
  EXPECT_FALSE(all.starved(t));
  EXPECT_NEAR(all.share(), 1.0, 0.03);
  ScanSupply half;
  const double u = feed(half, 0.0, 0, 100, [](int64_t i) { return i % 2 == 0; });
  EXPECT_FALSE(half.starved(u));
  EXPECT_NEAR(half.share(), 0.5, 0.05);
  EXPECT_EQ(half.why(), "");
}

TEST(ScanSupply, OneScanInTenIsStarvedAndSaysWhy) {
  ScanSupply supply;
  const double t = feed(supply, 0.0, 0, 200, [](int64_t i) { return i % 10 == 0; });
  EXPECT_TRUE(supply.starved(t - kScanPeriod * 9));  // just after a scan: not the silence
  EXPECT_NEAR(supply.share(), 0.1, 0.03);
  EXPECT_NE(supply.why().find("% of the scans"), std::string::npos) << supply.why();
}

TEST(ScanSupply, SilenceIsStarvedAndTheFirstScansAreNotJudged) {
  ScanSupply supply;
  EXPECT_FALSE(supply.starved(100.0));  // never a scan: not this watch's to judge
  supply.received(0.0, 7);
  EXPECT_FALSE(supply.starved(0.5));  // too few due for a share, not silent yet
  EXPECT_TRUE(supply.starved(1.2));   // 1.2 s without a scan
  EXPECT_NE(supply.why().find("no scan for"), std::string::npos) << supply.why();
}

TEST(ScanSupply, FedAgainOnlyAboveTheUpperShare) {
  ScanSupply supply;
  double t = feed(supply, 0.0, 0, 50, [](int64_t i) { return i % 10 == 0; });
  ASSERT_TRUE(supply.starved(t - kScanPeriod * 9));
  // A quarter arriving: between the two shares, still starved.
  t = feed(supply, t, 50, 50, [](int64_t i) { return i % 4 == 0; });
  EXPECT_TRUE(supply.starved(t - kScanPeriod * 3)) << supply.share();
  // All of them: fed.
  t = feed(supply, t, 100, 50, [](int64_t) { return true; });
  EXPECT_FALSE(supply.starved(t));
}

TEST(ScanSupply, AScannerCountingAgainStartsAFreshWindow) {
  ScanSupply supply;
  double t = feed(supply, 0.0, 1000, 50, [](int64_t) { return true; });
  ASSERT_FALSE(supply.starved(t));
  // Restarted: numbers from 0 again, all arriving; the jump back is no gap.
  t = feed(supply, t, 0, 50, [](int64_t) { return true; });
  EXPECT_FALSE(supply.starved(t));
  EXPECT_NEAR(supply.share(), 1.0, 0.03);
}

TEST(ScanSupply, OffNeverStarves) {
  ScanSupplySettings off;
  off.enabled = false;
  ScanSupply supply(off);
  supply.received(0.0, 0);
  EXPECT_FALSE(supply.starved(50.0));
}

}  // namespace
}  // namespace ofn::rh
