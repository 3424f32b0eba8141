#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>

#include "apps/command.h"
#include "calib/core/input_error.h"

namespace stereorig {

namespace {

// The message with every byte a terminal would not show as text written as
// \xNN: control bytes, and bytes that are not valid UTF-8 (a binary file
// given where YAML or text was expected puts its bytes into the parser's
// message). Valid UTF-8 (a path with 'å') passes unchanged.
std::string Printable(const std::string& message) {
  std::string out;
  auto escape = [&out](unsigned char c) {
    char buf[8];
    std::snprintf(buf, sizeof buf, "\\x%02X", c);
    out += buf;
  };
  for (size_t i = 0; i < message.size();) {
    const auto c = static_cast<unsigned char>(message[i]);
    if (c < 0x20 || c == 0x7F) {
      escape(c);
      ++i;
      continue;
    }
    if (c < 0x80) {
      out += message[i++];
      continue;
    }
    // A UTF-8 sequence: its lead byte says how many continuation bytes
    // (10xxxxxx) follow; overlong and surrogate forms are not told apart.
    const size_t n = c >= 0xC2 && c <= 0xDF ? 1 : c >= 0xE0 && c <= 0xEF ? 2 : c >= 0xF0 && c <= 0xF4 ? 3 : 0;
    bool valid = n > 0;
    for (size_t k = 1; valid && k <= n; ++k)
      valid = i + k < message.size() && (static_cast<unsigned char>(message[i + k]) & 0xC0) == 0x80;
    if (!valid) {
      escape(c);
      ++i;
      continue;
    }
    out.append(message, i, n + 1);
    i += n + 1;
  }
  return out;
}

}  // namespace

int RunCommand(const Command& command, int argc, char** argv) {
  try {
    return command.run(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help is a ParseError in CLI11 with exit code 0.
    if (e.get_exit_code() == 0) return kExitOk;
    std::fprintf(stderr, "stereorig %s: %s\n", command.name, Printable(e.what()).c_str());
    return kExitBadInput;
  } catch (const InputError& e) {
    std::fprintf(stderr, "stereorig %s: %s\n", command.name, Printable(e.what()).c_str());
    return kExitBadInput;
  } catch (const std::filesystem::filesystem_error& e) {
    // A path the user gave that cannot be listed, read or written (a folder
    // without permission, a file where a folder should be): its message
    // names the path.
    std::fprintf(stderr, "stereorig %s: %s\n", command.name, Printable(e.what()).c_str());
    return kExitBadInput;
  }
}

}  // namespace stereorig
