#include "apps/ply_cloud_file.h"

#include <filesystem>
#include <fstream>
#include <sstream>

namespace stereorig {

bool IsPlyCloudFile(const std::string& path) {
  constexpr std::streamsize kMaxHeaderBytes = 4096;
  // A pipe would block the open until a writer came (check's CRC hung so).
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) return false;
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::string head(size_t(kMaxHeaderBytes), '\0');
  in.read(head.data(), kMaxHeaderBytes);
  head.resize(size_t(in.gcount()));
  std::istringstream lines(head);
  std::string line;
  if (!std::getline(lines, line) || (line != "ply" && line != "ply\r")) return false;
  bool vertices = false;
  while (std::getline(lines, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream words(line);
    std::string word, element;
    words >> word;
    if (word == "end_header") return vertices;
    if (word != "element") continue;
    words >> element;
    if (element == "face") return false;
    if (element == "vertex") vertices = true;
  }
  return false;  // no end_header within kMaxHeaderBytes (or none at all): not a file to judge
}

}  // namespace stereorig
