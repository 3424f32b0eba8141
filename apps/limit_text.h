// A figure printed beside the limit it is judged against (verify's MPE):
// the limit as the certificate gives it, the figure with enough decimals
// that the two texts order as the numbers do. With four decimals alone,
// P_F 0.341527 against an MPE of 0.34152 printed "0.3415 mm (MPE 0.3415 mm)
// FAIL", a tie that read as a contradiction.
#pragma once

#include <string>

namespace stereorig {

// The fewest decimals, at least `least`, that print `limit` exactly as its
// shortest round-trip text does (0.34152: 5; 1.5 with least 4: 4).
int LimitDecimals(double limit, int least = 4);

// `limit` with LimitDecimals(limit, least) decimals: 0.34152, 1.5000.
std::string LimitText(double limit, int least = 4);

// `value` with at least LimitDecimals(limit, least) decimals, and more until
// its magnitude read back from the text compares with `limit` as |value|
// does (greater, equal, less); the shortest round-trip text where no fixed
// count up to 17 does. Never "-0.0000": a value that rounds to zero is
// printed without its sign.
std::string ValueBesideLimitText(double value, double limit, int least = 4);

// `value` with `decimals` decimals, a zero printed without a sign
// (%.4f prints -0.00001 as "-0.0000").
std::string FixedText(double value, int decimals);

}  // namespace stereorig
