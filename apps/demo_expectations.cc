#include "apps/demo_expectations.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "apps/cli_util.h"

namespace stereorig {

namespace {

// The `stereorig` a shell runs for `path_env`, or "" if none: the first
// folder of PATH holding an executable file of that name (an empty entry,
// "a::b" or a trailing ':', is the current folder).
std::string StereorigOnPath(const char* path_env) {
  if (path_env == nullptr || *path_env == '\0') return "";
  const std::string path = path_env;
  for (size_t begin = 0; begin <= path.size();) {
    size_t end = path.find(':', begin);
    if (end == std::string::npos) end = path.size();
    const std::string folder = path.substr(begin, end - begin);
    const std::filesystem::path candidate = std::filesystem::path(folder.empty() ? "." : folder) / "stereorig";
    std::error_code ec;
    if (std::filesystem::is_regular_file(candidate, ec) && access(candidate.c_str(), X_OK) == 0)
      return candidate.string();
    begin = end + 1;
  }
  return "";
}

}  // namespace

std::string BumpedNightSurprise(const std::string& report_path, int bumped_camera) {
  std::ifstream f(report_path);
  if (!f) return "its report " + report_path + " cannot be read";
  const nlohmann::json report = nlohmann::json::parse(f, nullptr, /*allow_exceptions=*/false);
  const std::string expected = "expected recalibrate naming camera " + std::to_string(bumped_camera) + " alone";
  if (report.is_discarded() || !report.is_object() || !report.contains("verdict") ||
      !report.contains("flagged_cameras") || !report.contains("flagged_modules") ||
      !report["flagged_cameras"].is_array() || !report["flagged_modules"].is_array())
    return "its report " + report_path + " is not a check report (verdict, flagged_cameras, flagged_modules)";
  if (report["verdict"] != "recalibrate") return "its report says " + report["verdict"].dump() + ", " + expected;
  const nlohmann::json& cameras = report["flagged_cameras"];
  const nlohmann::json& modules = report["flagged_modules"];
  if (cameras == nlohmann::json::array({bumped_camera}) && modules.empty()) return "";
  return "its report names cameras " + cameras.dump() + " and modules " + modules.dump() + ", " + expected;
}

std::string BinaryNote(const std::string& self_exe, const char* path_env) {
  const std::string on_path = StereorigOnPath(path_env);
  std::error_code ec;
  if (!on_path.empty() && std::filesystem::equivalent(on_path, self_exe, ec)) return "";
  return "note: `$ stereorig` below means " + ShellQuoted(self_exe) +
         (on_path.empty() ? " (no stereorig on PATH; `cmake --install build` puts it in /usr/local/bin)"
                          : " (not " + on_path + ", the stereorig on PATH)");
}

}  // namespace stereorig
