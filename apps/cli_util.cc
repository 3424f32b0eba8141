#include "apps/cli_util.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <sstream>

#include "apps/command.h"
#include "calib/core/input_error.h"
#include "calib/core/rig.h"

namespace stereorig {

std::string ShellQuoted(const std::string& word) {
  const bool plain = !word.empty() && std::all_of(word.begin(), word.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || (c != '\0' && std::strchr("_@%+=:,./-", c) != nullptr);
  });
  if (plain) return word;
  std::string quoted = "'";
  for (char c : word) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

namespace {

const CLI::Validator& NonEmptyValue() {
  static const CLI::Validator v(
      [](const std::string& text) { return text.empty() ? std::string("an empty value") : std::string(); }, "",
      "NonEmptyValue");
  return v;
}

// Every option that takes a value refuses an empty one; NonEmptyPath's own
// message stands where an option has it.
void RefuseEmptyValues(CLI::App& app) {
  for (CLI::Option* option : app.get_options()) {
    if (option->get_type_size() == 0) continue;  // a flag
    try {
      option->get_validator("NonEmptyPath");
      continue;
    } catch (const CLI::OptionNotFound&) {
    }
    option->check(NonEmptyValue());
  }
}

// Whole-number options read a leading 0 as a decimal zero: CLI11 converts
// with strtoll's base 0, where 010 is octal 8 and 09 "Could not convert"
// (a script's zero-padded numbers: simulate --threads 09 refused,
// --calibration-captures 010 rendered 8). [sign] 0... digits loses its
// leading zeros before any conversion or check; anything else (0x10, 1.5,
// words) is left to the option's own reading.
void ReadLeadingZerosAsDecimal(CLI::App& app) {
  static const CLI::Validator leading_zeros(
      [](std::string& text) {
        const size_t begin = !text.empty() && (text[0] == '-' || text[0] == '+') ? 1 : 0;
        if (text.size() < begin + 2 || text.find_first_not_of("0123456789", begin) != std::string::npos)
          return std::string();
        size_t end = begin;
        while (end + 1 < text.size() && text[end] == '0') ++end;
        text.erase(begin, end - begin);
        return std::string();
      },
      "", "LeadingZerosDecimal");
  for (CLI::Option* option : app.get_options()) {
    const std::string type = option->get_type_name();
    if (type.rfind("INT", 0) == 0 || type.rfind("UINT", 0) == 0) option->transform(leading_zeros);
  }
}

}  // namespace

std::optional<int> ParseArgs(CLI::App& app, int argc, char** argv) {
  RefuseEmptyValues(app);
  ReadLeadingZerosAsDecimal(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp&) {
    std::fputs(app.help().c_str(), stdout);
    return kExitOk;
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "%s: %s (see --help)\n", app.get_name().c_str(), PrintableText(e.what()).c_str());
    return kExitBadInput;
  }
  return std::nullopt;
}

std::vector<std::string> SplitSceneList(const std::string& list) {
  std::vector<std::string> scenes;
  std::stringstream in(list);
  for (std::string name; std::getline(in, name, ',');) {
    if (name.empty()) throw InputError("--scenes " + list, "an empty scene name (two commas, or one at an end)");
    // A path ("cup/", as a shell completes the folder) passed the dataset's
    // check, then named its outputs after it: score's --diagnose images
    // went under a folder DIR/cup/ that does not exist, found only once the
    // scene was scored.
    if (name.find('/') != std::string::npos)
      throw InputError("--scenes " + list, "'" + name + "' is not a scene name (a folder's name in scenes/, no '/')");
    if (std::find(scenes.begin(), scenes.end(), name) != scenes.end())
      throw InputError("--scenes " + list, "names '" + name + "' twice");
    scenes.push_back(name);
  }
  if (scenes.empty() || list.back() == ',')
    throw InputError("--scenes " + list, "an empty scene name (two commas, or one at an end)");
  return scenes;
}

