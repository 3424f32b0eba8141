// ISO 14253-1's zones and ILAC-G8's three rules, against values worked by
// hand: MPE 1.5 mm, U 0.25 mm, so the conformance zone ends at 1.25 mm and
// the nonconformance zone starts beyond 1.75 mm. Every boundary is exactly
// representable, so "<=" and ">" are tested at the boundary itself.
#include "reconstruct/metrology/decision_rule.h"

#include <gtest/gtest.h>

#include <limits>

namespace stereorig {
namespace {

constexpr double kMpe = 1.5, kU = 0.25;

TEST(DecisionRule, ZonesFollowTheExpandedUncertaintyOnBothSidesOfTheMpe) {
  EXPECT_EQ(ZoneOf(0.0, kU, kMpe), ConformanceZone::kConformance);
  EXPECT_EQ(ZoneOf(1.25, kU, kMpe), ConformanceZone::kConformance);  // |v| + U = MPE: still proven within
  EXPECT_EQ(ZoneOf(-1.25, kU, kMpe), ConformanceZone::kConformance);
  EXPECT_EQ(ZoneOf(1.375, kU, kMpe), ConformanceZone::kUncertaintyRange);
  EXPECT_EQ(ZoneOf(-1.625, kU, kMpe), ConformanceZone::kUncertaintyRange);
  EXPECT_EQ(ZoneOf(1.75, kU, kMpe), ConformanceZone::kUncertaintyRange);  // |v| - U = MPE: not proven beyond
  EXPECT_EQ(ZoneOf(1.875, kU, kMpe), ConformanceZone::kNonconformance);
  EXPECT_EQ(ZoneOf(-1.875, kU, kMpe), ConformanceZone::kNonconformance);
  // U = 0: no uncertainty range; an infinite U: nothing but it.
  EXPECT_EQ(ZoneOf(1.5, 0, kMpe), ConformanceZone::kConformance);
  EXPECT_EQ(ZoneOf(1.5000001, 0, kMpe), ConformanceZone::kNonconformance);
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(ZoneOf(0.0, inf, kMpe), ConformanceZone::kUncertaintyRange);
  EXPECT_EQ(ZoneOf(100.0, inf, kMpe), ConformanceZone::kUncertaintyRange);
}

TEST(DecisionRule, EachRuleSendsTheUncertaintyRangeItsOwnWay) {
  struct Case {
    double value_mm;
    bool simple, guarded_acceptance, guarded_rejection;
  };
  for (const Case& c : {Case{1.0, true, true, true},       // conformance zone: every rule passes
                        Case{1.375, true, false, true},    // uncertainty range, within the MPE
                        Case{1.625, false, false, true},   // uncertainty range, beyond the MPE
                        Case{-1.625, false, false, true},  // the sign of the error does not matter
                        Case{1.875, false, false, false}}) {
    EXPECT_EQ(Passes(DecisionRule::kSimpleAcceptance, c.value_mm, kU, kMpe), c.simple) << c.value_mm;
    EXPECT_EQ(Passes(DecisionRule::kGuardedAcceptance, c.value_mm, kU, kMpe), c.guarded_acceptance) << c.value_mm;
    EXPECT_EQ(Passes(DecisionRule::kGuardedRejection, c.value_mm, kU, kMpe), c.guarded_rejection) << c.value_mm;
  }
  // Simple acceptance ignores U, whatever it is.
  EXPECT_TRUE(Passes(DecisionRule::kSimpleAcceptance, 1.5, 1e9, kMpe));
  EXPECT_FALSE(Passes(DecisionRule::kSimpleAcceptance, 1.5000001, 0, kMpe));
}

TEST(DecisionRule, NamesRoundTripAndAnUnknownOneIsRefused) {
  for (DecisionRule rule :
       {DecisionRule::kSimpleAcceptance, DecisionRule::kGuardedAcceptance, DecisionRule::kGuardedRejection}) {
    EXPECT_EQ(ParseDecisionRule(DecisionRuleName(rule)), rule);
  }
  EXPECT_EQ(std::string(DecisionRuleName(DecisionRule::kGuardedAcceptance)), "guarded-acceptance");
  EXPECT_FALSE(ParseDecisionRule("guarded").has_value());
  EXPECT_FALSE(ParseDecisionRule("").has_value());
  EXPECT_EQ(std::string(ConformanceZoneName(ConformanceZone::kUncertaintyRange)), "uncertainty_range");
}

}  // namespace
}  // namespace stereorig
