// Text as a terminal shows it: every byte that is not text written \xNN.
#pragma once

#include <string>

namespace stereorig {

// `message` with every byte a terminal would not show as text written as
// \xNN: control bytes (C0, DEL, C1), and bytes that are not valid UTF-8 (a
// binary file given where YAML or text was expected puts its bytes into the
// parser's message). Valid UTF-8 (a path with 'å') passes unchanged. Every
// error line goes through it (RunCommand, ParseArgs, main), and every text
// the check's history holds as it is read (a path's bytes need not be UTF-8;
// nlohmann::json refuses to write such a string).
std::string PrintableText(const std::string& message);

}  // namespace stereorig
