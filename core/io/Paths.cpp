#include "io/Paths.h"

#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <vector>

namespace tp {

std::string defaultTissuePath() {
  namespace fs = std::filesystem;
  std::vector<fs::path> tried;
  if (const char* env = std::getenv("TISSUEPROBE_DEFAULT_TISSUE")) tried.emplace_back(env);
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    tried.push_back(exe.parent_path() / ".." / ".." / "meshes" / "default.ply");
    tried.push_back(exe.parent_path() / ".." / "share" / "tissueprobe" / "meshes" / "default.ply");
  }
  tried.push_back(fs::path(TP_SOURCE_DIR) / "meshes" / "default.ply");
  for (const auto& p : tried)
    if (fs::is_regular_file(p, ec)) return fs::weakly_canonical(p, ec).string();
  std::string msg = "the default tissue was not found; tried:";
  for (const auto& p : tried) {
    msg += ' ';
    msg += p.string();
  }
  throw std::runtime_error(msg);
}

}  // namespace tp