void CheckDatasetFolder(const std::string& dataset, bool need_truth) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status status = fs::status(dataset, ec);
  if (status.type() == fs::file_type::not_found) throw InputError(dataset, "no such dataset folder (--dataset)");
  if (ec) throw InputError(dataset, "cannot read it: " + ec.message());
  if (!fs::is_directory(status))
    throw InputError(dataset, "is a file, not a dataset folder (--dataset: the folder stereorig simulate writes)");
  if (need_truth && !fs::is_directory(fs::path(dataset) / "truth", ec))
    throw InputError(dataset, "is not a simulator dataset: it has no truth/ folder (--dataset)");
}

void CheckScenesInDataset(const std::string& dataset, const std::vector<std::string>& scenes) {
  namespace fs = std::filesystem;
  const fs::path scenes_dir = fs::path(dataset) / "scenes";
  std::vector<std::string> missing;
  for (const std::string& name : scenes)
    if (!fs::is_directory(scenes_dir / name / "active")) missing.push_back(name);
  if (missing.size() == 1)
    throw InputError((scenes_dir / missing[0]).string(), "no such scene in the dataset (--scenes)");
  if (!missing.empty()) {
    std::string names;
    for (const std::string& name : missing) names += (names.empty() ? "" : ", ") + name;
    throw InputError(scenes_dir.string(), "no such scenes in the dataset (--scenes): " + names);
  }
}

void RequireTruthRigLayout(const Rig& rig, const std::string& rig_path, const Rig& truth,
                           const std::string& truth_rig_path, const std::string& command) {
  for (int m = 0; m < std::max(rig.num_modules(), truth.num_modules()); ++m) {
    // Each side a whole clause: "module 1 has cameras 2 and 3" or "there is
    // no module 1" (the message starts with the rig file's path).
    auto side = [m](const Rig& r) {
      return m < r.num_modules()
                 ? "module " + std::to_string(m) + " has cameras " + std::to_string(r.module(m).left_camera) + " and " +
                       std::to_string(r.module(m).right_camera)
                 : "there is no module " + std::to_string(m);
    };
    if (side(rig) != side(truth))
      throw InputError(rig_path, side(rig) + "; in the dataset's truth rig (" + truth_rig_path + ") " + side(truth) +
                                     ": " + command +
                                     " compares each module with the truth's of its number; calibrate with the "
                                     "dataset's layout");
  }
}

std::vector<std::string> ScenesToRun(const std::string& dataset, const std::vector<std::string>& scenes, bool named) {
  if (named) {
    CheckScenesInDataset(dataset, scenes);
    return scenes;
  }
  namespace fs = std::filesystem;
  const fs::path scenes_dir = fs::path(dataset) / "scenes";
  std::vector<std::string> held;
  std::string defaults;
  for (const std::string& name : scenes) {
    if (fs::is_directory(scenes_dir / name / "active")) held.push_back(name);
    defaults += (defaults.empty() ? "" : ", ") + name;
  }
  if (held.empty())
    throw InputError(scenes_dir.string(),
                     "holds none of the default scenes (" + defaults +
                         ", each a folder <name>/active): name the dataset's scenes with --scenes");
  return held;
}

std::string OtherCameramodelsNote(const std::string& dir, const std::vector<std::string>& written) {
  namespace fs = std::filesystem;
  std::vector<std::string> written_names, others;
  for (const std::string& path : written) written_names.push_back(fs::path(path).filename().string());
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    // Hidden files are no rig's models (an interrupted write's .tmp-*).
    if (name.front() != '.' && e.path().extension() == ".cameramodel" &&
        std::find(written_names.begin(), written_names.end(), name) == written_names.end())
      others.push_back(name);
  }
  if (others.empty()) return "";
  std::sort(others.begin(), others.end());
  std::string list;
  for (const std::string& name : others) list += (list.empty() ? "" : ", ") + name;
  return dir + " also holds " + list +
         ", not written by this run: another rig's models? (remove them, or export into a folder of its own)";
}

int NotBuiltYet(const char* name, const char* what, int argc, char** argv) {
  CLI::App app{std::string(what) + "\n\nNOT BUILT YET: this subcommand is reserved; a later release fills it in.",
               std::string("stereorig ") + name};
  app.allow_extras();
  if (auto rc = ParseArgs(app, argc, argv)) return *rc;
  std::fprintf(stderr, "stereorig %s: not built yet in this release (see stereorig %s --help)\n", name, name);
  return kExitBadInput;
}

