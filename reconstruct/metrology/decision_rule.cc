#include "reconstruct/metrology/decision_rule.h"

#include <cmath>

namespace stereorig {

const char* DecisionRuleName(DecisionRule rule) {
  switch (rule) {
    case DecisionRule::kSimpleAcceptance:
      return "simple";
    case DecisionRule::kGuardedAcceptance:
      return "guarded-acceptance";
    case DecisionRule::kGuardedRejection:
      return "guarded-rejection";
  }
  return "?";
}

std::optional<DecisionRule> ParseDecisionRule(const std::string& name) {
  for (DecisionRule rule :
       {DecisionRule::kSimpleAcceptance, DecisionRule::kGuardedAcceptance, DecisionRule::kGuardedRejection}) {
    if (name == DecisionRuleName(rule)) return rule;
  }
  return std::nullopt;
}

const char* ConformanceZoneName(ConformanceZone zone) {
  switch (zone) {
    case ConformanceZone::kConformance:
      return "conformance";
    case ConformanceZone::kUncertaintyRange:
      return "uncertainty_range";
    case ConformanceZone::kNonconformance:
      return "nonconformance";
  }
  return "?";
}

ConformanceZone ZoneOf(double value_mm, double expanded_uncertainty_mm, double mpe_mm) {
  const double magnitude_mm = std::abs(value_mm);
  if (magnitude_mm + expanded_uncertainty_mm <= mpe_mm) return ConformanceZone::kConformance;
  if (magnitude_mm - expanded_uncertainty_mm > mpe_mm) return ConformanceZone::kNonconformance;
  return ConformanceZone::kUncertaintyRange;
}

double JudgedMagnitudeMm(DecisionRule rule, double value_mm, double expanded_uncertainty_mm) {
  switch (rule) {
    case DecisionRule::kGuardedAcceptance:
      return std::abs(value_mm) + expanded_uncertainty_mm;
    case DecisionRule::kGuardedRejection:
      return std::abs(value_mm) - expanded_uncertainty_mm;
    case DecisionRule::kSimpleAcceptance:
      break;
  }
  return std::abs(value_mm);
}

}  // namespace stereorig
