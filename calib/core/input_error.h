// Bad user input: a file, key or value that the user must fix.
//
// Thrown by the readers and the options checks; caught once, in apps/, where
// it becomes one line on stderr and exit code 2. Programming errors are not
// InputErrors: they are assertions (STEREORIG_CHECK).
#pragma once

#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace stereorig {

class InputError : public std::runtime_error {
 public:
  // `where` names the file (and key, if any); `what` says the problem.
  InputError(const std::string& where, const std::string& problem)
      : std::runtime_error(where.empty() ? problem : where + ": " + problem), where_(where), problem_(problem) {}
  // The two parts, for a caller that knows the key by another name (an
  // options section's prefix, a command-line flag) and throws it again.
  const std::string& where() const { return where_; }
  const std::string& problem() const { return problem_; }

 private:
  std::string where_, problem_;
};

}  // namespace stereorig

// An invariant of the code itself. Active in every build type, unlike
// assert(), because a wrong number in a metrology tool is worse than a crash.
#define STEREORIG_CHECK(cond)                                                                \
  do {                                                                                       \
    if (!(cond)) {                                                                           \
      std::fprintf(stderr, "%s:%d: internal check failed: %s\n", __FILE__, __LINE__, #cond); \
      std::abort();                                                                          \
    }                                                                                        \
  } while (0)