namespace {

// A validator of the number the text reads as: `ok` says whether it is
// allowed, `rule` what is.
CLI::Validator NumberValidator(bool (*ok)(double), const char* rule, const char* name) {
  return CLI::Validator(
      [ok, rule](const std::string& text) {
        double value = 0;
        if (!CLI::detail::lexical_cast(text, value)) return "not a number: '" + text + "'";
        if (!ok(value)) return std::string("must be ") + rule + ", got " + text;
        return std::string();
      },
      "", name);
}

}  // namespace

namespace {

// The whole number `digits` writes in `base` (10, or 16 after a 0x),
// digits alone (strtoull would take a sign, spaces, and with base 0 a
// leading 0 as octal), into *value: false if they are not. *fits: false
// for a value past 2^64 - 1 (*value is then 2^64 - 1).
bool ReadDigits(const std::string& digits, int base, uint64_t* value, bool* fits) {
  if (digits.empty() ||
      digits.find_first_not_of(base == 16 ? "0123456789abcdefABCDEF" : "0123456789") != std::string::npos)
    return false;
  errno = 0;
  const unsigned long long x = std::strtoull(digits.c_str(), nullptr, base);
  *value = x;
  *fits = errno != ERANGE;
  return true;
}

// The seed `text` names into *seed: "" if it is one (AddSeedOption's
// forms, at most max_seed), else what is wrong with it.
std::string ParseSeed(const std::string& text, uint64_t max_seed, uint64_t* seed) {
  const bool hex = text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X');
  if (text.empty()) return "an empty value";  // as every option says it (NonEmptyValue above)
  // " -1" too: strtoull skipped the space, and wrapped "-1" round to 2^64 - 1.
  const size_t first = text.find_first_not_of(" \t\n\v\f\r");
  if (first != std::string::npos && text[first] == '-') return "must be >= 0";
  uint64_t value = 0;
  bool fits = false;
  if (!ReadDigits(hex ? text.substr(2) : text, hex ? 16 : 10, &value, &fits))
    return "must be a whole number (decimal, or hex with 0x), not '" + text + "'";
  if (!fits || value > max_seed) {
    const std::string most = std::to_string(max_seed);
    return "must be at most " + most +
           (max_seed == std::numeric_limits<uint64_t>::max() ? std::string(" (2^64 - 1)") : std::string());
  }
  *seed = value;
  return "";
}

// The rule of a whole-number option, as its messages say it: "a whole
// number in [2, 1024]", "a whole number >= 1" where the top is an int's,
// "a whole number" for any int (match --roi, whose own check follows).
std::string RangeText(int min, int max) {
  if (max != std::numeric_limits<int>::max()) return "in [" + std::to_string(min) + ", " + std::to_string(max) + "]";
  return min != std::numeric_limits<int>::min() ? ">= " + std::to_string(min) : "";
}
std::string WholeNumberRule(int min, int max) {
  const std::string range = RangeText(min, max);
  return "a whole number" + (range.empty() ? "" : " " + range);
}

// The whole number in [min, max] `text` names into *value: "" if it is one
// (decimal digits, a '-' or '+' before them), else what is
// wrong with it, the value given said.
std::string ParseWholeNumber(const std::string& text, int min, int max, int* value) {
  if (text.empty()) return "an empty value";  // as every option says it (NonEmptyValue above)
  const bool negative = text[0] == '-', sign = negative || text[0] == '+';
  uint64_t magnitude = 0;
  bool fits = false;
  if (!ReadDigits(sign ? text.substr(1) : text, 10, &magnitude, &fits))
    return "must be " + WholeNumberRule(min, max) + ", got " + text;
  // Past an int's range is past [min, max]: compared as int64 below that.
  const bool huge = !fits || magnitude > static_cast<uint64_t>(std::numeric_limits<int>::max()) + 1;
  const int64_t number = huge ? 0 : negative ? -static_cast<int64_t>(magnitude) : static_cast<int64_t>(magnitude);
  const bool above = huge ? !negative : number > max, below = huge ? negative : number < min;
  if (above || below) {
    if (max != std::numeric_limits<int>::max()) return "must be " + RangeText(min, max) + ", got " + text;
    // An int's own top (a count's range, --roi's): the end it missed.
    const std::string rule = below ? ">= " + std::to_string(min) : "at most " + std::to_string(max);
    return "must be " + rule + ", got " + text;
  }
  *value = static_cast<int>(number);
  return "";
}

}  // namespace

