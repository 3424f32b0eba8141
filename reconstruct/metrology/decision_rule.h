// ISO 14253-1 decision rules: how a figure measured with an expanded
// uncertainty U is judged against its maximum permissible error. Every
// VDI/VDE 2634-2 figure is limited on one side, |value| <= MPE, so the
// specification zone is [0, MPE] for |value| and ISO 14253-1's zones are:
//   - conformance zone:    |value| + U <= MPE (within the MPE, proven);
//   - nonconformance zone: |value| - U >  MPE (beyond it, proven);
//   - uncertainty range:   between the two (the measurement cannot say).
// The rules, by ILAC-G8's names:
//   - simple acceptance: pass iff |value| <= MPE, U not used (what
//     VDI/VDE 2634-2's tables compare; verify's default);
//   - guarded acceptance: pass only in the conformance zone. The burden of
//     proof on whoever claims the rig conforms (a supplier at delivery): the
//     uncertainty range counts against the rig;
//   - guarded rejection: fail only in the nonconformance zone. The burden of
//     proof on whoever claims it does not (a customer's complaint): the
//     uncertainty range counts for the rig.
// U = kDecisionCoverageFactor * u, u the figure's combined standard
// uncertainty (vdi2634.h). An infinite U leaves only the uncertainty range.
#pragma once

#include <optional>
#include <string>

namespace stereorig {

enum class DecisionRule { kSimpleAcceptance, kGuardedAcceptance, kGuardedRejection };
enum class ConformanceZone { kConformance, kUncertaintyRange, kNonconformance };

// k of the U the guarded rules and the zones read (U = k u): 2, ~95% for a
// normal distribution, as ISO 14253-1 and ILAC-G8 take by default.
inline constexpr double kDecisionCoverageFactor = 2.0;

// "simple", "guarded-acceptance", "guarded-rejection": the CLI's and the
// report's spelling.
const char* DecisionRuleName(DecisionRule rule);
std::optional<DecisionRule> ParseDecisionRule(const std::string& name);
// "conformance", "uncertainty_range", "nonconformance".
const char* ConformanceZoneName(ConformanceZone zone);

ConformanceZone ZoneOf(double value_mm, double expanded_uncertainty_mm, double mpe_mm);

// What the rule compares with the MPE: |value| + U (guarded acceptance),
// |value| - U (guarded rejection), |value| (simple). The figure passes iff it
// is <= MPE, and of several measurements of one figure the largest is the
// one nearest to failing under the rule.
double JudgedMagnitudeMm(DecisionRule rule, double value_mm, double expanded_uncertainty_mm);
inline bool Passes(DecisionRule rule, double value_mm, double expanded_uncertainty_mm, double mpe_mm) {
  return JudgedMagnitudeMm(rule, value_mm, expanded_uncertainty_mm) <= mpe_mm;
}

}  // namespace stereorig
