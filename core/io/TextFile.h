#pragma once
// A whole file as text (the readers of measured curves parse it from memory).

#include <string>

namespace tp {

/// The file's bytes. Throws std::runtime_error "PATH: cannot open the WHAT file" when it
/// cannot be read.
std::string readTextFile(const std::string& path, const std::string& what);

}  // namespace tp