CLI::Option* AddSeedOption(CLI::App& app, uint64_t* seed, uint64_t max_seed, const std::string& description) {
  return app
      .add_option_function<std::string>(
          "--seed", [seed, max_seed](const std::string& text) { (void)ParseSeed(text, max_seed, seed); },
          description + "; a whole number, 0 to " + std::to_string(max_seed) +
              " (decimal, or hex with 0x; leading zeros are decimal: 010 is ten)")
      ->check(CLI::Validator(
          [max_seed](const std::string& text) {
            uint64_t ignored = 0;
            return ParseSeed(text, max_seed, &ignored);
          },
          "", "Seed"))
      ->type_name("UINT")
      ->default_str(std::to_string(*seed));
}

const CLI::Validator& PositiveValue() {
  static const CLI::Validator v =
      NumberValidator([](double x) { return std::isfinite(x) && x > 0; }, "positive and finite", "Positive");
  return v;
}

const CLI::Validator& NonNegativeValue() {
  static const CLI::Validator v =
      NumberValidator([](double x) { return std::isfinite(x) && x >= 0; }, ">= 0 and finite", "NonNegative");
  return v;
}

CLI::Validator WholeNumberIn(int min, int max) {
  return CLI::Validator(
      [min, max](const std::string& text) {
        int ignored = 0;
        return ParseWholeNumber(text, min, max, &ignored);
      },
      "", "WholeNumber");
}

CLI::Option* AddWholeNumberOption(CLI::App& app, const std::string& name, int* value, int min, int max,
                                  const std::string& description) {
  return app
      .add_option_function<std::string>(
          name, [value, min, max](const std::string& text) { (void)ParseWholeNumber(text, min, max, value); },
          description + "; " + WholeNumberRule(min, max) + " (decimal: 010 is ten)")
      ->check(WholeNumberIn(min, max))
      ->type_name("INT")
      ->default_str(std::to_string(*value));
}

CLI::Option* AddCountOption(CLI::App& app, const std::string& name, int* count, const std::string& description) {
  return AddWholeNumberOption(app, name, count, 1, std::numeric_limits<int>::max(), description);
}

namespace {

int g_stdout_errno = 0;  // why the first flush of stdout that failed failed

}  // namespace

void FlushStdout() {
  errno = 0;
  if (std::fflush(stdout) != 0 && g_stdout_errno == 0) g_stdout_errno = errno;
}

std::string StdoutWriteError() {
  FlushStdout();
  if (!std::ferror(stdout)) return "";
  // An earlier write that failed (a printf that filled the buffer) left
  // only the stream's error flag.
  return g_stdout_errno != 0 ? std::strerror(g_stdout_errno) : "a write failed";
}

void RequireStdoutWritten() {
  const std::string error = StdoutWriteError();
  if (!error.empty()) throw InputError("standard output", "cannot be written: " + error);
}

int ExitCodeWithStdout(int code, const std::string& program) {
  const std::string error = StdoutWriteError();
  if (error.empty() || code == kExitBadInput) return code;
  std::fprintf(stderr, "%s: standard output: cannot be written: %s\n", program.c_str(), error.c_str());
  // A check that ran and failed keeps its 1: its verdict is in its report
  // and history, and "bad input" would hide the drift from a supervisor.
  return code == kExitCheckFailed ? kExitCheckFailed : kExitBadInput;
}

const CLI::Validator& NonEmptyPath() {
  static const CLI::Validator v(
      [](const std::string& text) { return text.empty() ? std::string("an empty path") : std::string(); }, "",
      "NonEmptyPath");
  return v;
}

}  // namespace stereorig
