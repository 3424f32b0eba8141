// The text of a JSON report, the same for every command (calibrate, check,
// verify, score, reconstruct, bench): indented by 2, its strings the
// document's, except that bytes which are not UTF-8 (a Linux path may hold a
// Latin-1 'é', the one byte E9) are written as the four characters \xNN
// (docs/formats.md, "Reports"): JSON text must be UTF-8, and nlohmann-json's
// dump throws on them (which ended a run in std::terminate after its verdict
// was printed, with no report); replacing them with U+FFFD would lose which
// file the report names.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace stereorig {

std::string JsonReportText(const nlohmann::json& document);
std::string JsonReportText(const nlohmann::ordered_json& document);

// `text` with each byte that starts no well-formed UTF-8 sequence written
// as \xNN (upper-case hex), the rest as it is.
std::string Utf8OrEscapedBytes(const std::string& text);

}  // namespace stereorig
